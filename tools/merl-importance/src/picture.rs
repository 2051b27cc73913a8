//! A picture of what the tables do: for a few slices, the lobe `L(f) cos theta_i` over the
//! hemisphere of `wi` (orthographic view from above: `x = wi.x` to the right, `y = wi.y` up; the
//! mirror direction of `wo` lies on the left of the horizontal axis), log-scaled over six
//! decades from the panel's maximum (mirror-like lobes are a few pixels wide), with the first
//! vector of the slice's precomputed samples drawn on top in cyan.

use envmap::colormap::inferno;
use merl::{Interp, MerlTable, luminance};

use importance::ImportanceTables;

/// An 8-bit RGB image, row-major, top row first.
#[derive(Debug, Clone, PartialEq)]
pub struct Picture {
    pub width: usize,
    pub height: usize,
    pub rgb: Vec<u8>,
}

const GAP: usize = 4;
const BACKGROUND: [u8; 3] = [32, 32, 32];
const SAMPLE: [u8; 3] = [0, 255, 255];
const DECADES: f64 = 6.0;

/// Panels of `panel` x `panel` pixels, one per slice in `slices`, side by side.
pub fn lobes(table: &MerlTable, tables: &ImportanceTables, slices: &[usize], panel: usize) -> Picture {
    let width = slices.len() * panel + slices.len().saturating_sub(1) * GAP;
    let mut rgb = vec![0u8; width * panel * 3];
    for (i, &k) in slices.iter().enumerate() {
        let slice = &tables.slices()[k];
        let wo = slice.wo();
        let x0 = i * (panel + GAP);
        let to_dir = |px: usize, py: usize| {
            let x = (px as f64 + 0.5) / panel as f64 * 2.0 - 1.0;
            let y = 1.0 - (py as f64 + 0.5) / panel as f64 * 2.0;
            let z2 = 1.0 - x * x - y * y;
            (z2 > 0.0).then(|| glam::DVec3::new(x, y, z2.sqrt()))
        };
        let values: Vec<Option<f64>> = (0..panel * panel)
            .map(|p| {
                to_dir(p % panel, p / panel)
                    .map(|wi| table.lookup(wi, wo, Interp::Nearest).map_or(0.0, |f| luminance(f) * wi.z))
            })
            .collect();
        let max = values.iter().flatten().fold(0.0_f64, |m, v| m.max(*v));
        for (p, v) in values.iter().enumerate() {
            let colour = match v {
                None => BACKGROUND,
                Some(v) if *v > 0.0 && max > 0.0 => inferno(1.0 + (v / max).log10() / DECADES),
                Some(_) => inferno(0.0),
            };
            let at = ((p / panel) * width + x0 + p % panel) * 3;
            rgb[at..at + 3].copy_from_slice(&colour);
        }
        {
            for s in tables.samples(k, 0).iter().filter(|s| s.pdf > 0.0 && s.wi.z > 0.0) {
                let px = ((s.wi.x + 1.0) / 2.0 * panel as f64) as isize;
                let py = ((1.0 - s.wi.y) / 2.0 * panel as f64) as isize;
                for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    let (x, y) = (px + dx, py + dy);
                    if (0..panel as isize).contains(&x) && (0..panel as isize).contains(&y) {
                        let at = (y as usize * width + x0 + x as usize) * 3;
                        rgb[at..at + 3].copy_from_slice(&SAMPLE);
                    }
                }
            }
        }
    }
    // The gaps between panels.
    for y in 0..panel {
        for i in 1..slices.len() {
            for x in i * (panel + GAP) - GAP..i * (panel + GAP) {
                let at = (y * width + x) * 3;
                rgb[at..at + 3].copy_from_slice(&[255, 255, 255]);
            }
        }
    }
    Picture { width, height: panel, rgb }
}
