//! What the fast analysis changes against the straightforward one in the default analysis of
//! MERL tables. The fast analysis reads the lobes with the crate's own `atan2`
//! (`LuminanceTable::lookup`) and sums a level's band energy in eight partial sums per row of
//! coefficients (`view::band_energy`); the reference reads them with libm's (`LuminanceTable::lookup_libm`)
//! and sums one coefficient after another ([`sequential_band_energy`]), as the crate did before.
//! Per table, every row's lobe image drawn both ways: the largest difference of a pixel relative
//! to the lobe's peak, the tiles whose texels differ in any bit, the largest relative difference
//! of a row's band energy and of its view bandwidth (the bake's default reduction), and the rows
//! whose Phong layer (the default layers) differs. The crate docs ("Angles") quote it.
//!
//! `cargo run --release -p bandwidth-atlas --example analysis-difference -- TABLE.binary ...`
//! Exit status 1 if a tile or a layer differs.

use std::process::ExitCode;

use bandwidth_atlas::view::{KNOWN_LAYER_BANDWIDTHS, KNOWN_LAYER_REDUCTION, band_energy, nearest_layer};
use bandwidth_atlas::{Analyser, Config, IncidentGrid, LuminanceTable};
use rayon::prelude::*;

/// `view::band_energy` as the crate computed it before its partial sums: the squares of a
/// level's coefficients at or above the noise floor, added one after another (the three
/// orientations in turn, each row-major).
fn sequential_band_energy(image: &[f64], n: usize, relative_noise_floor: f64) -> Vec<f64> {
    let tiling = bandwidth_atlas::mirror_tiling(image, n);
    let decomposition =
        dwt::wavedec2(&tiling, dwt::Wavelet::D4, bandwidth_atlas::analysis_levels(n)).expect("a lobe image");
    let peak = image.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut energy = Vec::new();
    for (i, level) in decomposition.details.iter().enumerate() {
        let floor = relative_noise_floor * peak * (1u64 << (i + 1)) as f64;
        let mut sum = 0.0;
        for c in level.iter().flat_map(dwt::Image::data).filter(|c| c.abs() >= floor) {
            sum += c * c;
        }
        energy.push(sum);
    }
    energy
}

/// What one row shows: the image difference, whether the tiles differ, the band energies' and
/// the view bandwidth's relative differences, whether the layer differs.
struct Row {
    image: f64,
    tile: bool,
    energy: f64,
    view: f64,
    layer: bool,
}

fn main() -> ExitCode {
    let config = Config::default();
    let analyser = Analyser::new(&config);
    let grid = IncidentGrid::new(config.lobes);
    let layers: Vec<f64> = KNOWN_LAYER_BANDWIDTHS.iter().map(|&(_, bits)| f64::from_bits(bits)).collect();
    let mut differs = false;
    println!(
        "table  largest pixel difference / peak  tiles differing  largest band energy difference  largest view \
         bandwidth difference  rows whose layer differs"
    );
    for path in std::env::args().skip(1) {
        let table = match merl::read_file(std::path::Path::new(&path)) {
            Ok(table) => table,
            Err(e) => {
                eprintln!("error: reading {path}: {e}");
                return ExitCode::from(2);
            }
        };
        let luminance = LuminanceTable::new(&table);
        let rows: Vec<Row> = (0..config.lobes)
            .into_par_iter()
            .map(|j| {
                let wi = merl::spherical_dir(grid.theta_i(j), 0.0);
                let fast = analyser.lobe_image(|wo| luminance.lookup(wi, wo));
                let libm = analyser.lobe_image(|wo| luminance.lookup_libm(wi, wo));
                let peak = libm.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                let image = fast.iter().zip(&libm).fold(0.0f64, |m, (a, b)| m.max((a - b).abs())) / peak;
                let view = |image: Vec<f64>, energy: Vec<f64>| {
                    let tile = analyser.analyse_image(image).tile(config.tile);
                    let nu = KNOWN_LAYER_REDUCTION.reduce(&tile, &energy, &config);
                    (tile, energy, nu, nearest_layer(nu, &layers))
                };
                let n = config.analysis_size;
                let energy = band_energy(&fast, n, config.relative_noise_floor);
                let (tile_fast, energy_fast, nu_fast, layer_fast) = view(fast, energy);
                let energy = sequential_band_energy(&libm, n, config.relative_noise_floor);
                let (tile_libm, energy_libm, nu_libm, layer_libm) = view(libm, energy);
                let bits = |tile: &[f32]| tile.iter().map(|v| v.to_bits()).collect::<Vec<u32>>();
                let relative = |a: f64, b: f64| if b > 0.0 { (a - b).abs() / b } else { a.abs() };
                Row {
                    image,
                    tile: bits(&tile_fast) != bits(&tile_libm),
                    energy: energy_fast.iter().zip(&energy_libm).fold(0.0f64, |m, (&a, &b)| m.max(relative(a, b))),
                    view: relative(nu_fast, nu_libm),
                    layer: layer_fast != layer_libm,
                }
            })
            .collect();
        let image = rows.iter().fold(0.0f64, |m, r| m.max(r.image));
        let tiles = rows.iter().filter(|r| r.tile).count();
        let energy = rows.iter().fold(0.0f64, |m, r| m.max(r.energy));
        let view = rows.iter().fold(0.0f64, |m, r| m.max(r.view));
        let layers = rows.iter().filter(|r| r.layer).count();
        let name = std::path::Path::new(&path).file_stem().map_or(path.clone(), |s| s.to_string_lossy().into_owned());
        println!("{name}  {image:.3e}  {tiles} of {}  {energy:.3e}  {view:.3e}  {layers}", config.lobes);
        differs |= tiles > 0 || layers > 0;
    }
    if differs { ExitCode::from(1) } else { ExitCode::SUCCESS }
}
