//! The colour conventions the toolchain shares. Every RGB value it reads or writes in floating
//! point (MERL tables, HDR and EXR maps, renders) is linear, with Rec. 709 (sRGB) primaries; where
//! a scalar stands for a colour (a BRDF's lobe image, an environment's bandwidth, a picture's
//! mean) it is the Rec. 709 luminance, [`luminance`]. The WGSL has its twin
//! (`gpu/src/preview/adaptive/predict.wgsl`).

/// The weights of linear R, G and B in Rec. 709 luminance (ITU-R BT.709, the `Y` of its
/// primaries and D65 white).
pub const LUMINANCE_WEIGHTS: [f64; 3] = [0.2126, 0.7152, 0.0722];

/// Rec. 709 luminance of a linear RGB triple.
pub fn luminance(rgb: [f64; 3]) -> f64 {
    LUMINANCE_WEIGHTS[0] * rgb[0] + LUMINANCE_WEIGHTS[1] * rgb[1] + LUMINANCE_WEIGHTS[2] * rgb[2]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each primary has BT.709's weight (the standard's published figures, written here
    /// independently of the constant) and white keeps its luminance.
    #[test]
    fn each_primary_has_bt_709_s_weight_and_white_is_one() {
        assert_eq!(luminance([1.0, 0.0, 0.0]), 0.2126);
        assert_eq!(luminance([0.0, 1.0, 0.0]), 0.7152);
        assert_eq!(luminance([0.0, 0.0, 1.0]), 0.0722);
        assert_eq!(luminance([0.0, 2.0, 0.0]), 2.0 * 0.7152);
        assert!((luminance([1.0, 1.0, 1.0]) - 1.0).abs() < 1e-15);
    }
}
