//! Outputs: float OpenEXR images with named channels and 8-bit PNG previews. Every file is encoded
//! in memory and written with [`asset::write_atomic`], so an interrupted tool never leaves half a
//! file.

use std::path::Path;

use crate::error::Error;
use crate::map::EnvMap;

/// How [`write_exr`] stores samples.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SampleType {
    /// 32-bit float: every value round-trips exactly.
    #[default]
    F32,
    /// 16-bit half float: half the size; values round to 11 significant bits, and a value above
    /// 65504 (the largest half) is an error rather than an infinity.
    F16,
}

/// Writes a float OpenEXR image (single part, scanlines, ZIP compression) with one channel per
/// `(name, values)` pair, each `width * height` values row-major, top row first: `[("Y", &y)]`
/// for a scalar table, `[("R", &r), ("G", &g), ("B", &b)]` for colour. Rejects, as
/// [`Error::Invalid`], an empty image, no channels, empty, repeated or non-Latin-1 names, a
/// wrong number of values, NaN or infinite values (the readers reject them too), and with
/// [`SampleType::F16`] values beyond the half range.
pub fn write_exr(
    path: &Path,
    width: usize,
    height: usize,
    channels: &[(&str, &[f32])],
    sample_type: SampleType,
) -> Result<(), Error> {
    let bytes = encode_exr(width, height, channels, sample_type)?;
    asset::write_atomic(path, &bytes)?;
    Ok(())
}

/// [`write_exr`] to memory.
pub fn encode_exr(
    width: usize,
    height: usize,
    channels: &[(&str, &[f32])],
    sample_type: SampleType,
) -> Result<Vec<u8>, Error> {
    encode_exr_image(width, height, channels, sample_type, false)
}

/// [`encode_exr`], with OpenEXR's standard `envmap` attribute set to latlong when `latlong`.
fn encode_exr_image(
    width: usize,
    height: usize,
    channels: &[(&str, &[f32])],
    sample_type: SampleType,
    latlong: bool,
) -> Result<Vec<u8>, Error> {
    use exr::meta::attribute::EnvironmentMap;
    use exr::prelude::{AnyChannel, AnyChannels, Encoding, FlatSamples, Image, Layer, LayerAttributes};
    use exr::prelude::{SmallVec, WritableImage, f16};

    if width == 0 || height == 0 {
        return Err(Error::Invalid(format!("empty image: {width} x {height}")));
    }
    if channels.is_empty() {
        return Err(Error::Invalid("no channels to write".into()));
    }
    let mut list: SmallVec<[AnyChannel<FlatSamples>; 4]> = SmallVec::new();
    for (i, &(name, values)) in channels.iter().enumerate() {
        let text = exr::meta::attribute::Text::new_or_none(name)
            .filter(|_| !name.is_empty())
            .ok_or_else(|| Error::Invalid(format!("channel name {name:?} is empty or not latin-1")))?;
        if channels[..i].iter().any(|&(other, _)| other == name) {
            return Err(Error::Invalid(format!("channel {name} given twice")));
        }
        if Some(values.len()) != width.checked_mul(height) {
            return Err(Error::Invalid(format!(
                "channel {name} has {} values, a {width} x {height} image needs {}",
                values.len(),
                width * height
            )));
        }
        if let Some(index) = values.iter().position(|v| !v.is_finite()) {
            return Err(Error::Invalid(format!(
                "channel {name}: non-finite value {} at x {}, y {}",
                values[index],
                index % width,
                index / width
            )));
        }
        let samples = match sample_type {
            SampleType::F32 => FlatSamples::F32(values.to_vec()),
            SampleType::F16 => {
                if let Some(index) = values.iter().position(|v| v.abs() > f16::MAX.to_f32()) {
                    return Err(Error::Invalid(format!(
                        "channel {name}: {} at x {}, y {} does not fit in f16 (largest {})",
                        values[index],
                        index % width,
                        index / width,
                        f16::MAX
                    )));
                }
                FlatSamples::F16(values.iter().map(|&v| f16::from_f32(v)).collect())
            }
        };
        list.push(AnyChannel::new(text, samples));
    }
    let attributes = LayerAttributes {
        environment_map: latlong.then_some(EnvironmentMap::LatitudeLongitude),
        ..LayerAttributes::default()
    };
    let layer = Layer::new((width, height), attributes, Encoding::SMALL_LOSSLESS, AnyChannels::sort(list));
    let mut bytes = std::io::Cursor::new(Vec::new());
    Image::from_layer(layer).write().non_parallel().to_buffered(&mut bytes)?;
    Ok(bytes.into_inner())
}

/// Writes an 8-bit sRGB PNG from interleaved RGB bytes, three per pixel, row-major.
pub fn write_png_rgb8(path: &Path, width: usize, height: usize, rgb8: &[u8]) -> Result<(), Error> {
    let bytes = encode_png_rgb8(width, height, rgb8)?;
    asset::write_atomic(path, &bytes)?;
    Ok(())
}

/// [`write_png_rgb8`] to memory.
pub fn encode_png_rgb8(width: usize, height: usize, rgb8: &[u8]) -> Result<Vec<u8>, Error> {
    use image::ImageEncoder;

    let (Ok(w), Ok(h)) = (u32::try_from(width), u32::try_from(height)) else {
        return Err(Error::Invalid(format!("{width} x {height} is too large for png")));
    };
    if width == 0 || height == 0 {
        return Err(Error::Invalid(format!("empty image: {width} x {height}")));
    }
    // The encoder asserts the length; a wrong length must be an error, not a panic.
    if Some(rgb8.len()) != width.checked_mul(height).and_then(|n| n.checked_mul(3)) {
        return Err(Error::Invalid(format!(
            "{width} x {height} rgb image needs {} bytes, got {}",
            3 * width * height,
            rgb8.len()
        )));
    }
    let mut bytes = Vec::new();
    image::codecs::png::PngEncoder::new(&mut bytes)
        .write_image(rgb8, w, h, image::ExtendedColorType::Rgb8)
        .map_err(|e| Error::from_image("png", e))?;
    Ok(bytes)
}

/// How linear radiance becomes an 8-bit picture: the exposure, then the tone curve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ToneMapping {
    /// Radiance is multiplied by `2^exposure_ev` first.
    pub exposure_ev: f32,
    pub tone_map: ToneMap,
}

impl ToneMapping {
    /// Reinhard's key: [`ToneMapping::auto`] maps a map's log-average luminance to this.
    pub const KEY: f64 = 0.18;

    /// The preview of pictures lit by `map`: the exposure that maps the map's log-average
    /// luminance ([`EnvMap::log_average_luminance`]) to [`ToneMapping::KEY`], then Reinhard (Reinhard
    /// et al. 2002: a scene's "key" sets its exposure). Every picture of a comparison shares it.
    pub fn auto(map: &EnvMap) -> ToneMapping {
        let exposure_ev = (Self::KEY / map.log_average_luminance()).log2() as f32;
        ToneMapping { exposure_ev, tone_map: ToneMap::Reinhard }
    }
}

impl Default for ToneMapping {
    /// No exposure change, Reinhard: suns and lamps stay visible without a chosen exposure.
    fn default() -> Self {
        ToneMapping { exposure_ev: 0.0, tone_map: ToneMap::Reinhard }
    }
}

/// The curve from exposed linear radiance to `[0, 1]`, applied per channel before the sRGB
/// transfer function (IEC 61966-2-1) and rounding to 8 bits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ToneMap {
    /// `min(x, 1)`: exact below 1, so previews of values known to lie in `[0, 1]` are faithful.
    Clamp,
    /// `x / (1 + x)` (Reinhard et al. 2002, the simple global operator): compresses highlights.
    Reinhard,
}

/// Tone maps interleaved linear RGB (or any number of channels: each value is mapped alone) to
/// 8-bit sRGB. NaN maps to 0.
pub fn tonemap_rgb8(rgb: &[f32], preview: &ToneMapping) -> Vec<u8> {
    let scale = f64::from(preview.exposure_ev).exp2();
    rgb.iter().map(|&value| (tonemap_value(f64::from(value), scale, preview.tone_map) * 255.0).round() as u8).collect()
}

/// One value as [`tonemap_rgb8`] shows it, before the rounding to 8 bits: the sRGB-encoded
/// level in `[0, 1]`. NaN maps to 0.
pub fn tonemap(value: f64, preview: &ToneMapping) -> f64 {
    tonemap_value(value, f64::from(preview.exposure_ev).exp2(), preview.tone_map)
}

fn tonemap_value(value: f64, scale: f64, tone_map: ToneMap) -> f64 {
    let x = (value * scale).max(0.0);
    let mapped = match tone_map {
        ToneMap::Clamp => x.min(1.0),
        ToneMap::Reinhard => {
            if x.is_infinite() {
                1.0
            } else {
                x / (1.0 + x)
            }
        }
    };
    // `max(0.0)` above turned NaN into 0.
    srgb_encode(mapped)
}

/// The sRGB transfer function (linear to encoded), for `x` in `[0, 1]`.
fn srgb_encode(x: f64) -> f64 {
    if x <= 0.003_130_8 { 12.92 * x } else { 1.055 * x.powf(1.0 / 2.4) - 0.055 }
}

impl EnvMap {
    /// Writes the map as an RGB float OpenEXR (channels R, G, B) with the standard `envmap`
    /// attribute set to latlong; see [`write_exr`].
    pub fn write_exr(&self, path: &Path, sample_type: SampleType) -> Result<(), Error> {
        asset::write_atomic(path, &self.encode_exr(sample_type)?)?;
        Ok(())
    }

    /// [`EnvMap::write_exr`] to memory.
    pub fn encode_exr(&self, sample_type: SampleType) -> Result<Vec<u8>, Error> {
        let [r, g, b] = self.planes();
        encode_exr_image(self.width(), self.height(), &[("R", &r), ("G", &g), ("B", &b)], sample_type, true)
    }

    /// Writes a tone-mapped 8-bit sRGB PNG preview of the map.
    pub fn write_preview_png(&self, path: &Path, preview: &ToneMapping) -> Result<(), Error> {
        write_png_rgb8(path, self.width(), self.height(), &tonemap_rgb8(self.rgb(), preview))
    }

    fn planes(&self) -> [Vec<f32>; 3] {
        std::array::from_fn(|c| self.texels().iter().map(|texel| texel[c]).collect())
    }
}
