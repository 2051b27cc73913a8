//! One bandwidth per view direction, and the Phong layer it selects (`001` sections 2.5 and 4.3:
//! "look up pre-filtered illumination ... according to the maximum frequency of the BRDF").
//!
//! A renderer that shades a pixel with a prefiltered environment needs one number per view
//! direction, where the atlas holds a tile per incident direction. By reciprocity the lobe the
//! atlas holds for incidence `wi` is also the lobe a renderer integrates over when it looks along
//! `wo = wi`, so row `j` of the atlas serves the views whose `cos theta_o` lies in that row.
//! [`ViewReduction`] turns a row's lobe into one number:
//!
//! - [`ViewReduction::Max`]: the largest texel of the row's tile, the papers' "maximum
//!   frequency" read literally.
//! - [`ViewReduction::BandQuantile`]: the frequency below which a share `q` of the lobe image's
//!   wavelet detail energy lies ([`band_quantile`]): the same D4 decomposition, of the lobe
//!   image's mirror tiling ([`crate::mirror_tiling`]), its energy per level accumulated from the
//!   coarsest, the crossing interpolated within its level, level `j` read as `c 2^-j` cycles per
//!   pixel as the estimator reads it, converted at the lobe map's centre (`n / pi` pixels per
//!   radian).
//!
//! Why not the tile alone: the estimator reads whole octaves, and the layers are an octave apart
//! (exponents a factor 4 apart are lobes a factor 2 apart in width), so a per-texel maximum or
//! an energy-weighted quantile of texels puts two neighbouring layers on the same value as often
//! as not (measured on the default layers at analysis sizes 64 to 1024: every size ties at least
//! one pair, e.g. n = 256 and 1024 both read 7.2 cycles per radian at 512). The maximum is also
//! set by the lobe's far tail, where a Gaussian-like lobe's local frequency keeps growing while
//! its value vanishes. The detail energy is a property of the whole lobe that moves smoothly with
//! its width.
//!
//! The Phong layers are put on the same scale by measuring each layer's own lobe with exactly
//! the analysis the atlas uses ([`layer_bandwidth`]): the lobe `max(0, w . r)^n` drawn as a lobe
//! image of the same size and parameterization, at normal incidence (the centre of the lobe map,
//! where it distorts least), analysed and reduced the same way. A view then uses the layer whose
//! measured bandwidth is nearest on a log scale ([`nearest_layer`]).

use merl::MerlTable;

use rayon::prelude::*;

use crate::analysis::{Analyser, MirrorTiling, analysis_levels, peak};
use crate::atlas::{AtlasBuild, Config};
use crate::error::Error;

/// How a lobe becomes one number.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ViewReduction {
    /// The largest texel of the lobe's tile.
    Max,
    /// The frequency below which this share (in `(0, 1)`) of the lobe's wavelet detail energy
    /// lies ([`band_quantile`]).
    BandQuantile(f64),
}

impl ViewReduction {
    /// The name in files and on the command line: `max`, or `band-0.99`.
    pub fn name(self) -> String {
        match self {
            ViewReduction::Max => "max".to_string(),
            ViewReduction::BandQuantile(q) => format!("band-{q}"),
        }
    }

    /// Parses [`ViewReduction::name`].
    pub fn from_name(name: &str) -> Option<ViewReduction> {
        if name == "max" {
            return Some(ViewReduction::Max);
        }
        let q: f64 = name.strip_prefix("band-")?.parse().ok()?;
        (q > 0.0 && q < 1.0).then_some(ViewReduction::BandQuantile(q))
    }

    /// The bandwidth, in cycles per radian, of a lobe whose tile is `tile` and whose image's
    /// detail energy per level (finest first, [`band_energy`]) is `energy`, analysed with
    /// `config`.
    pub fn reduce(self, tile: &[f32], energy: &[f64], config: &Config) -> f64 {
        match self {
            ViewReduction::Max => tile.iter().fold(0.0f64, |m, &v| m.max(f64::from(v))),
            ViewReduction::BandQuantile(q) => {
                band_quantile(energy, q, config.c) * config.analysis_size as f64 / std::f64::consts::PI
            }
        }
    }
}

/// The energy of each detail level of a lobe image's wavelet decomposition: the periodic
/// image's mirror tiling ([`crate::mirror_tiling`]: four copies of the image, so the shares are the
/// image's own), D4, [`analysis_levels`] levels;
/// finest first, the three orientations of a level summed. A coefficient of level `j` counts only
/// from `relative_noise_floor` times the image's largest magnitude times `2^j` (the noise floor
/// of the per-texel analysis, [`Config::relative_noise_floor`]), so that a lobe without detail,
/// a Lambertian's constant, has none, rather than its lookups' rounding noise, which would read
/// as the finest frequencies (27 cycles per radian at the default size: the sharpest layer).
pub fn band_energy(image: &[f64], n: usize, relative_noise_floor: f64) -> Vec<f64> {
    band_energy_in(image, n, relative_noise_floor * peak(image), &mut dwt::Workspace2::default())
}

/// [`band_energy`] with the noise floor in the image's units (`relative_noise_floor` times its
/// peak) and the transform's reused buffers. The tiling is given to the transform row by row and
/// its details summed as they are made ([`dwt::Workspace2::detail_energy`]: eight partial sums
/// per row and orientation, within `2 m u` of a sum in order, `m` terms), neither ever stored.
pub(crate) fn band_energy_in(image: &[f64], n: usize, noise_floor: f64, transform: &mut dwt::Workspace2) -> Vec<f64> {
    let floor = |level: usize| noise_floor * (1u64 << level) as f64;
    transform
        .detail_energy(&MirrorTiling { image, n }, dwt::Wavelet::D4, analysis_levels(n), &floor)
        .expect("lobe images are finite, of a power-of-two size of at least 16")
}

/// The frequency, in cycles per pixel, below which a share `q` of the detail energy `energy`
/// (per level, finest first) lies. Levels are accumulated from the coarsest; within the level
/// where the share is reached, a fraction `t` of its energy needed moves the answer geometrically
/// from `c 2^-(j+1)` (none of level `j`) to `c 2^-j` (all of it), level `j` read as the estimator
/// reads it. 0 for a lobe with no detail (flat).
pub fn band_quantile(energy: &[f64], q: f64, c: f64) -> f64 {
    let total: f64 = energy.iter().sum();
    if total <= 0.0 {
        return 0.0;
    }
    let mut cumulative = 0.0;
    for j in (1..=energy.len()).rev() {
        let e = energy[j - 1];
        if cumulative + e >= q * total {
            let t = ((q * total - cumulative) / e).clamp(0.0, 1.0);
            return c * 2f64.powf(-(j as f64 + 1.0 - t));
        }
        cumulative += e;
    }
    c / 2.0
}

/// The bandwidth the analysis of `config` measures for the Phong lobe `max(0, w . r)^n` around
/// the normal, reduced like a view: the layer of exponent `n`'s place on the atlas's scale. The
/// lobe's normalization does not matter (the estimator is relative to each lobe's peak).
pub fn layer_bandwidth(config: &Config, n: u32, reduction: ViewReduction) -> f64 {
    layer_bandwidth_with(&Analyser::new(config), config, n, reduction)
}

/// The reduction [`KNOWN_LAYER_BANDWIDTHS`] were measured with: the bake's default.
pub const KNOWN_LAYER_REDUCTION: ViewReduction = ViewReduction::BandQuantile(0.99);

/// [`layer_bandwidth`] of the default configuration under [`KNOWN_LAYER_REDUCTION`] for the
/// default Phong exponents, `(n, bits of the f64)`: they depend on neither the material nor the
/// map, so a bake reads them rather than measuring the eight lobes again. Printed by
/// `cargo run --release -p bandwidth-atlas --example layer-bandwidths`; a test holds them to the
/// measurement.
pub const KNOWN_LAYER_BANDWIDTHS: [(u32, u64); 8] = [
    (1, 0x3fd3609ce95d2754),
    (4, 0x3fd42cf4b97e1f98),
    (16, 0x3fdcac9cf3d5b74d),
    (64, 0x3fec08daaa61e251),
    (256, 0x3ffbb761706661e7),
    (1024, 0x400b86b5140489ea),
    (4096, 0x401b4b4672efc038),
    (16384, 0x402ad28c75a5c1ba),
];

/// The layer bandwidth of `n` from [`KNOWN_LAYER_BANDWIDTHS`] where `config` and `reduction` are
/// the ones they were measured with.
fn known_layer_bandwidth(config: &Config, n: u32, reduction: ViewReduction) -> Option<f64> {
    if *config != Config::default() || reduction != KNOWN_LAYER_REDUCTION {
        return None;
    }
    KNOWN_LAYER_BANDWIDTHS.iter().find(|(m, _)| *m == n).map(|(_, bits)| f64::from_bits(*bits))
}

/// [`layer_bandwidth`] with the analyser of `config` made once for all layers.
fn layer_bandwidth_with(analyser: &Analyser, config: &Config, n: u32, reduction: ViewReduction) -> f64 {
    let image = analyser.lobe_image(|w| Some(w.z.max(0.0).powi(n as i32)));
    let energy = band_energy(&image, config.analysis_size, config.relative_noise_floor);
    let tile = analyser.analyse_image(image).tile(config.tile);
    reduction.reduce(&tile, &energy, config)
}

/// The index of the layer whose bandwidth is nearest to `nu` on a log scale (ties to the lower
/// index); a flat view (`nu = 0`) takes the layer of lowest bandwidth.
pub fn nearest_layer(nu: f64, layers: &[f64]) -> usize {
    let by = |distance: &dyn Fn(f64) -> f64| {
        let key = |k: &(usize, &f64)| distance(*k.1);
        layers.iter().enumerate().min_by(|a, b| key(a).total_cmp(&key(b))).map_or(0, |(k, _)| k)
    };
    if nu > 0.0 {
        by(&|b: f64| if b > 0.0 { (nu.ln() - b.ln()).abs() } else { f64::INFINITY })
    } else {
        by(&|b: f64| b)
    }
}

/// Where a view of bandwidth `nu` falls among layers of bandwidths `layers` (increasing), as a
/// coordinate to blend two layers by: `k + t` reads layer `k` with weight `1 - t` and layer
/// `k + 1` with weight `t`, `t = (ln nu - ln b_k) / (ln b_(k+1) - ln b_k)` between the two layers
/// that bracket `nu` on a log scale, the measure [`nearest_layer`] uses, so the coordinate
/// rounds to its layer. Below the broadest layer, and for a flat view (`nu = 0`), 0; above the
/// sharpest, the last index. Layers whose bandwidths do not increase (a damaged selection) blend
/// nothing: the coordinate is [`nearest_layer`]'s.
pub fn layer_coordinate(nu: f64, layers: &[f64]) -> f64 {
    let increasing = layers.windows(2).all(|w| w[1] > w[0]) && layers.first().is_some_and(|&b| b > 0.0);
    if !increasing || !nu.is_finite() {
        return nearest_layer(nu, layers) as f64;
    }
    let last = layers.len() - 1;
    if nu <= layers[0] {
        return 0.0;
    }
    if nu >= layers[last] {
        return last as f64;
    }
    let k = layers.partition_point(|&b| b <= nu) - 1;
    k as f64 + (nu.ln() - layers[k].ln()) / (layers[k + 1].ln() - layers[k].ln())
}

/// The bandwidth of the Phong layer a renderer reads for a view, as a multiple of the view's
/// (the lobe's) bandwidth. The pre-filtered estimator integrates the BRDF against the light
/// convolved with the layer's lobe, which is the BRDF blurred by that lobe: a layer of the lobe's
/// own bandwidth widens it by about `sqrt 2`, and a glossy highlight under a sun showed it, a dark
/// band through its middle with brighter rims (gold-paint under quarry_01, the camera on the
/// sun's reflection, 128 x 128: the 7 x 7 windowed bias, `render::metrics::windowed_bias`,
/// against the converged estimate of 512 samples per strategy, 1.57 levels at the 99th
/// percentile). Twice the bandwidth widens it by about 12% (0.65 levels), at no cost in noise at
/// the previewer's 128 samples per pixel (PSNR 49.4 to 49.9 dB); four times, 0.49 levels and
/// 49.9 dB. `cargo bench -p brdf-preview --bench mitsuba` reports the bias of every mode against
/// Mitsuba 3.
pub const LAYER_OVER_VIEW_BANDWIDTH: f64 = 2.0;

/// The coordinate among the layers that each view reads, as the renderers read them
/// (`render::Material::view_layers`): [`layer_coordinate`] of [`LAYER_OVER_VIEW_BANDWIDTH`]
/// times its bandwidth; above the sharpest layer, up to one layer further: `K` (of `K` layers)
/// is the map itself, unfiltered, at the layers' last step continued (`b_K = b_(K-1)^2 /
/// b_(K-2)`, twice the sharpest's bandwidth between the default layers; the renderers read it
/// as the smooth part's level 0). Chrome's views (18 to 27 cycles per radian, 36 to 54 wanted)
/// all read it; a lobe the sharpest layer would blur has nothing sharper to read otherwise.
pub fn view_coordinates(view_bandwidth: &[f64], layer_bandwidth: &[f64]) -> Vec<f32> {
    let past = match layer_bandwidth {
        [.., a, b] if *a > 0.0 && b > a => Some(b * b / a),
        _ => None,
    };
    let last = layer_bandwidth.len().saturating_sub(1);
    view_bandwidth
        .iter()
        .map(|&nu| {
            let wanted = LAYER_OVER_VIEW_BANDWIDTH * nu;
            let x = layer_coordinate(wanted, layer_bandwidth);
            match (past, layer_bandwidth.last()) {
                (Some(past), Some(&sharpest)) if x >= last as f64 && wanted > sharpest => {
                    (last as f64 + ((wanted.ln() - sharpest.ln()) / (past.ln() - sharpest.ln())).min(1.0)) as f32
                }
                _ => x as f32,
            }
        })
        .collect()
}

/// Which Phong layer serves each view elevation of a material (the `bake` stage
/// `layer_selection` writes it as the asset `layer-selection`).
#[derive(Clone, Debug, PartialEq)]
pub struct ViewLayers {
    pub reduction: ViewReduction,
    pub exponents: Vec<u32>,
    /// Each layer's measured bandwidth ([`layer_bandwidth`]), cycles per radian.
    pub layer_bandwidth: Vec<f64>,
    /// Per row of the atlas (equal steps of `cos theta_o`, row `j` at `1 - (j + 1/2) / rows`):
    /// the material's bandwidth for views in that row, cycles per radian.
    pub view_bandwidth: Vec<f64>,
    /// Per row: the layer index whose bandwidth is nearest to the view's.
    pub view_layer: Vec<u32>,
}

impl ViewLayers {
    /// How many rows select each layer.
    pub fn histogram(&self) -> Vec<usize> {
        let mut counts = vec![0; self.exponents.len()];
        for &k in &self.view_layer {
            counts[k as usize] += 1;
        }
        counts
    }
}

/// The layer selection of a material from its atlas build (made with `config`, which keeps each
/// row's band energy), for layers of `exponents`. The atlas's first column of tiles serves: a
/// MERL table is isotropic, every tile of a row is the same.
pub fn select_layers(
    build: &AtlasBuild,
    config: &Config,
    exponents: &[u32],
    reduction: ViewReduction,
) -> Result<ViewLayers, Error> {
    config.check()?;
    let atlas = &build.atlas;
    if (atlas.lobes_y, atlas.tile, atlas.analysis_size) != (config.lobes, config.tile, config.analysis_size) {
        return Err(Error::Config(format!(
            "the atlas ({} rows, tiles of {}, analysed at {}) was not made with this configuration ({} rows, tiles \
             of {}, analysed at {})",
            atlas.lobes_y, atlas.tile, atlas.analysis_size, config.lobes, config.tile, config.analysis_size
        )));
    }
    let known: Vec<Option<f64>> = exponents.iter().map(|&n| known_layer_bandwidth(config, n, reduction)).collect();
    let layer_bandwidth: Vec<f64> = match known.iter().all(Option::is_some) {
        true => known.into_iter().flatten().collect(),
        false => {
            let analyser = Analyser::new(config);
            exponents.par_iter().map(|&n| layer_bandwidth_with(&analyser, config, n, reduction)).collect()
        }
    };
    let view_bandwidth: Vec<f64> = (0..config.lobes)
        .map(|j| reduction.reduce(&atlas.tile_of(atlas.lobe_index(0, j)), &build.band_energy[j], config))
        .collect();
    let view_layer = view_bandwidth.iter().map(|&nu| nearest_layer(nu, &layer_bandwidth) as u32).collect();
    Ok(ViewLayers { reduction, exponents: exponents.to_vec(), layer_bandwidth, view_bandwidth, view_layer })
}

/// Convenience for tests and tools that have only the table: builds the atlas and selects.
pub fn select_layers_of_table(
    table: &MerlTable,
    config: &Config,
    exponents: &[u32],
    reduction: ViewReduction,
) -> Result<ViewLayers, Error> {
    let build = crate::build_atlas(table, config, &|_| {})?;
    select_layers(&build, config, exponents, reduction)
}
