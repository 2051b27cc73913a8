//! A material's validation summary (`merl-info`): dimensions, cells without data, per-channel
//! statistics, directional albedo by a half-vector quadrature and the peak (`merl::summary`), as
//! figures, a report and an asset of kind `material-info`; validation finds an albedo above what
//! an energy-conserving table can show, a cell that alone reflects more than the light received
//! (`merl::summary::cell_share`), or a noticeable share of the hemisphere without data. A bake
//! refuses a table far beyond the first two ([`unphysical`]).

use merl::albedo::Quadrature;
use merl::summary::{ChannelStats, Summary, summarize};
use merl::{Interp, MerlTable};
use serde_json::json;

use crate::{Error, OutFile, Program, Source, Staged, object};

pub const ASSET: &str = "material-info.asset";

/// Albedo above this is a problem: 1 plus what the discretization of a table of an
/// energy-conserving BRDF can add (measured: under 1% for normalized Phong up to n = 1000).
pub const ALBEDO_LIMIT: f64 = 1.01;
/// Share of the cosine-weighted hemisphere without data above which the table is flagged.
pub const NO_DATA_LIMIT: f64 = 0.01;
/// A table that reflects more than this many times the light it receives, at one of the
/// summary's elevations or through one cell alone (`merl::summary::cell_share`), is not a
/// material but corrupt data: a bake refuses it ([`unphysical`]). Far above [`ALBEDO_LIMIT`],
/// so that a measured table a little above 1 at grazing angles is flagged by `merl-info` and
/// still baked.
pub const UNPHYSICAL_LIMIT: f64 = 2.0;

/// The summary of `table` (read from `source`), its directional albedo integrated with
/// `albedo_interp` lookups.
pub fn run(table: &MerlTable, source: &Source, program: &Program, albedo_interp: Interp) -> Result<Staged, Error> {
    let quadrature = Quadrature::default();
    let summary = summarize(table, albedo_interp, quadrature);
    let parameters = [
        ("albedo_interp", interp_name(albedo_interp).to_string()),
        (
            "quadrature",
            format!("{} u nodes per theta_h cell x {} phi_h nodes", quadrature.nodes_per_cell, quadrature.n_phi_h),
        ),
    ];
    let provenance = source.provenance(program, &parameters);
    let payload = asset::Payload::MaterialInfo(material_info(&summary));
    let bytes = asset::encode_checked(&asset::Asset { provenance, payload })
        .map_err(|e| Error::Internal(format!("encoding {ASSET}: {e}")))?;
    Ok(Staged {
        name: "material-info",
        parameters: object([("albedo_interp", json!(interp_name(albedo_interp)))]),
        figures: figures(&summary, albedo_interp),
        files: vec![OutFile { name: ASSET.into(), format: asset::FileFormat::Asset, role: "material-info", bytes }],
        report: report(source, &summary, albedo_interp),
        problems: problems(&summary),
    })
}

fn interp_name(interp: Interp) -> &'static str {
    match interp {
        Interp::Nearest => "nearest",
        Interp::Trilinear => "trilinear",
    }
}

/// Why a table with `s` for its summary is not a material (values no measurement gives), in the
/// words of the validation problems (`merl-info`'s); empty when it may be baked. A bake takes the
/// summary of the cells alone (`merl::summary::summarize_cells`: the cell share) before anything
/// else, and the albedo from the importance stage's quadrature ([`unphysical_albedo`]), which
/// computes it anyway.
pub fn unphysical(s: &Summary) -> Vec<String> {
    energy_problems(s, UNPHYSICAL_LIMIT)
}

/// Why directional albedos `(theta_o in degrees, RGB)` are not a material's: each above
/// [`UNPHYSICAL_LIMIT`] (or NaN), in the words of [`unphysical`].
pub fn unphysical_albedo(albedo: &[(f64, [f64; 3])]) -> Vec<String> {
    albedo_problems(albedo.iter().copied(), UNPHYSICAL_LIMIT)
}

fn albedo_problems(albedo: impl Iterator<Item = (f64, [f64; 3])>, limit: f64) -> Vec<String> {
    albedo
        .filter(|(_, rgb)| rgb.iter().any(|v| v.is_nan() || *v > limit))
        .map(|(deg, rgb)| {
            format!(
                "albedo above {limit} at theta_o {deg} deg ({:.4e} {:.4e} {:.4e}): the table reflects more than it receives",
                rgb[0], rgb[1], rgb[2]
            )
        })
        .collect()
}

/// The albedos and the cell share above `limit`.
fn energy_problems(s: &Summary, limit: f64) -> Vec<String> {
    let mut out = albedo_problems(s.albedo.iter().map(|(deg, a)| (*deg, a.rgb)), limit);
    if let Some(c) = s.largest_share.filter(|c| c.share.is_nan() || c.share > limit) {
        out.push(format!(
            "cell ({}, {}, {}) (theta_i {:.1} deg, theta_o {:.1} deg) holds {:.4e} {:.4e} {:.4e} 1/sr: on its own it \
             reflects an estimated {:.4e} times the light received, above {limit}",
            c.cell.theta_h,
            c.cell.theta_d,
            c.cell.phi_d,
            c.theta_i.to_degrees(),
            c.theta_o.to_degrees(),
            c.rgb[0],
            c.rgb[1],
            c.rgb[2],
            c.share
        ));
    }
    out
}

fn problems(s: &Summary) -> Vec<String> {
    let mut out = energy_problems(s, ALBEDO_LIMIT);
    if s.channels.is_none() {
        out.push("no cell holds data".to_string());
    }
    for (deg, a) in &s.albedo {
        if a.no_data_fraction > NO_DATA_LIMIT {
            out.push(format!(
                "{:.1}% of the hemisphere above the horizon holds no data at theta_o {deg} deg",
                100.0 * a.no_data_fraction
            ));
        }
    }
    out
}

fn report(source: &Source, s: &Summary, albedo_interp: Interp) -> Vec<String> {
    let d = s.dims;
    let mut lines = Vec::new();
    lines.push(format!("file       {}", source.path.display()));
    lines.push(format!("dims       {} x {} x {} (theta_h x theta_d x phi_d)", d.n_theta_h, d.n_theta_d, d.n_phi_d));
    lines.push(format!(
        "no data    {} of {} cells per channel ({:.1}%)",
        s.no_data_cells,
        s.cells,
        100.0 * s.no_data_cells as f64 / s.cells as f64
    ));
    if let Some(ch) = &s.channels {
        lines.push("BRDF (1/sr)        red        green       blue".to_string());
        for (name, pick) in [("min", 0), ("max", 1), ("mean", 2)] {
            let v = ch.map(|c| [c.min, c.max, c.mean][pick]);
            lines.push(format!("  {name:<10} {:>11.5e} {:>11.5e} {:>11.5e}", v[0], v[1], v[2]));
        }
    }
    lines.push(format!("directional albedo ({} lookup), half-vector quadrature", interp_name(albedo_interp)));
    for (deg, a) in &s.albedo {
        lines.push(format!(
            "  theta_o {deg:>2} deg  {:.4} {:.4} {:.4}   no data {:.2}%",
            a.rgb[0],
            a.rgb[1],
            a.rgb[2],
            100.0 * a.no_data_fraction
        ));
    }
    if let Some(p) = &s.peak {
        lines.push(format!(
            "peak       {:.5e} {:.5e} {:.5e} (luminance {:.5e}) at cell ({}, {}, {}): theta_h {:.3} deg, theta_d {:.3} deg, phi_d {:.3} deg",
            p.rgb[0],
            p.rgb[1],
            p.rgb[2],
            p.luminance,
            p.cell.theta_h,
            p.cell.theta_d,
            p.cell.phi_d,
            p.at.theta_h.to_degrees(),
            p.at.theta_d.to_degrees(),
            p.at.phi_d.to_degrees()
        ));
    }
    if let Some(c) = &s.largest_share {
        lines.push(format!(
            "one cell   at most {:.3e} of the light received reflected by one cell alone: ({}, {}, {}), theta_i {:.1} \
             deg, theta_o {:.1} deg",
            c.share,
            c.cell.theta_h,
            c.cell.theta_d,
            c.cell.phi_d,
            c.theta_i.to_degrees(),
            c.theta_o.to_degrees()
        ));
    }
    lines
}

/// The summary's figures (`merl-info --json` prints them with the file, the problems and the files
/// written).
fn figures(s: &Summary, albedo_interp: Interp) -> serde_json::Map<String, serde_json::Value> {
    let d = s.dims;
    let channels = s.channels.map(|ch| {
        json!({
            "min": ch.map(|c| c.min),
            "max": ch.map(|c| c.max),
            "mean": ch.map(|c| c.mean),
        })
    });
    let albedo: Vec<_> = s
        .albedo
        .iter()
        .map(|(deg, a)| json!({ "theta_o_deg": deg, "rgb": a.rgb, "no_data_fraction": a.no_data_fraction }))
        .collect();
    let peak = s.peak.map(|p| {
        json!({
            "rgb": p.rgb,
            "luminance": p.luminance,
            "cell": [p.cell.theta_h, p.cell.theta_d, p.cell.phi_d],
            "theta_h_deg": p.at.theta_h.to_degrees(),
            "theta_d_deg": p.at.theta_d.to_degrees(),
            "phi_d_deg": p.at.phi_d.to_degrees(),
        })
    });
    object([
        ("dims", json!([d.n_theta_h, d.n_theta_d, d.n_phi_d])),
        ("cells", json!(s.cells)),
        ("no_data_cells", json!(s.no_data_cells)),
        ("channels", json!(channels)),
        ("albedo_interp", json!(interp_name(albedo_interp))),
        ("albedo", json!(albedo)),
        ("peak", json!(peak)),
        (
            "largest_cell_share",
            json!(s.largest_share.map(|c| json!({
                "share": c.share,
                "rgb": c.rgb,
                "cell": [c.cell.theta_h, c.cell.theta_d, c.cell.phi_d],
                "theta_i_deg": c.theta_i.to_degrees(),
                "theta_o_deg": c.theta_o.to_degrees(),
            }))),
        ),
    ])
}

/// The summary as the asset's payload.
fn material_info(s: &Summary) -> asset::MaterialInfo {
    let d = s.dims;
    let ch = s.channels.unwrap_or([ChannelStats { min: 0.0, max: 0.0, mean: 0.0 }; 3]);
    let (peak_rgb, peak_cell) = s
        .peak
        .map_or(([0.0; 3], [0; 3]), |p| (p.rgb, [p.cell.theta_h as u32, p.cell.theta_d as u32, p.cell.phi_d as u32]));
    asset::MaterialInfo {
        dims: [d.n_theta_h as u32, d.n_theta_d as u32, d.n_phi_d as u32],
        no_data_cells: s.no_data_cells as u64,
        channel_min: ch.map(|c| c.min),
        channel_max: ch.map(|c| c.max),
        channel_mean: ch.map(|c| c.mean),
        peak_rgb,
        peak_cell,
        albedo_theta_o: s.albedo.iter().map(|(deg, _)| deg.to_radians()).collect(),
        albedo_rgb: s.albedo.iter().map(|(_, a)| a.rgb).collect(),
        albedo_no_data_fraction: s.albedo.iter().map(|(_, a)| a.no_data_fraction).collect(),
    }
}
