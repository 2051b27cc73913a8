//! `asset-info`: shows what a baked asset file holds (header, provenance, checksum status and a
//! summary of the payload) as text or JSON, and checks the files it names beside it. The exit
//! status tells a script whether the file is valid (0), readable but damaged or stale (1: the
//! checksum does not match, or a file it names is missing or does not have the recorded
//! SHA-256), or unreadable (2).

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use asset::{
    Asset, Error, Header, ImportanceSamples, LinkedFile, LinkedStatus, MaterialInfo, Payload, PrefilteredEnvmap,
    Provenance, hex,
};
use clap::Parser;
use serde_json::{Value, json};

/// Show what a baked asset file holds: its header, where it came from, whether its checksum
/// matches, and a summary of its payload.
///
/// Exit status: 0 the asset is valid; 1 its checksum does not match its contents (the header is
/// still shown), or a file it names beside it (the KTX2, EXR and PNG files of a prefiltered
/// envmap) is missing or does not have the SHA-256 it records; 2 the file cannot be read, is not an asset, or is of a version or kind this
/// build does not know.
#[derive(Debug, Parser)]
#[command(version, allow_negative_numbers = true)]
struct Args {
    /// The asset file to inspect
    file: PathBuf,
    /// Print one JSON object instead of text
    #[arg(long)]
    json: bool,
}

/// What was found in a file whose header is valid.
#[derive(Debug)]
struct Report {
    header: Header,
    /// What the contents hash to.
    computed: [u8; 32],
    /// `None` when `computed` differs from the header's checksum: damaged contents are not
    /// decoded.
    asset: Option<Asset>,
}

fn main() -> ExitCode {
    cli::main(run)
}

fn run() -> anyhow::Result<ExitCode> {
    let args: Args = cli::args()?;
    let context = || format!("reading {}", args.file.display());
    let report = match asset::read_file_with_header(&args.file) {
        Ok((header, asset)) => Report { header, computed: header.checksum, asset: Some(asset) },
        Err(Error::ChecksumMismatch { header, computed }) => Report { header, computed, asset: None },
        Err(e) => return Err(e).with_context(context),
    };
    let dir = match args.file.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent,
        _ => std::path::Path::new("."),
    };
    let linked: Vec<(&LinkedFile, LinkedStatus)> = report.asset.as_ref().map_or_else(Vec::new, |asset| {
        asset
            .payload
            .linked_files()
            .into_iter()
            .map(|f| (f, asset::linked_file_status(dir, &f.name, &f.sha256)))
            .collect()
    });
    if args.json {
        let mut value = to_json(&report);
        value["linked_files"] = linked.iter().map(|(f, status)| linked_json(f, status)).collect();
        cli::outln!("{value:#}");
    } else {
        print_text(&report);
        print_linked(&linked);
    }
    let stale: Vec<String> = linked
        .iter()
        .filter_map(|(f, status)| match status {
            LinkedStatus::Matches => None,
            LinkedStatus::Missing => Some(format!("{} is missing", f.name)),
            LinkedStatus::Differs { .. } => Some(format!("{} does not have the sha256 the asset records", f.name)),
            LinkedStatus::Unreadable(e) => Some(format!("{} cannot be read: {e}", f.name)),
        })
        .collect();
    if !stale.is_empty() {
        eprintln!("error: checking {}: linked file {}", args.file.display(), stale.join("; "));
        return Ok(ExitCode::from(1));
    }
    if report.asset.is_some() {
        return Ok(ExitCode::SUCCESS);
    }
    let mismatch = Error::ChecksumMismatch { header: report.header, computed: report.computed };
    eprintln!("error: {:#}", anyhow::Error::new(mismatch).context(context()));
    Ok(ExitCode::from(1))
}

/// The files the asset names, each with what was found beside it.
fn print_linked(linked: &[(&LinkedFile, LinkedStatus)]) {
    if linked.is_empty() {
        return;
    }
    cli::outln!("linked files (beside the asset, checked against the sha256 it records)");
    for (f, status) in linked {
        let found = match status {
            LinkedStatus::Matches => "ok".to_string(),
            LinkedStatus::Missing => "MISSING".to_string(),
            LinkedStatus::Differs { found } => format!("DIFFERS (found sha256 {})", hex(found)),
            LinkedStatus::Unreadable(e) => format!("UNREADABLE ({e})"),
        };
        cli::outln!("  {:<22} {found}", f.name);
    }
}

fn linked_json(f: &LinkedFile, status: &LinkedStatus) -> Value {
    let (name, found) = match status {
        LinkedStatus::Matches => ("ok", Some(hex(&f.sha256))),
        LinkedStatus::Missing => ("missing", None),
        LinkedStatus::Differs { found } => ("differs", Some(hex(found))),
        LinkedStatus::Unreadable(_) => ("unreadable", None),
    };
    json!({ "name": f.name, "sha256": hex(&f.sha256), "status": name, "found_sha256": found })
}

fn print_text(report: &Report) {
    let header = &report.header;
    cli::outln!("header");
    cli::outln!("  magic            {} (ok)", asset::MAGIC.escape_ascii());
    cli::outln!("  format version   {}", header.version);
    cli::outln!("  kind             {} ({})", header.kind, header.kind.code());
    cli::outln!("  provenance       {} bytes", header.provenance_len);
    cli::outln!("  payload          {} bytes", header.payload_len);
    match &report.asset {
        None => {
            cli::outln!("checksum           MISMATCH");
            cli::outln!("  stored sha256    {}", hex(&header.checksum));
            cli::outln!("  computed sha256  {}", hex(&report.computed));
            cli::outln!("(contents not decoded: they are damaged)");
        }
        Some(asset) => {
            cli::outln!("checksum           ok (sha256 {})", hex(&header.checksum));
            print_provenance(&asset.provenance);
            match &asset.payload {
                Payload::MaterialInfo(info) => print_material_info(info),
                Payload::ImportanceSamples(samples) => print_importance_samples(samples),
                Payload::PrefilteredEnvmap(prefiltered) => print_prefiltered_envmap(prefiltered),
                Payload::BandwidthAtlas(atlas) => {
                    cli::outln!("payload: bandwidth atlas");
                    print_tiles(atlas.lobes_x, atlas.lobes_y, atlas.tile, &atlas.analysis);
                    let max = atlas.data.iter().fold(0.0f32, |m, v| m.max(*v));
                    cli::outln!("  max bandwidth    {max} cycles per radian");
                }
                Payload::BandwidthPca(pca) => {
                    cli::outln!("payload: bandwidth pca");
                    print_tiles(pca.lobes_x, pca.lobes_y, pca.tile, &pca.analysis);
                    cli::outln!("  components       {}", pca.n_components);
                }
                Payload::LayerSelection(selection) => print_layer_selection(selection),
                Payload::BandwidthRows(rows) => {
                    cli::outln!("payload: bandwidth rows (an isotropic bandwidth atlas, one tile per row)");
                    print_tiles(rows.lobes_x, rows.lobes_y, rows.tile, &rows.analysis);
                    cli::outln!("  stored           {} row tiles: row j's tile serves every column", rows.lobes_y);
                    let max = rows.data.iter().fold(0.0f32, |m, v| m.max(*v));
                    cli::outln!("  max bandwidth    {max} cycles per radian");
                }
                Payload::WaveletBrdf(wavelet) => print_wavelet_brdf(wavelet),
            }
        }
    }
}

fn print_wavelet_brdf(w: &asset::WaveletBrdf) {
    let (n, k) = (w.side as usize, w.stored_slices());
    cli::outln!("payload: wavelet brdf (Haar, Claustres et al. 2007)");
    cli::outln!("  grid             ({n} x {n})^2 directions: {n} x {n} incoming per outgoing cell");
    cli::outln!(
        "  log encoding     eps {}, channel means {} {} {} (1/sr)",
        w.epsilon,
        w.channel_mean[0],
        w.channel_mean[1],
        w.channel_mean[2]
    );
    cli::outln!(
        "  kept             {k} of {} coefficient positions (ratio {}:1), each {} outgoing cells x 3 channels",
        n * n,
        (n * n) as f64 / k.max(1) as f64,
        n * n
    );
    let storage = match &w.coefficients {
        asset::WaveletCoefficients::Float(_) => "32-bit floats",
        asset::WaveletCoefficients::Quantized { .. } => "8-bit codes, one offset and step per slice and channel",
    };
    cli::outln!("  coefficients     {storage}");
}

fn print_layer_selection(selection: &asset::LayerSelection) {
    cli::outln!("payload: layer selection");
    let a = &selection.analysis;
    cli::outln!("  analysis         {} at {} px, eps {}, c {}", a.parameterization, a.analysis_size, a.eps, a.c);
    cli::outln!("  reduction        {}", selection.reduction);
    cli::outln!("  layer            exponent  bandwidth (cycles per radian)  views (rows of {})", selection.rows);
    for (k, (n, b)) in selection.exponents.iter().zip(&selection.layer_bandwidth).enumerate() {
        let views = selection.view_layer.iter().filter(|&&l| l as usize == k).count();
        cli::outln!("  {k:>5}            {n:>8}  {b:>29.4}  {views:>5}");
    }
}

fn print_tiles(lobes_x: u32, lobes_y: u32, tile: u32, analysis: &asset::BandwidthAnalysis) {
    cli::outln!("  lobes            {lobes_x} x {lobes_y}, tiles of {tile} x {tile} texels");
    cli::outln!(
        "  analysis         {} at {} px, eps {}, c {}",
        analysis.parameterization,
        analysis.analysis_size,
        analysis.eps,
        analysis.c
    );
}

fn print_provenance(p: &Provenance) {
    cli::outln!("provenance");
    cli::outln!("  source           {}", p.source_name);
    cli::outln!("  source sha256    {}", hex(&p.source_sha256));
    cli::outln!("  tool             {} {}", p.tool, p.tool_version);
    if p.parameters.is_empty() {
        cli::outln!("  parameters       (none)");
    }
    for (i, (name, value)) in p.parameters.iter().enumerate() {
        let label = if i == 0 { "parameters" } else { "" };
        cli::outln!("  {label:<16} {name} = {value}");
    }
}

fn print_material_info(info: &MaterialInfo) {
    let [theta_h, theta_d, phi_d] = info.dims;
    let cells = u64::from(theta_h) * u64::from(theta_d) * u64::from(phi_d);
    let rgb = |v: [f64; 3]| format!("{:.6} {:.6} {:.6}", v[0], v[1], v[2]);
    cli::outln!("payload: material info");
    cli::outln!("  dims             {theta_h} x {theta_d} x {phi_d} (theta_h x theta_d x phi_d)");
    cli::outln!("  no-data cells    {} of {cells}", info.no_data_cells);
    cli::outln!("  min (1/sr)       {}", rgb(info.channel_min));
    cli::outln!("  max (1/sr)       {}", rgb(info.channel_max));
    cli::outln!("  mean (1/sr)      {}", rgb(info.channel_mean));
    let [h, d, p] = info.peak_cell;
    cli::outln!("  peak (1/sr)      {} at cell ({h}, {d}, {p})", rgb(info.peak_rgb));
    cli::outln!("  directional albedo");
    cli::outln!("    theta_o_deg        red      green       blue   no data");
    let rows = info.albedo_theta_o.iter().zip(&info.albedo_rgb).zip(&info.albedo_no_data_fraction);
    for ((theta_o, albedo), no_data) in rows {
        cli::outln!(
            "    {:>11.2} {:>10.6} {:>10.6} {:>10.6} {:>8.2}%",
            theta_o.to_degrees(),
            albedo[0],
            albedo[1],
            albedo[2],
            100.0 * no_data
        );
    }
}

fn print_importance_samples(s: &ImportanceSamples) {
    let summary = importance_summary(s);
    cli::outln!("payload: importance samples");
    cli::outln!(
        "  slices           {} (theta_o {:.1} to {:.1} deg)",
        summary.slices,
        summary.theta_o_deg.0,
        summary.theta_o_deg.1
    );
    cli::outln!("  samples          {} vectors x {} samples per slice", s.n_vectors, s.n_samples);
    cli::outln!("  cells            {} theta_h rows x {} phi_h sectors", summary.rows, s.n_phi_h);
    cli::outln!("  samples with pdf 0  {}", summary.zero_pdf_samples);
}

fn print_prefiltered_envmap(p: &PrefilteredEnvmap) {
    let rgb = |v: [f64; 3]| format!("{:.6} {:.6} {:.6}", v[0], v[1], v[2]);
    let [sw, sh] = p.source_size;
    let [lw, lh] = p.layer_size;
    cli::outln!("payload: prefiltered envmap");
    cli::outln!("  source           {sw} x {sh}, mean radiance {}", rgb(p.source_mean_radiance));
    cli::outln!("  layers           {} of {lw} x {lh}", p.exponents.len());
    cli::outln!("    exponent  bandwidth (cycles/rad)  up to (cycles/rad)   mean radiance");
    for (k, (n, nu)) in p.exponents.iter().zip(&p.lobe_bandwidth).enumerate() {
        let up_to = p.bandwidth_thresholds.get(k).map_or_else(|| "-".to_string(), |t| format!("{t:.4}"));
        cli::outln!("    {n:>8} {nu:>22.4} {up_to:>19}   {}", rgb(p.layer_mean_radiance[k]));
    }
    let file = |f: &LinkedFile| format!("{} (sha256 {})", f.name, hex(&f.sha256));
    cli::outln!("  layers ktx2      {}, radiance scale {}", file(&p.layers_ktx2), p.layers_radiance_scale);
    for (n, exr) in p.exponents.iter().zip(&p.layer_exrs) {
        cli::outln!("  layer exr        n = {n}: {}", file(exr));
    }
    cli::outln!(
        "  mips ktx2        {}, {} levels, radiance scale {}",
        file(&p.mips_ktx2),
        p.mip_levels,
        p.mips_radiance_scale
    );
    cli::outln!("  contact sheet    {}", file(&p.contact_sheet_png));
}

/// A prefiltered envmap's payload in JSON: its own fields, hashes as hexadecimal.
fn prefiltered_envmap_json(p: &PrefilteredEnvmap) -> Value {
    let file = |f: &LinkedFile| json!({ "name": f.name, "sha256": hex(&f.sha256) });
    json!({
        "source_size": p.source_size,
        "source_mean_radiance": p.source_mean_radiance,
        "layer_size": p.layer_size,
        "mip_levels": p.mip_levels,
        "layers_radiance_scale": p.layers_radiance_scale,
        "mips_radiance_scale": p.mips_radiance_scale,
        "exponents": p.exponents,
        "lobe_bandwidth": p.lobe_bandwidth,
        "bandwidth_thresholds": p.bandwidth_thresholds,
        "layer_mean_radiance": p.layer_mean_radiance,
        "layers_ktx2": file(&p.layers_ktx2),
        "layer_exrs": p.layer_exrs.iter().map(file).collect::<Vec<_>>(),
        "mips_ktx2": file(&p.mips_ktx2),
        "contact_sheet_png": file(&p.contact_sheet_png),
    })
}

/// What asset-info says about an importance-samples payload (the arrays themselves are too
/// large to print).
struct ImportanceSummary {
    slices: usize,
    rows: usize,
    theta_o_deg: (f64, f64),
    zero_pdf_samples: usize,
}

fn importance_summary(s: &ImportanceSamples) -> ImportanceSummary {
    let degrees = |v: Option<&f64>| v.map_or(0.0, |t| t.to_degrees());
    ImportanceSummary {
        slices: s.theta_o.len(),
        rows: s.theta_h_edges.len().saturating_sub(1),
        theta_o_deg: (degrees(s.theta_o.first()), degrees(s.theta_o.last())),
        zero_pdf_samples: s.samples.iter().filter(|t| t[3] == 0.0).count(),
    }
}

/// The grid and analysis of a bandwidth payload (kinds 4, 5 and 7) in JSON, as `print_tiles`
/// prints them.
fn tiles_json(lobes_x: u32, lobes_y: u32, tile: u32, analysis: &asset::BandwidthAnalysis) -> Value {
    json!({
        "lobes_x": lobes_x,
        "lobes_y": lobes_y,
        "tile": tile,
        "analysis": serde_json::to_value(analysis).expect("analysis serializes to json"),
    })
}

fn to_json(report: &Report) -> Value {
    let header = &report.header;
    let header_json = json!({
        "magic": asset::MAGIC.escape_ascii().to_string(),
        "format_version": header.version,
        "kind": header.kind.name(),
        "kind_code": header.kind.code(),
        "provenance_bytes": header.provenance_len,
        "payload_bytes": header.payload_len,
    });
    let checksum = json!({
        "ok": report.asset.is_some(),
        "stored_sha256": hex(&header.checksum),
        "computed_sha256": hex(&report.computed),
    });
    match &report.asset {
        None => json!({
            "header": header_json,
            "checksum": checksum,
            "provenance": null,
            "payload": null,
        }),
        Some(asset) => {
            let p = &asset.provenance;
            // Pairs rather than an object: the order is the tool's and names may repeat.
            let parameters: Vec<[&str; 2]> =
                p.parameters.iter().map(|(name, value)| [name.as_str(), value.as_str()]).collect();
            let payload = match &asset.payload {
                // The payload's own serde form: the field names of the type, angles in radians.
                Payload::MaterialInfo(info) => serde_json::to_value(info).expect("material info serializes to json"),
                Payload::ImportanceSamples(samples) => {
                    let summary = importance_summary(samples);
                    json!({
                        "theta_o": samples.theta_o,
                        "n_vectors": samples.n_vectors,
                        "n_samples": samples.n_samples,
                        "theta_h_rows": summary.rows,
                        "n_phi_h": samples.n_phi_h,
                        "zero_pdf_samples": summary.zero_pdf_samples,
                    })
                }
                Payload::PrefilteredEnvmap(prefiltered) => prefiltered_envmap_json(prefiltered),
                Payload::BandwidthAtlas(atlas) => tiles_json(atlas.lobes_x, atlas.lobes_y, atlas.tile, &atlas.analysis),
                Payload::BandwidthPca(pca) => {
                    let mut value = tiles_json(pca.lobes_x, pca.lobes_y, pca.tile, &pca.analysis);
                    value["n_components"] = pca.n_components.into();
                    value
                }
                Payload::LayerSelection(selection) => {
                    serde_json::to_value(selection).expect("layer selection serializes to json")
                }
                Payload::BandwidthRows(rows) => {
                    let mut value = tiles_json(rows.lobes_x, rows.lobes_y, rows.tile, &rows.analysis);
                    value["stored_tiles"] = rows.lobes_y.into();
                    value
                }
                Payload::WaveletBrdf(w) => json!({
                    "side": w.side,
                    "epsilon": w.epsilon,
                    "channel_mean": w.channel_mean,
                    "positions": w.map.len(),
                    "kept_positions": w.stored_slices(),
                    "quantized": matches!(w.coefficients, asset::WaveletCoefficients::Quantized { .. }),
                }),
            };
            json!({
                "header": header_json,
                "checksum": checksum,
                "provenance": {
                    "source_name": p.source_name,
                    "source_sha256": hex(&p.source_sha256),
                    "tool": p.tool,
                    "tool_version": p.tool_version,
                    "parameters": parameters,
                },
                "payload": payload,
            })
        }
    }
}
