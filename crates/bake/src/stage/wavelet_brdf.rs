//! Haar wavelet encoding of a material (`brdf-wavelet`; `004` sections 4-5, crate
//! `wavelet-brdf`): the asset of kind `wavelet-brdf`, Table 1's errors of the reconstruction
//! against the resampled table, and a picture of a few slices before and after.

use std::f64::consts::FRAC_PI_2;

use merl::MerlTable;
use picture::colormap::{Scale, inferno, viridis};
use picture::layout::{Axis, Grid as Panels, caption, heat_map, stack};
use picture::legend::Legend;
use picture::{Canvas, format_number};
use serde_json::json;
use wavelet_brdf::{Config, Decoded, Grid, Keep, Resampled};

use crate::{Error, OutFile, Program, Source, Staged, object};

pub const ASSET: &str = "wavelet-brdf.asset";
pub const PICTURE: &str = "wavelet-brdf.png";

/// The stage's settings: the grid side and the encoding.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    pub side: usize,
    pub config: Config,
}

impl Default for Settings {
    fn default() -> Settings {
        Settings { side: wavelet_brdf::DEFAULT_SIDE, config: Config::default() }
    }
}

impl Settings {
    /// Refuses settings the stage cannot run, before any work.
    pub fn check(&self) -> Result<(), Error> {
        if self.side > MAX_SIDE {
            return Err(Error::Invalid(format!(
                "a {0} x {0} grid needs {1:.1} GB of working memory: use a side of at most {MAX_SIDE}",
                self.side,
                (self.side as f64).powi(4) * 3.0 * 8.0 * 3.0 / 1e9
            )));
        }
        let grid = Grid::new(self.side).map_err(|e| Error::Invalid(e.to_string()))?;
        self.config.check(grid).map_err(|e| Error::Invalid(e.to_string()))
    }

    /// The settings as the stage's manifest entry records them.
    pub fn parameters(&self) -> serde_json::Map<String, serde_json::Value> {
        object([
            ("side", json!(self.side)),
            ("epsilon", json!(self.config.epsilon)),
            ("keep", json!(keep_name(self.config.keep))),
            ("quantize", json!(self.config.quantize)),
        ])
    }
}

fn keep_name(keep: Keep) -> String {
    match keep {
        Keep::All => "all".to_string(),
        Keep::Ratio(r) => format!("ratio {r}"),
        Keep::Threshold(t) => format!("threshold {t}"),
    }
}

/// The largest grid side the stage accepts: `(64 x 64)^2` samples already hold 1.2 GB of `f64`
/// working values (three copies of `3 n^4` values); the paper used 32.
pub const MAX_SIDE: usize = 64;

/// Resamples `table`, encodes it and measures the reconstruction (module docs).
pub fn run(table: &MerlTable, source: &Source, program: &Program, settings: Settings) -> Result<Staged, Error> {
    settings.check()?;
    let grid = Grid::new(settings.side).map_err(|e| Error::Invalid(e.to_string()))?;
    let resampled = wavelet_brdf::resample_table(grid, table);
    let encoded = wavelet_brdf::encode(&resampled, settings.config).map_err(|e| Error::Invalid(e.to_string()))?;
    let brdf = Decoded::from_payload(&encoded.payload).map_err(|e| Error::Internal(e.to_string()))?;
    let decoded = brdf.decode(0);
    let errors = wavelet_brdf::errors(&resampled.values, &decoded, brdf.floor());

    let config = settings.config;
    let keep = keep_name(config.keep);
    let parameters = [
        ("side", settings.side.to_string()),
        ("epsilon", config.epsilon.to_string()),
        ("keep", keep.clone()),
        ("quantize", if config.quantize { "8" } else { "none" }.to_string()),
    ];
    let asset = asset::encode_checked(&asset::Asset {
        provenance: source.provenance(program, &parameters),
        payload: encoded.payload.clone().into(),
    })
    .map_err(|e| Error::Internal(format!("encoding {ASSET}: {e}")))?;
    let raw_bytes = 4 * encoded.total_coefficients;
    let figure = picture(&source.file_name(), &resampled, &decoded, encoded.ratio());
    let png = envmap::encode_png_rgb8(figure.width, figure.height, &figure.rgb)
        .map_err(|e| Error::Internal(format!("encoding {PICTURE}: {e}")))?;

    let figures = object([
        ("side", json!(settings.side)),
        ("ratio", json!(encoded.ratio())),
        ("kept_positions", json!(encoded.kept_positions)),
        ("kept_coefficients", json!(encoded.kept_coefficients)),
        ("total_coefficients", json!(encoded.total_coefficients)),
        ("rms", json!(errors.rms)),
        ("mean_relative_error", json!(errors.mean_relative_error)),
        ("max_relative_error", json!(errors.max_relative_error)),
        ("mean_relative_error_above_floor", json!(errors.mean_relative_error_above_floor)),
        ("floor", json!(brdf.floor())),
        ("mean_value", json!(errors.mean_value)),
        ("log_squared_error_dropped", json!(encoded.dropped_energy)),
        ("no_data_samples", json!(resampled.no_data)),
        ("bytes", json!(asset.len())),
        ("raw_float_bytes", json!(raw_bytes)),
    ]);
    let n = settings.side;
    let lines = vec![
        format!(
            "grid              ({n} x {n})^2 direction pairs of the sphere parameterization, {} samples x 3 channels",
            n.pow(4)
        ),
        format!(
            "kept              {} of {} coefficient positions ({keep}): {} of {} coefficients, ratio {}:1",
            encoded.kept_positions,
            n * n,
            encoded.kept_coefficients,
            encoded.total_coefficients,
            format_number(encoded.ratio())
        ),
        format!(
            "storage           {} ({} bytes; the table as 32-bit floats: {raw_bytes} bytes)",
            if config.quantize { "8-bit codes" } else { "32-bit floats" },
            asset.len()
        ),
        format!(
            "rms               {:.5} (root mean square of f - f', 1/sr; mean value {:.4})",
            errors.rms, errors.mean_value
        ),
        format!(
            "relative error    mean {:.3}%, max {:.2}% (|f - f'| / f over the {} samples and channels with f > 0)",
            100.0 * errors.mean_relative_error,
            100.0 * errors.max_relative_error,
            errors.positive
        ),
        format!(
            "                  mean {:.3}% over the {} with f >= eps mu ({} {} {} 1/sr; below it the log encoding is \
             relative to eps mu, not to f)",
            100.0 * errors.mean_relative_error_above_floor,
            errors.above_floor,
            format_number(brdf.floor()[0]),
            format_number(brdf.floor()[1]),
            format_number(brdf.floor()[2])
        ),
        format!("log-domain error  {} (sum of squares of the dropped coefficients)", encoded.dropped_energy),
    ];
    let mut problems = Vec::new();
    if resampled.no_data > 0 {
        problems.push(format!(
            "{} of {} samples fall where the table holds no data; they were encoded as 0",
            resampled.no_data,
            resampled.values.len()
        ));
    }
    Ok(Staged {
        name: "wavelet-brdf",
        parameters: settings.parameters(),
        figures,
        files: vec![
            OutFile { name: ASSET.into(), format: asset::FileFormat::Asset, role: "wavelet-brdf", bytes: asset },
            OutFile { name: PICTURE.into(), format: asset::FileFormat::Png, role: "wavelet-brdf-picture", bytes: png },
        ],
        report: lines,
        problems,
    })
}

/// The outgoing cell nearest `(sin theta_o, 0, cos theta_o)`.
fn outgoing_cell(grid: Grid, theta_o: f64) -> usize {
    let wo = glam::DVec3::new(theta_o.sin(), 0.0, theta_o.cos());
    let weights = grid.bilinear(wo).expect("above the horizon");
    weights.iter().max_by(|a, b| a.1.total_cmp(&b.1)).expect("four cells").0
}

/// Three outgoing elevations, each as the slice of incoming directions before encoding, after,
/// and their relative difference.
fn picture(name: &str, original: &Resampled, decoded: &[[f64; 3]], ratio: f64) -> Canvas {
    let grid = original.grid;
    let (n, cells) = (grid.side(), grid.cells());
    let luminance = |v: &[f64; 3]| color::luminance(*v);
    let peak = original.values.iter().map(luminance).fold(0.0f64, f64::max).max(1e-12);
    let value_scale = Scale::log(peak * 1e-4, peak);
    let error_scale = Scale::log(1e-4, 1.0);
    let zoom = (192 / n).max(1);
    let axes = (Axis::new("theta, degrees", 0.0, 180.0), Axis::new("phi, degrees", 0.0, 180.0));
    let mut panels = Panels::new(3);
    panels.title(format!(
        "wavelet encoding of {name} at {}:1: slices of wi for three view directions",
        format_number(ratio)
    ));
    let (mut below, mut above) = (false, false);
    for degrees in [10.0f64, 45.0, 75.0] {
        let o = outgoing_cell(grid, degrees.to_radians().min(FRAC_PI_2));
        let slice =
            |values: &[[f64; 3]]| -> Vec<f64> { (0..cells).map(|i| luminance(&values[o * cells + i])).collect() };
        let (before, after) = (slice(&original.values), slice(decoded));
        let shade = |v: f64, scale: &Scale, map: fn(f64) -> [u8; 3]| {
            if v > 0.0 { map(scale.position(v).clamp(0.0, 1.0)) } else { [0, 0, 0] }
        };
        let image = |values: &[f64]| Canvas::from_fn(n, n, |x, y| shade(values[y * n + x], &value_scale, inferno));
        let relative: Vec<f64> =
            before.iter().zip(&after).map(|(a, b)| if *a > 0.0 { (a - b).abs() / a } else { 0.0 }).collect();
        let (lo, hi) = error_scale.clipping(&relative.iter().copied().filter(|r| *r > 0.0).collect::<Vec<_>>());
        below |= lo;
        above |= hi;
        let errors = Canvas::from_fn(n, n, |x, y| shade(relative[y * n + x], &error_scale, viridis));
        let theta_o = format_number((grid.direction(o).z.acos().to_degrees() * 10.0).round() / 10.0);
        panels.add(heat_map(&image(&before), zoom, &axes.0, &axes.1), format!("resampled, theta_o {theta_o}\u{b0}"));
        panels.add(heat_map(&image(&after), zoom, &axes.0, &axes.1), format!("reconstructed, theta_o {theta_o}\u{b0}"));
        panels.add(heat_map(&errors, zoom, &axes.0, &axes.1), format!("|f - f'| / f, theta_o {theta_o}\u{b0}"));
    }
    let width = panels.width();
    let values = Legend::new(value_scale, inferno, "f (luminance), 1/sr (log scale); black: 0").clipped((true, false));
    let errors = Legend::new(error_scale, viridis, "relative error |f - f'| / f (log scale); black: exact or f = 0")
        .clipped((below, above));
    let text = "Each panel is one slice: the incoming directions (theta, phi) of the sphere parameterization for one \
                outgoing direction, wi = (sin phi cos theta, cos phi, sin theta sin phi) with the normal at the centre \
                (90, 90) and the tangent poles at phi = 0 and 180. The mirror direction of a view at theta_o lies at \
                theta = 90 + theta_o, phi = 90.";
    panels.footer(stack(&[values.render(width), errors.render(width), caption(text, width)]));
    panels.render()
}
