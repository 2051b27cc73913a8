//! Importance-sampling tables of a material (`merl-importance`; `001` section 3.3): the asset of
//! kind `importance-samples` and a picture of the samples over the lobe, validated by quadrature
//! (relative variance against cosine sampling, and the albedo the stored samples estimate).

mod picture;

use importance::quality::{albedo_estimate, slice_quality};
use importance::{Config, ImportanceTables};
use merl::MerlTable;
use merl::albedo::Quadrature;
use serde_json::json;

use crate::{Error, OutFile, Program, Source, Staged, object};

pub const ASSET: &str = "importance.asset";
pub const PICTURE: &str = "importance.png";

/// Slices drawn in the picture and measured: the ones nearest these elevations.
pub const SHOWN_DEG: [f64; 4] = [0.0, 30.0, 60.0, 80.0];
/// Relative variance above which a measured slice is a problem.
pub const RV_LIMIT: f64 = 0.1;

/// Builds the tables of `table` (read from `source`) with `config`; with `measure`, also measures
/// the slices nearest [`SHOWN_DEG`] by quadrature (about a second for the default tables).
pub fn run(
    table: &MerlTable,
    source: &Source,
    program: &Program,
    config: &Config,
    measure: bool,
) -> Result<Staged, Error> {
    run_measured(table, source, program, config, measure).map(|(staged, _)| staged)
}

/// The directional albedo at measured slices: `theta_o` in degrees, RGB.
pub type Albedos = Vec<(f64, [f64; 3])>;

/// [`run`], and with `measure` the directional albedo its quadrature found at each measured slice
/// (nearest lookups): what a bake holds to `UNPHYSICAL_LIMIT`.
pub fn run_measured(
    table: &MerlTable,
    source: &Source,
    program: &Program,
    config: &Config,
    measure: bool,
) -> Result<(Staged, Albedos), Error> {
    let tables = importance::build(table, config).map_err(|e| Error::stage("importance", e))?;
    let payload = payload(config, &tables);
    let provenance = source.provenance(program, &provenance_parameters(config));
    let asset = asset::encode_checked(&asset::Asset { provenance, payload: payload.into() })
        .map_err(|e| Error::Internal(format!("encoding {ASSET}: {e}")))?;
    let shown = shown_slices(config);
    let picture = picture::lobes(&source.stem(), table, &tables, &shown, 256);
    let png = envmap::encode_png_rgb8(picture.width, picture.height, &picture.rgb)
        .map_err(|e| Error::Internal(format!("encoding {PICTURE}: {e}")))?;

    let mut figures = object([
        ("slices", json!(config.n_theta_o)),
        ("vectors", json!(config.n_vectors)),
        ("samples", json!(config.n_samples)),
    ]);
    let mut report = vec![format!(
        "{} slices (theta_o = k / {} x 90 degrees) x {} vectors x {} samples",
        config.n_theta_o, config.n_theta_o, config.n_vectors, config.n_samples
    )];
    let mut problems = Vec::new();
    let mut albedo = Vec::new();
    if measure {
        let measured = measure_slices(table, &tables, &shown);
        albedo.extend(measured.iter().map(|m| (m.theta_o_deg, m.albedo)));
        report.extend(report_lines(&measured));
        for m in &measured {
            if m.rv > RV_LIMIT {
                problems.push(format!(
                    "relative variance {:.4} above {RV_LIMIT} at theta_o {:.1} degrees",
                    m.rv, m.theta_o_deg
                ));
            }
        }
        figures.insert("measured".into(), json!(measured.iter().map(Measured::json).collect::<Vec<_>>()));
    }
    let staged = Staged {
        name: "importance",
        parameters: object([
            ("theta_o", json!(config.n_theta_o)),
            ("theta_h_subdivision", json!(config.theta_h_subdivision)),
            ("phi_h", json!(config.n_phi_h)),
            ("supersampling", json!(config.supersampling)),
            ("defensive", json!(config.defensive)),
            ("vectors", json!(config.n_vectors)),
            ("samples", json!(config.n_samples)),
            ("seed", json!(config.seed)),
        ]),
        figures,
        files: vec![
            OutFile { name: ASSET.into(), format: asset::FileFormat::Asset, role: "importance-samples", bytes: asset },
            OutFile { name: PICTURE.into(), format: asset::FileFormat::Png, role: "importance-picture", bytes: png },
        ],
        report,
        problems,
    };
    Ok((staged, albedo))
}

/// The slices nearest to [`SHOWN_DEG`], without repeats.
fn shown_slices(config: &Config) -> Vec<usize> {
    let mut out: Vec<usize> = SHOWN_DEG
        .iter()
        .map(|deg| ((deg / 90.0 * config.n_theta_o as f64).round() as usize).min(config.n_theta_o - 1))
        .collect();
    out.dedup();
    out
}

/// What the quadrature says of one slice.
struct Measured {
    theta_o_deg: f64,
    rv: f64,
    rv_cos: f64,
    upper_mass: f64,
    albedo: [f64; 3],
    /// Relative error of the albedo the slice's stored samples estimate.
    estimate_error: [f64; 3],
}

impl Measured {
    fn json(&self) -> serde_json::Value {
        json!({
            "theta_o_deg": self.theta_o_deg,
            "relative_variance": self.rv,
            "relative_variance_cosine": self.rv_cos,
            "upper_hemisphere_mass": self.upper_mass,
            "albedo_rgb": self.albedo,
            "samples_albedo_relative_error_rgb": self.estimate_error,
        })
    }
}

fn measure_slices(table: &MerlTable, tables: &ImportanceTables, shown: &[usize]) -> Vec<Measured> {
    shown
        .iter()
        .map(|&k| {
            let slice = &tables.slices()[k];
            let q = slice_quality(table, slice, Quadrature::default());
            let estimate = albedo_estimate(table, slice, tables.slice_samples(k));
            let estimate_error =
                std::array::from_fn(|c| if q.albedo[c] > 0.0 { estimate[c] / q.albedo[c] - 1.0 } else { 0.0 });
            Measured {
                theta_o_deg: q.theta_o.to_degrees(),
                rv: q.rv,
                rv_cos: q.rv_cos,
                upper_mass: q.upper_mass,
                albedo: q.albedo,
                estimate_error,
            }
        })
        .collect()
}

fn report_lines(measured: &[Measured]) -> Vec<String> {
    let mut lines = vec![
        "theta_o  relative variance         upper     albedo by quadrature     error of the samples' albedo".into(),
        "  (deg)   tables   cosine   ratio   mass       red  green   blue       red  green   blue".into(),
    ];
    for m in measured {
        lines.push(format!(
            "{:>7.1} {:>8.5} {:>8.4} {:>7.5} {:>7.5}   {:.4} {:.4} {:.4}   {:+.2}% {:+.2}% {:+.2}%",
            m.theta_o_deg,
            m.rv,
            m.rv_cos,
            m.rv / m.rv_cos,
            m.upper_mass,
            m.albedo[0],
            m.albedo[1],
            m.albedo[2],
            100.0 * m.estimate_error[0],
            100.0 * m.estimate_error[1],
            100.0 * m.estimate_error[2]
        ));
    }
    lines.push(
        "relative variance: Var(L f cos / pdf) / E^2 of one sample (luminance), with the tables and with cosine \
         sampling; upper mass: the share of the density above the horizon; albedo by quadrature uses the nearest \
         lookup"
            .into(),
    );
    lines
}

fn provenance_parameters(config: &Config) -> [(&'static str, String); 8] {
    [
        ("theta_o", config.n_theta_o.to_string()),
        ("theta_h_rows", format!("90 MERL cells x {}", config.theta_h_subdivision)),
        ("phi_h", config.n_phi_h.to_string()),
        ("supersampling", config.supersampling.to_string()),
        ("defensive", config.defensive.to_string()),
        ("vectors", config.n_vectors.to_string()),
        ("samples", config.n_samples.to_string()),
        ("seed", config.seed.to_string()),
    ]
}

/// The asset's payload, converted by hand from the crate's tables (f32 for textures).
fn payload(config: &Config, tables: &ImportanceTables) -> asset::ImportanceSamples {
    let f32s = |v: &[f64]| v.iter().map(|x| *x as f32).collect::<Vec<f32>>();
    let mut marginal_cdf = Vec::new();
    let mut conditional_cdf = Vec::new();
    let mut h_density = Vec::new();
    for slice in tables.slices() {
        let d = slice.distribution();
        marginal_cdf.extend(f32s(d.marginal().cdf()));
        conditional_cdf.extend(f32s(d.conditional_cdf()));
        for iv in 0..d.nv() {
            h_density.extend((0..d.nu()).map(|iu| slice.h_density([iu, iv]) as f32));
        }
    }
    let samples = tables.sample_texels();
    asset::ImportanceSamples {
        theta_o: tables.slices().iter().map(|s| s.theta_o()).collect(),
        n_vectors: config.n_vectors as u32,
        n_samples: config.n_samples as u32,
        theta_h_edges: tables.rows().theta_edges(),
        n_phi_h: config.n_phi_h as u32,
        samples,
        marginal_cdf,
        conditional_cdf,
        h_density,
    }
}
