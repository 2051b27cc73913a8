//! Pictures and the numbers that compare them: 8-bit tone mapping (the same for every picture of
//! a comparison), an automatic exposure, PSNR on the 8-bit pictures, the relative error of the
//! linear values, the mean luminance of the covered pixels and an amplified difference picture.

use envmap::{EnvMap, ToneMapping};

use crate::Image;

/// The gain of [`difference_rgb8`]: differences of a few 8-bit steps become visible.
pub const DIFFERENCE_GAIN: u32 = 4;

/// The 8-bit sRGB picture of an image (`envmap::tonemap_rgb8`: exposure, then the curve, then
/// the sRGB transfer function), interleaved RGB.
pub fn tonemap(image: &Image, preview: &ToneMapping) -> Vec<u8> {
    envmap::tonemap_rgb8(&image.rgb, preview)
}

/// The preview every picture of a comparison shares: `envmap::ToneMapping::auto` of the environment
/// (its log-average luminance maps to 0.18, then Reinhard's curve).
pub fn auto_tone_mapping(map: &EnvMap) -> ToneMapping {
    ToneMapping::auto(map)
}

/// Peak signal-to-noise ratio of two 8-bit pictures over all pixels and channels,
/// `10 log10(255^2 / MSE)` in decibels; infinity when they are identical (empty ones included).
///
/// # Panics
/// If the lengths differ: the pictures are not of the same image.
pub fn psnr_db(a: &[u8], b: &[u8]) -> f64 {
    assert_eq!(a.len(), b.len(), "psnr of pictures of different sizes");
    let squared: u64 = a.iter().zip(b).map(|(&x, &y)| u64::from(x.abs_diff(y)).pow(2)).sum();
    if squared == 0 {
        return f64::INFINITY;
    }
    let mse = squared as f64 / a.len() as f64;
    10.0 * (255.0 * 255.0 / mse).log10()
}

/// `|a - b| / |b|` with Euclidean norms over all values: 0 when equal, infinity when `b` is zero
/// and `a` is not.
///
/// # Panics
/// If the lengths differ.
pub fn relative_error(a: &[f32], b: &[f32]) -> f64 {
    assert_eq!(a.len(), b.len(), "relative error of images of different sizes");
    let (mut difference, mut norm) = (0.0f64, 0.0f64);
    for (&x, &y) in a.iter().zip(b) {
        difference += (f64::from(x) - f64::from(y)).powi(2);
        norm += f64::from(y).powi(2);
    }
    if difference == 0.0 { 0.0 } else { (difference / norm).sqrt() }
}

/// The mean Rec. 709 luminance of the covered pixels; 0 when none is covered.
pub fn mean_luminance(image: &Image) -> f64 {
    let (sum, count) = image
        .rgb
        .chunks_exact(3)
        .zip(&image.covered)
        .filter(|(_, covered)| **covered)
        .fold((0.0, 0usize), |(sum, count), (rgb, _)| {
            (sum + color::luminance([rgb[0], rgb[1], rgb[2]].map(f64::from)), count + 1)
        });
    if count == 0 { 0.0 } else { sum / count as f64 }
}

/// The absolute difference of two 8-bit pictures, times [`DIFFERENCE_GAIN`], clamped to 255.
///
/// # Panics
/// If the lengths differ.
pub fn difference_rgb8(a: &[u8], b: &[u8]) -> Vec<u8> {
    assert_eq!(a.len(), b.len(), "difference of pictures of different sizes");
    a.iter().zip(b).map(|(&x, &y)| (u32::from(x.abs_diff(y)) * DIFFERENCE_GAIN).min(255) as u8).collect()
}

/// The side of the window [`windowed_bias`] averages over.
pub const BIAS_WINDOW: usize = 7;

/// The structure of the difference between two pictures, with the noise averaged out: per pixel
/// and channel the mean of the signed 8-bit difference `a - b` over the included pixels of its
/// [`BIAS_WINDOW`] x [`BIAS_WINDOW`] window, in levels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bias {
    /// The 99th percentile of its magnitude over the included pixels and channels.
    pub p99: f64,
    /// Its largest magnitude.
    pub max: f64,
    /// The mean of the signed values.
    pub mean: f64,
}

/// [`Bias`] of two interleaved 8-bit RGB pictures of `width x height` over the pixels `include`
/// marks (a window takes only those: the background beside a sphere does not enter its rim's
/// means). Bands, blocks and a shading error survive the window; independent noise of standard
/// deviation `s` shrinks to `s / 7`. All zero when no pixel is included.
///
/// # Panics
/// If the lengths differ from `width x height` pixels.
pub fn windowed_bias(a: &[u8], b: &[u8], width: usize, height: usize, include: &[bool]) -> Bias {
    assert!(a.len() == 3 * width * height && b.len() == a.len() && include.len() == width * height);
    let r = BIAS_WINDOW / 2;
    let mut values = Vec::new();
    for y in 0..height {
        for x in 0..width {
            if !include[y * width + x] {
                continue;
            }
            let (mut sum, mut count) = ([0i64; 3], 0i64);
            for wy in y.saturating_sub(r)..(y + r + 1).min(height) {
                for wx in x.saturating_sub(r)..(x + r + 1).min(width) {
                    let i = wy * width + wx;
                    if include[i] {
                        for (c, s) in sum.iter_mut().enumerate() {
                            *s += i64::from(a[3 * i + c]) - i64::from(b[3 * i + c]);
                        }
                        count += 1;
                    }
                }
            }
            values.extend(sum.map(|s| s as f64 / count as f64));
        }
    }
    if values.is_empty() {
        return Bias { p99: 0.0, max: 0.0, mean: 0.0 };
    }
    let mean = values.iter().sum::<f64>() / values.len() as f64;
    let mut magnitudes: Vec<f64> = values.iter().map(|v| v.abs()).collect();
    magnitudes.sort_by(f64::total_cmp);
    let rank = ((magnitudes.len() - 1) as f64 * 0.99).round() as usize;
    Bias { p99: magnitudes[rank], max: magnitudes[magnitudes.len() - 1], mean }
}
