//! False colour for pictures people look at: matplotlib's perceptually uniform colour maps
//! (inferno for maps over an image, viridis for atlases and error maps) and a logarithmic
//! scale. Every tool that writes a false-colour PNG takes its colours from here.

/// matplotlib's inferno at 0, 0.1, ..., 1 (viridisLite's `inferno(11)`), interpolated linearly
/// in sRGB: close enough to the 256-entry table for a preview, and still monotone in lightness.
const INFERNO: [[u8; 3]; 11] = [
    [0x00, 0x00, 0x04],
    [0x16, 0x0b, 0x39],
    [0x42, 0x0a, 0x68],
    [0x6a, 0x17, 0x6e],
    [0x93, 0x26, 0x67],
    [0xbc, 0x37, 0x54],
    [0xdd, 0x51, 0x3a],
    [0xf3, 0x78, 0x19],
    [0xfc, 0xa5, 0x0a],
    [0xf6, 0xd7, 0x46],
    [0xfc, 0xff, 0xa4],
];

/// The colour of position `t` in `0..=1`.
pub fn inferno(t: f64) -> [u8; 3] {
    let s = t.clamp(0.0, 1.0) * (INFERNO.len() - 1) as f64;
    let i = (s.floor() as usize).min(INFERNO.len() - 2);
    let f = s - i as f64;
    std::array::from_fn(|c| (f64::from(INFERNO[i][c]) * (1.0 - f) + f64::from(INFERNO[i + 1][c]) * f).round() as u8)
}

/// Viridis at 0, 1/8, ..., 1 (sRGB bytes); linear in between.
const VIRIDIS: [[f64; 3]; 9] = [
    [68.0, 1.0, 84.0],
    [71.0, 44.0, 122.0],
    [59.0, 81.0, 139.0],
    [44.0, 113.0, 142.0],
    [33.0, 144.0, 141.0],
    [39.0, 173.0, 129.0],
    [92.0, 200.0, 99.0],
    [170.0, 220.0, 50.0],
    [253.0, 231.0, 37.0],
];

/// The colour of `t` in `[0, 1]` (clamped).
pub fn viridis(t: f64) -> [u8; 3] {
    let x = t.clamp(0.0, 1.0) * 8.0;
    let i = (x as usize).min(7);
    let f = x - i as f64;
    std::array::from_fn(|c| (VIRIDIS[i][c] * (1.0 - f) + VIRIDIS[i + 1][c] * f).round() as u8)
}

/// The range of a logarithmic scale for `values`: from the smallest positive value, but no
/// more than `decades` decades below the largest, to the largest. `None` when no value is
/// positive.
pub fn log_range(values: &[f32], decades: f64) -> Option<(f64, f64)> {
    let hi = values.iter().fold(0.0f64, |m, v| m.max(f64::from(*v)));
    if hi <= 0.0 {
        return None;
    }
    let lo = values.iter().filter(|v| **v > 0.0).fold(hi, |m, v| m.min(f64::from(*v)));
    Some((lo.max(hi * 10f64.powf(-decades)), hi))
}

/// Interleaved RGB bytes for `values`: `log(v)` mapped linearly from `range.0` (dark violet) to
/// `range.1` (yellow), clamped; zero, negative and NaN values are black.
pub fn false_colour_log(values: &[f32], range: (f64, f64)) -> Vec<u8> {
    let (lo, hi) = (range.0.ln(), range.1.ln());
    let span = if hi > lo { hi - lo } else { 1.0 };
    values
        .iter()
        .flat_map(|&v| {
            let v = f64::from(v);
            if v > 0.0 { viridis((v.ln() - lo) / span) } else { [0, 0, 0] }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inferno_ends() {
        assert_eq!(inferno(0.0), [0, 0, 4]);
        assert_eq!(inferno(1.0), [0xfc, 0xff, 0xa4]);
        assert_eq!(inferno(-1.0), inferno(0.0));
    }

    #[test]
    fn ends_and_zero() {
        assert_eq!(viridis(0.0), [68, 1, 84]);
        assert_eq!(viridis(1.0), [253, 231, 37]);
        let rgb = false_colour_log(&[0.0, 1.0, 100.0, f32::NAN], (1.0, 100.0));
        assert_eq!(rgb, [0, 0, 0, 68, 1, 84, 253, 231, 37, 0, 0, 0]);
        assert_eq!(log_range(&[0.0, 0.5, 20.0], 3.0), Some((0.5, 20.0)));
        let (lo, hi) = log_range(&[1e-9, 20.0], 3.0).unwrap();
        assert!((lo - 0.02).abs() < 1e-15 && hi == 20.0);
        assert_eq!(log_range(&[0.0], 3.0), None);
    }
}
