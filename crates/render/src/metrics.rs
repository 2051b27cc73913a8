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
            (sum + envmap::luminance([rgb[0], rgb[1], rgb[2]].map(f64::from)), count + 1)
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
