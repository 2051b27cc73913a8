//! What the estimator reads of an HDR image.

use color::luminance;
use dwt::Image;

use crate::Error;

/// `ln(1 + Y)` of every pixel of a linear HDR image, `Y` its Rec. 709 luminance clamped at 0
/// (HDR files carry small negative values from filtering): the image the estimator should read
/// (crate docs, "HDR input"). `rgb` is row-major, one triple per pixel.
pub fn log1p_luminance<T: Copy + Into<f64>>(width: usize, height: usize, rgb: &[[T; 3]]) -> Result<Image, Error> {
    if width.checked_mul(height) != Some(rgb.len()) {
        return Err(Error::DataLength { what: "rgb image", width, height, len: rgb.len() });
    }
    let data = rgb
        .iter()
        .enumerate()
        .map(|(index, p)| {
            let y = luminance([p[0].into(), p[1].into(), p[2].into()]);
            if y.is_finite() { Ok(y.max(0.0).ln_1p()) } else { Err(Error::NonFinite { what: "rgb image", index }) }
        })
        .collect::<Result<Vec<f64>, Error>>()?;
    Ok(Image::new(width, height, data).expect("sizes match"))
}
