//! The contact sheet: the source and the layers side by side as one 8-bit picture, for a person
//! to look at.

use envmap::{EnvMap, MipChain, Preview, ToneMap};

/// Grey columns between panels.
const GAP: usize = 4;
const GAP_VALUE: u8 = 64;

/// Reinhard's key: the log-average luminance maps to this before the tone curve.
const KEY: f64 = 0.18;

/// An 8-bit sRGB picture, interleaved RGB, row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactSheet {
    pub width: usize,
    pub height: usize,
    pub rgb8: Vec<u8>,
    /// The exposure every panel was shown at.
    pub exposure_ev: f32,
}

/// The source (its mip level nearest the layers' size) and then each layer, left to right,
/// `GAP` grey columns apart, all tone mapped alike: exposed so that the source's solid-angle-
/// weighted log-average luminance becomes 0.18, then Reinhard's `x / (1 + x)` (Reinhard et al.
/// 2002). The layers must all have the same size.
pub fn contact_sheet(source: &MipChain, layers: &[&EnvMap]) -> ContactSheet {
    let (w, h) =
        layers.first().map_or((source.level(0).width(), source.level(0).height()), |l| (l.width(), l.height()));
    let lod = (source.level(0).width() as f64 / w as f64).log2().max(0.0);
    let mut panels: Vec<Vec<f32>> = Vec::with_capacity(layers.len() + 1);
    let mut panel = Vec::with_capacity(3 * w * h);
    for y in 0..h {
        for x in 0..w {
            let (u, v) = envmap::geometry::texel_center_uv(x, y, w, h);
            panel.extend_from_slice(&source.lookup_uv(u, v, lod));
        }
    }
    panels.push(panel);
    panels.extend(layers.iter().map(|layer| layer.rgb().to_vec()));

    let exposure_ev = (KEY / log_average_luminance(source.level(0))).log2() as f32;
    let preview = Preview { exposure_ev, tone_map: ToneMap::Reinhard };
    let mapped: Vec<Vec<u8>> = panels.iter().map(|rgb| envmap::tonemap_rgb8(rgb, &preview)).collect();
    let width = panels.len() * w + (panels.len() - 1) * GAP;
    let mut rgb8 = vec![GAP_VALUE; 3 * width * h];
    for (i, panel) in mapped.iter().enumerate() {
        let x0 = i * (w + GAP);
        for y in 0..h {
            let row = &panel[3 * y * w..3 * (y + 1) * w];
            rgb8[3 * (y * width + x0)..3 * (y * width + x0 + w)].copy_from_slice(row);
        }
    }
    ContactSheet { width, height: h, rgb8, exposure_ev }
}

/// `exp(sum omega ln(1e-4 + Y) / (4 pi))`: the geometric mean of the luminance over directions
/// (the small offset keeps black texels finite).
fn log_average_luminance(map: &EnvMap) -> f64 {
    let luminance = map.luminance();
    let mut sum = 0.0;
    for (y, row) in luminance.chunks_exact(map.width()).enumerate() {
        let omega = map.texel_solid_angle(y);
        sum += omega * row.iter().map(|&v| (1e-4 + f64::from(v)).ln()).sum::<f64>();
    }
    (sum / (4.0 * std::f64::consts::PI)).exp()
}
