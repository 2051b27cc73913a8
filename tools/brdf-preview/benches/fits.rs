//! How close `brdf-fit`'s glTF material comes to each measured table, in pictures (a benchmark,
//! not a test): for each of the 20 real-derived materials, the fit at its defaults
//! (`gltf_fit::fit`), the kept variant's parameters, objective and directional albedo error, and
//! for every variant (core, `KHR_materials_specular`, `KHR_materials_clearcoat`) its objective and
//! the PSNR of its exact render (its MERL table, `gltf_fit::fitted_table`) against the measured
//! table's, both by the converged estimator (`render::converged`: no baked table, 256 samples per
//! strategy, the same seed, so the two pictures share their noise) on a 128 x 128 sphere under
//! two maps, each with the camera of the Mitsuba benchmark that looks at its brightest light's
//! reflection: quarry_01 (a sun) and studio_small_03 (lamps). PSNR on the 8-bit pictures after
//! the previewer's tone mapping of the map, over the sphere's pixels only.
//!
//! Whether the objective predicts the pictures: per map, how often the variant of least objective
//! is the one of best PSNR, and what the kept variant loses against the best. Which objective
//! draws the better pictures: each material fitted again with the other objective
//! (`Objective::LinearCosine` beside the default `LogCosine`), its kept variant's PSNR per map
//! beside the default's, and per map how often each wins. Beside a published figure: the kept
//! fits' roughness and diffuse albedo against Ngan et al. 2005's Lafortune fits of the same
//! materials (`ngan2005-lafortune.csv`; [`published_table`] says how they are compared). The report
//! (markdown) is printed and written to target/bench-fits/report.md; the sorted plot of the kept
//! variants' PSNRs to docs/brdf-fit-psnr.png, which the report shows.
//!
//! `cargo bench -p brdf-preview --bench fits [-- --only NAME]`. Needs `../shared` (the maps, and
//! nbrdf2merl.py with numpy for the materials, made once under target/merl/). About 50 s per
//! material on 2 cores (two fits and eight converged renders).

use std::path::PathBuf;

mod common;

use common::{Stamp, material_path, root, shared};
use envmap::MipChain;
use gltf_fit::{Objective, Settings, Variant};
use merl::MerlTable;
use picture::layout::{Axis, caption, heat_map, stack};
use picture::{BACKGROUND, Canvas, INK, TEXT_SCALE};
use render::{Camera, Image, Lighting, Material, SampleSet, Scene, metrics};

/// The 20 real-derived materials (the Makefile's test data).
const MATERIALS: [&str; 20] = [
    "alum-bronze",
    "black-obsidian",
    "blue-acrylic",
    "blue-rubber",
    "brass",
    "cherry-235",
    "chrome",
    "color-changing-paint3",
    "gold-paint",
    "gray-plastic",
    "green-metallic-paint",
    "nickel",
    "pink-fabric",
    "red-metallic-paint",
    "silver-metallic-paint",
    "steel",
    "teflon",
    "white-marble",
    "white-paint",
    "yellow-paint",
];

/// The maps, each with the Mitsuba benchmark's camera on its brightest light's reflection
/// (azimuth, elevation in degrees) and the colour of its dots in the plot.
const MAPS: [(&str, f32, f32, [u8; 3]); 2] =
    [("quarry_01_1k", -144.0, 10.0, [250, 160, 40]), ("studio_small_03_1k", 82.8, 43.1, [90, 170, 250])];

const SIZE: usize = 128;
const SAMPLES_PER_STRATEGY: u32 = 256;
const SEED: u64 = 7;

fn work() -> PathBuf {
    root().join("target/bench-fits")
}

/// One map of [`MAPS`]: its lighting (level 0 and its importance sampling are all the converged
/// estimator reads), the previewer's tone mapping of it, and the sphere seen from its camera.
struct Case {
    lighting: Lighting,
    tone: envmap::ToneMapping,
    scene: Scene,
}

impl Case {
    fn new(name: &str, azimuth: f32, elevation: f32) -> Case {
        let map = envmap::load(&shared().join(format!("data/env/{name}.hdr"))).expect("the map");
        let camera =
            Camera::orbit(glam::Vec3::ZERO, 3.2, azimuth.to_radians(), elevation.to_radians(), 45f32.to_radians())
                .expect("the camera");
        Case {
            lighting: Lighting::new(MipChain::new(&map), Vec::new(), Vec::new()).expect("the lighting"),
            tone: metrics::auto_tone_mapping(&map),
            scene: Scene { mesh: preview::mesh("sphere").expect("the sphere"), camera, width: SIZE, height: SIZE },
        }
    }
}

/// The converged estimator reads the table alone: no samples, no layers.
fn material(table: MerlTable) -> Material {
    let samples = SampleSet { n_slices: 0, n_vectors: 0, n_samples: 0, texels: Vec::new(), tables: Vec::new() };
    Material::new(table, samples, Vec::new())
}

/// PSNR of `a` against `b` (8-bit RGB) over the covered pixels.
fn sphere_psnr(a: &[u8], b: &[u8], covered: &[bool]) -> f64 {
    let pick = |p: &[u8]| -> Vec<u8> {
        p.chunks_exact(3).zip(covered).filter(|(_, c)| **c).flat_map(|(rgb, _)| rgb.iter().copied()).collect()
    };
    metrics::psnr_db(&pick(a), &pick(b))
}

/// The variants in the order of the report's columns.
const VARIANTS: [Variant; 3] = [Variant::Core, Variant::Specular, Variant::Clearcoat];

struct Row {
    name: &'static str,
    fit: gltf_fit::Fit,
    albedo: Vec<gltf_fit::AlbedoRow>,
    /// The kept variant's PSNR per map.
    psnr: Vec<f64>,
    /// Per variant ([`VARIANTS`]), its PSNR per map.
    by_variant: Vec<Vec<f64>>,
    /// The kept variant of the fit with the other objective ([`other_objective`]): its PSNR per map.
    other: Vec<f64>,
}

/// The objective the fits are compared with: the one the settings do not use.
fn other_objective(settings: &Settings) -> Objective {
    match settings.objective {
        Objective::LogCosine => Objective::LinearCosine,
        Objective::LinearCosine => Objective::LogCosine,
    }
}

fn main() {
    let only = std::env::args().skip_while(|a| a != "--only").nth(1);
    std::fs::create_dir_all(work()).expect("creating target/bench-fits");
    let settings = Settings::default();
    let cases: Vec<Case> = MAPS.iter().map(|(name, az, el, _)| Case::new(name, *az, *el)).collect();
    let rows: Vec<Row> = MATERIALS
        .into_iter()
        .filter(|n| only.as_ref().is_none_or(|o| n.contains(o.as_str())))
        .map(|name| measure(name, &settings, &cases))
        .collect();
    let complete = rows.len() == MATERIALS.len();
    if complete {
        let png = plot(&rows);
        std::fs::write(
            root().join("docs/brdf-fit-psnr.png"),
            envmap::encode_png_rgb8(png.width, png.height, &png.rgb).expect("encoding the plot"),
        )
        .expect("writing docs/brdf-fit-psnr.png");
    }
    let report = report(&rows, &settings, complete);
    print!("{report}");
    std::fs::write(work().join("report.md"), &report).expect("writing the report");
}

/// Fits the material `name` and renders the measured table and every variant's under each case.
fn measure(name: &'static str, settings: &Settings, cases: &[Case]) -> Row {
    let start = std::time::Instant::now();
    let bytes = merl::read_bytes(&material_path(name)).expect("the table");
    let table = MerlTable::parse(&bytes).expect("the table");
    let fit = gltf_fit::fit(&table, settings);
    let tables: Vec<MerlTable> = VARIANTS
        .iter()
        .map(|&v| gltf_fit::fitted_table(&fit.variant(v).material, settings.masking, table.dims()))
        .collect();
    let chosen = VARIANTS.iter().position(|&v| v == fit.chosen).expect("a variant");
    let albedo = gltf_fit::albedo_rows(&table, &tables[chosen]);
    let measured = material(table);
    let mut fitted: Vec<Material> = tables.into_iter().map(material).collect();
    // The kept variant of the fit with the other objective, drawn after the variants.
    let other_settings = Settings { objective: other_objective(settings), ..*settings };
    let other = gltf_fit::fit(&measured.table, &other_settings);
    fitted.push(material(gltf_fit::fitted_table(
        &other.variant(other.chosen).material,
        settings.masking,
        measured.table.dims(),
    )));
    // Per case, each variant's PSNR.
    let per_case: Vec<Vec<f64>> = cases
        .iter()
        .map(|case| {
            let render = |m: &Material| -> Image {
                render::converged::converged(&case.scene, m, &case.lighting, SAMPLES_PER_STRATEGY, SEED)
                    .expect("the converged estimate")
            };
            let truth = render(&measured);
            let truth_picture = metrics::tonemap(&truth, &case.tone);
            fitted
                .iter()
                .map(|m| sphere_psnr(&metrics::tonemap(&render(m), &case.tone), &truth_picture, &truth.covered))
                .collect()
        })
        .collect();
    let by_variant: Vec<Vec<f64>> = (0..VARIANTS.len()).map(|v| per_case.iter().map(|p| p[v]).collect()).collect();
    let other: Vec<f64> = per_case.iter().map(|p| p[VARIANTS.len()]).collect();
    let psnr = by_variant[chosen].clone();
    eprintln!(
        "{name}: {} {} ({:.1} s)",
        fit.chosen.name(),
        psnr.iter().map(|p| format!("{p:.2} dB")).collect::<Vec<_>>().join(", "),
        start.elapsed().as_secs_f64()
    );
    Row { name, fit, albedo, psnr, by_variant, other }
}

/// The report (markdown) of `rows`; with every material (`complete`), it shows the plot.
fn report(rows: &[Row], settings: &Settings, complete: bool) -> String {
    let mut lines = vec![
        "# brdf-fit: the glTF material against the measured table".to_string(),
        String::new(),
        format!("Measured at {}.", Stamp::now()),
        String::new(),
        format!(
            "Fits at brdf-fit's defaults (objective {}, masking {}, a variant with an extension kept when {}% lower). \
             PSNR: the fit's MERL table against the measured one, both by the converged estimator ({SAMPLES_PER_STRATEGY} \
             samples per strategy, one seed), {SIZE} x {SIZE} sphere, the sphere's pixels, 8-bit after the map's tone \
             mapping; cameras on the brightest light's reflection. Albedo error: the fit's directional albedo (luminance) \
             against the table's at theta_o 0 / 30 / 60 / 80 degrees.",
            settings.objective.name(),
            settings.masking.name(),
            settings.margin * 100.0
        ),
        String::new(),
    ];
    lines.extend(kept_table(rows));
    lines.push(String::new());
    lines.extend(variant_table(rows));
    lines.push(String::new());
    lines.extend(objective_table(rows, settings));
    lines.push(String::new());
    lines.extend(summaries(rows));
    lines.push(String::new());
    lines.extend(published_table(rows));
    if complete {
        lines.push(String::new());
        lines.push("![The fit's PSNR per material and map, sorted](brdf-fit-psnr.png)".into());
    }
    lines.iter().map(|l| format!("{l}\n")).collect()
}

/// The maps' names, in the order of [`MAPS`] (a row's PSNRs).
fn map_names() -> Vec<&'static str> {
    MAPS.iter().map(|m| m.0).collect()
}

/// The kept material of each row: factors, objective, albedo error, PSNR per map.
fn kept_table(rows: &[Row]) -> Vec<String> {
    let mut lines = vec![
        "## The kept material".to_string(),
        String::new(),
        format!(
            "| material | variant | baseColor | metallic | roughness | specular | specularColor | clearcoat | \
             clearcoatRoughness | objective | albedo error % | {} |",
            map_names().iter().map(|m| format!("{m} dB")).collect::<Vec<_>>().join(" | ")
        ),
        format!("|---|---|---|---:|---:|---:|---|---:|---:|---:|---|{}", "---:|".repeat(MAPS.len())),
    ];
    let triple = |v: [f64; 3]| format!("{:.3} {:.3} {:.3}", v[0], v[1], v[2]);
    for r in rows {
        let chosen = r.fit.chosen();
        let m = &chosen.material;
        let variant = chosen.variant.name();
        let albedo: Vec<String> = r.albedo.iter().map(|a| format!("{:+.1}", 100.0 * a.relative_error())).collect();
        lines.push(format!(
            "| {} | {variant} | {} | {:.3} | {:.3} | {:.3} | {} | {:.3} | {:.3} | {:.2e} | {} | {} |",
            r.name,
            triple(m.base_color),
            m.metallic,
            m.roughness,
            m.specular,
            triple(m.specular_color),
            m.clearcoat,
            m.clearcoat_roughness,
            chosen.objective,
            albedo.join(" / "),
            r.psnr.iter().map(|p| format!("{p:.2}")).collect::<Vec<_>>().join(" | ")
        ));
    }
    lines
}

/// Every variant of each row: its objective and its PSNR per map, the kept one marked.
fn variant_table(rows: &[Row]) -> Vec<String> {
    let header: Vec<String> = VARIANTS
        .iter()
        .flat_map(|v| {
            std::iter::once(format!("{} objective", v.name()))
                .chain(map_names().into_iter().map(move |m| format!("{} {m} dB", v.name())))
        })
        .collect();
    let mut lines = vec![
        "## Every variant: objective and PSNR (`*` the kept one)".to_string(),
        String::new(),
        format!("| material | {} |", header.join(" | ")),
        format!("|---|{}", "---:|".repeat(header.len())),
    ];
    for r in rows {
        let cells: Vec<String> = VARIANTS
            .iter()
            .zip(&r.by_variant)
            .flat_map(|(&v, psnr)| {
                let mark = if v == r.fit.chosen { "*" } else { "" };
                std::iter::once(format!("{:.2e}{mark}", r.fit.variant(v).objective))
                    .chain(psnr.iter().map(|p| format!("{p:.2}")))
            })
            .collect();
        lines.push(format!("| {} | {} |", r.name, cells.join(" | ")));
    }
    lines
}

/// Each material's kept fit under the default objective and under the other, PSNR per map, and
/// per map how often each draws the better picture.
fn objective_table(rows: &[Row], settings: &Settings) -> Vec<String> {
    let (ours, other) = (settings.objective.name(), other_objective(settings).name());
    let maps = map_names();
    let mut lines = vec![
        format!("## The objective against the pictures: {ours} (the default) and {other}"),
        String::new(),
        format!(
            "| material | {} |",
            maps.iter().map(|m| format!("{m}: {ours} / {other} dB")).collect::<Vec<_>>().join(" | ")
        ),
        format!("|---|{}", "---:|".repeat(maps.len())),
    ];
    for r in rows {
        let cells: Vec<String> = (0..maps.len()).map(|k| format!("{:.2} / {:.2}", r.psnr[k], r.other[k])).collect();
        lines.push(format!("| {} | {} |", r.name, cells.join(" | ")));
    }
    lines.push(String::new());
    for (k, map) in maps.iter().enumerate() {
        let wins = rows.iter().filter(|r| r.psnr[k] > r.other[k]).count();
        let mut gain: Vec<f64> = rows.iter().map(|r| r.psnr[k] - r.other[k]).collect();
        gain.sort_by(f64::total_cmp);
        if !gain.is_empty() {
            lines.push(format!(
                "{map}: {ours} draws the better picture for {wins} of {} materials; its PSNR minus {other}'s: median \
                 {:+.2} dB, from {:+.2} to {:+.2}.",
                rows.len(),
                median(&gain),
                gain[0],
                gain[gain.len() - 1]
            ));
        }
    }
    lines
}

/// Per map: whether the least objective draws the best picture, and the kept fits' PSNRs.
fn summaries(rows: &[Row]) -> Vec<String> {
    let mut lines = Vec::new();
    for (k, map) in map_names().iter().enumerate() {
        // The variant of least objective against the variant of best picture.
        let objective = |r: &Row, v: usize| r.fit.variant(VARIANTS[v]).objective;
        let least = |r: &Row| (0..VARIANTS.len()).min_by(|&a, &b| objective(r, a).total_cmp(&objective(r, b)));
        let best = |r: &Row| (0..VARIANTS.len()).max_by(|&a, &b| r.by_variant[a][k].total_cmp(&r.by_variant[b][k]));
        let agree = rows.iter().filter(|r| least(r) == best(r)).count();
        let mut loss: Vec<f64> = rows.iter().filter_map(|r| Some(r.by_variant[best(r)?][k] - r.psnr[k])).collect();
        loss.sort_by(f64::total_cmp);
        if let Some(worst) = loss.last() {
            lines.push(format!(
                "{map}: the variant of least objective draws the best picture for {agree} of {} materials; the kept \
                 variant's picture is {:.2} dB below the best variant's at the median, {worst:.2} dB at most.",
                rows.len(),
                median(&loss)
            ));
        }
    }
    lines.push(String::new());
    for (k, map) in map_names().iter().enumerate() {
        let mut v: Vec<f64> = rows.iter().map(|r| r.psnr[k]).collect();
        v.sort_by(f64::total_cmp);
        if let (Some(lo), Some(hi)) = (v.first(), v.last()) {
            lines.push(format!(
                "{map}: min {lo:.2} dB, median {:.2} dB, max {hi:.2} dB over {} materials.",
                median(&v),
                v.len()
            ));
        }
    }
    lines
}

/// Ngan et al. 2005's one-lobe Lafortune fits of the MERL materials (`ngan2005-lafortune.csv`,
/// whose comments say where the figures come from): per material, the diffuse albedo and the
/// lobe's exponent.
const NGAN_2005: &str = include_str!("ngan2005-lafortune.csv");

/// One material of [`NGAN_2005`].
struct Published {
    name: String,
    /// The Lambertian term's albedo, RGB.
    rho_d: [f64; 3],
    /// The lobe's exponent.
    n: f64,
}

fn ngan_2005() -> Vec<Published> {
    NGAN_2005
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("material,"))
        .map(|l| {
            let cells: Vec<&str> = l.split(',').collect();
            let num = |i: usize| cells[i].parse::<f64>().unwrap_or_else(|e| panic!("ngan2005-lafortune.csv: {l}: {e}"));
            Published { name: cells[0].to_string(), rho_d: [num(1), num(2), num(3)], n: num(4) }
        })
        .collect()
}

/// Beside a published figure: each row's kept fit against Ngan et al. 2005's Lafortune fit of
/// the same material, where the published set holds it. The lobe: a Lafortune lobe seen from
/// the normal is `cos^n` of the angle `beta` to the mirror direction (whatever its `C`, once
/// normalised), `1 - 2 n theta_h^2` near the peak (`beta = 2 theta_h`); GGX's `D` is
/// `1 - 2 theta_h^2 / alpha^2` there, so the lobes of equal curvature have `alpha = n^(-1/2)`
/// and glTF roughness `n^(-1/4)`. The diffuse part: Ngan's `rho_d` against the fit's
/// [`gltf_fit::Material::diffuse_albedo`], both as luminance.
fn published_table(rows: &[Row]) -> Vec<String> {
    let published = ngan_2005();
    let pairs: Vec<(&Row, &Published)> =
        rows.iter().filter_map(|r| published.iter().find(|p| p.name == r.name).map(|p| (r, p))).collect();
    let mut lines = vec![
        "## Beside a published figure: Ngan et al. 2005's Lafortune fits".to_string(),
        String::new(),
        format!(
            "Ngan, Durand and Matusik (EGSR 2005) fitted analytic models to each MERL measurement; their one-lobe \
             Lafortune fits hold {} of these {} materials (tools/brdf-preview/benches/ngan2005-lafortune.csv says \
             where the figures were read). What differs: the model (a Lafortune lobe around the mirror direction \
             and a Lambertian term; here glTF's GGX on the half vector with its Fresnel-weighted diffuse lobe), the \
             data (the MERL measurements; here tables rebuilt from neural fits of them, see \
             ../shared/data/nbrdf/README.md) and the error minimised (theirs; here ln(1 + f cos) over the cells). \
             Compared: the lobe's width, Ngan's exponent n as the glTF roughness of a GGX lobe of the same curvature \
             at the peak seen from the normal (n^(-1/4): cos^n(2 theta_h) and GGX's D both fall as 1 - 2 theta_h^2 \
             / alpha^2 there when alpha^2 = 1 / n), against the fit's roughness; and the diffuse albedo, Ngan's \
             rho_d against the fit's diffuse lobe's weight of baseColor where v.h = 1, (1 - metallic)(1 - max \
             dielectric f0) baseColor, both as luminance.",
            pairs.len(),
            rows.len()
        ),
        String::new(),
        "| material | Ngan n | Ngan n^(-1/4) | fit roughness | ratio | Ngan rho_d | fit diffuse albedo | ratio |"
            .into(),
        "|---|---:|---:|---:|---:|---:|---:|---:|".into(),
    ];
    let mut widths = (Vec::new(), Vec::new());
    let mut diffuse = (Vec::new(), Vec::new());
    for (r, Published { rho_d, n, .. }) in &pairs {
        let m = &r.fit.chosen().material;
        let (theirs, ours) = (n.powf(-0.25), m.roughness);
        let (rho, albedo) = (color::luminance(*rho_d), color::luminance(m.diffuse_albedo()));
        lines.push(format!(
            "| {} | {n} | {theirs:.3} | {ours:.3} | {:.2} | {rho:.4} | {albedo:.4} | {:.2} |",
            r.name,
            ours / theirs,
            albedo / rho
        ));
        widths.0.push(theirs);
        widths.1.push(ours);
        diffuse.0.push(rho);
        diffuse.1.push(albedo);
    }
    lines.push(String::new());
    for (what, (theirs, ours)) in [("roughness", &widths), ("diffuse albedo", &diffuse)] {
        let mut ratio: Vec<f64> = ours.iter().zip(theirs.iter()).map(|(o, t)| o / t).collect();
        ratio.sort_by(f64::total_cmp);
        if let (Some(lo), Some(hi), Some(rank)) = (ratio.first(), ratio.last(), bandwidth::spearman(theirs, ours)) {
            lines.push(format!(
                "The {what}: the fit's over Ngan's, median {:.2}, from {lo:.2} to {hi:.2}; Spearman's rank correlation \
                 over the {} materials {rank:.2}.",
                median(&ratio),
                ratio.len()
            ));
        }
    }
    lines
}

/// The median of sorted values (of an even count, the mean of the two middle ones).
fn median(sorted: &[f64]) -> f64 {
    let m = sorted.len() / 2;
    if sorted.len() % 2 == 1 { sorted[m] } else { (sorted[m - 1] + sorted[m]) / 2.0 }
}

/// One row per material, sorted by its lowest PSNR (worst at the top), a dot per map on a PSNR
/// axis, the material's name as the row's tick label; a legend of the maps below.
fn plot(rows: &[Row]) -> Canvas {
    // A row holds a label (14 pixels) and the gap heat_map keeps between labels.
    const ROW: usize = 20;
    const WIDTH: usize = 480;
    let mut order: Vec<&Row> = rows.iter().collect();
    let worst = |r: &Row| r.psnr.iter().copied().fold(f64::INFINITY, f64::min);
    order.sort_by(|a, b| worst(a).total_cmp(&worst(b)));
    let all = rows.iter().flat_map(|r| r.psnr.iter().copied());
    let lo = (all.clone().fold(f64::INFINITY, f64::min) / 5.0).floor() * 5.0;
    let hi = (all.fold(f64::NEG_INFINITY, f64::max) / 5.0).ceil() * 5.0;
    let x_of = |p: f64| (((p - lo) / (hi - lo)) * (WIDTH - 1) as f64).round() as isize;
    let mut image = Canvas::new(WIDTH, ROW * order.len(), BACKGROUND);
    for (i, r) in order.iter().enumerate() {
        let y = (i * ROW + ROW / 2) as isize;
        let xs: Vec<isize> = r.psnr.iter().map(|&p| x_of(p)).collect();
        let (a, b) = (*xs.iter().min().unwrap_or(&0), *xs.iter().max().unwrap_or(&0));
        image.hline(a, y, (b - a) as usize + 1, [110, 110, 110]);
        for (x, map) in xs.iter().zip(MAPS) {
            image.fill_rect(x - 3, y - 3, 7, 7, map.3);
        }
    }
    // Row i's centre is (i + 1/2) rows from the top, where heat_map counts a vertical axis from.
    let n = order.len() as f64;
    let ticks = order.iter().enumerate().map(|(i, r)| (i as f64 + 0.5, r.name.to_string())).collect();
    let y = Axis::new("material (worst first)", 0.0, n).with_ticks(ticks);
    // A tick every 5 dB (the axis's ends are multiples of 5).
    let steps = ((hi - lo) / 5.0).round() as usize;
    let x_ticks = (0..=steps).map(|k| lo + 5.0 * k as f64).map(|v| (v, format!("{v}"))).collect();
    let x = Axis::new("PSNR of the fit against the measured table, dB", lo, hi).with_ticks(x_ticks);
    let chart = heat_map(&image, 1, &x, &y);
    let width = chart.width;
    let title = caption(
        &format!(
            "brdf-fit's glTF material against the measured table: the converged estimate of each, {SIZE} x {SIZE} sphere, \
             camera on the brightest light's reflection"
        ),
        width,
    );
    let mut legend = Canvas::new(width, 14 * TEXT_SCALE, BACKGROUND);
    let mut x0 = 10;
    for (map, _, _, colour) in MAPS {
        legend.fill_rect(x0, 4, 10, 10, colour);
        legend.text(x0 + 16, 2, map, TEXT_SCALE, INK);
        x0 += 16 + picture::font::text_width(map, TEXT_SCALE) as isize + 24;
    }
    stack(&[title, chart, legend])
}
