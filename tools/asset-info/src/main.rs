//! `asset-info`: shows what a baked asset file holds (header, provenance, checksum status and a
//! summary of the payload) as text or JSON, and checks the files it names beside it. The exit
//! status tells a script whether the file is valid (0), readable but damaged or stale (1: the
//! checksum does not match, a file it names is missing or does not have the recorded SHA-256,
//! or its importance samples disagree with their tables), or unreadable (2).

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use asset::{Asset, Error, Header, LinkedFile, LinkedStatus, Provenance, hex};
use clap::Parser;
use serde_json::{Value, json};

/// Show what a baked asset file holds: its header, where it came from, whether its checksum
/// matches, and a summary of its payload.
///
/// Exit status: 0 the asset is valid; 1 its checksum does not match its contents (the header is
/// still shown), or a file it names beside it (the KTX2, EXR and PNG files of a prefiltered
/// envmap) is missing or does not have the SHA-256 it records, or importance samples whose pdfs
/// are not the densities their tables give (what the previewer refuses); 2 the file cannot be
/// read, is not an asset, or is of a version or kind this build does not know.
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
        let stale = cli::printable(&stale.join("; ")).into_owned();
        eprintln!("error: checking {}: linked file {stale}", cli::printable_path(&args.file));
        return Ok(ExitCode::from(1));
    }
    if let Some(asset) = &report.asset {
        // The one check across a payload's fields that decoding leaves to the renderers' reader.
        if let asset::Payload::ImportanceSamples(samples) = &asset.payload
            && let Err(e) = samples.check_densities()
        {
            eprintln!("error: checking {}: {}", cli::printable_path(&args.file), cli::printable(&e));
            return Ok(ExitCode::from(1));
        }
        return Ok(ExitCode::SUCCESS);
    }
    let mismatch = Error::ChecksumMismatch { header: report.header, computed: report.computed };
    eprintln!("error: {}", cli::printable(&format!("{:#}", anyhow::Error::new(mismatch).context(context()))));
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
        cli::outln!("  {:<22} {}", cli::printable(&f.name), cli::printable(&found));
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
            for line in asset.payload.describe().lines {
                cli::outln!("{}", cli::printable(&line));
            }
        }
    }
}

fn print_provenance(p: &Provenance) {
    cli::outln!("provenance");
    cli::outln!("  source           {}", cli::printable(&p.source_name));
    cli::outln!("  source sha256    {}", hex(&p.source_sha256));
    cli::outln!("  tool             {} {}", cli::printable(&p.tool), cli::printable(&p.tool_version));
    if p.parameters.is_empty() {
        cli::outln!("  parameters       (none)");
    }
    for (i, (name, value)) in p.parameters.iter().enumerate() {
        let label = if i == 0 { "parameters" } else { "" };
        cli::outln!("  {label:<16} {} = {}", cli::printable(name), cli::printable(value));
    }
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
            let payload = asset.payload.describe().json;
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
