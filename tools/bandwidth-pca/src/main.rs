//! `bandwidth-pca`: PCA compression of a bandwidth atlas (`000` Fig. 8): the mean tile, the
//! first K principal components and every lobe's K coefficients, with the reconstruction's
//! error. A thin layer over the `brdf-atlas` crate.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result, bail};
use brdf_atlas::{Atlas, Components, MAX_TEXELS, Parameterization, PcaModel, evaluate, fit};
use clap::{ArgGroup, Parser};

/// Compress a bandwidth atlas (from brdf-bandwidth) by PCA: each lobe's tile is one vector; the
/// model is the mean tile, K principal components and K coefficients per lobe, and a tile is
/// reconstructed as mean + sum_k coefficient_k component_k. Reports the relative RMSE
/// (|reconstruction - atlas| / |atlas| over all texels), the largest error of a texel and the
/// size of the model against the atlas. Writes the model (FILE) and a false-colour picture of
/// the absolute error in the atlas's layout (FILE with the extension .png, log scale).
///
/// Exit status: 0 ok, 2 error.
#[derive(Debug, Parser)]
#[command(version, about, long_about)]
#[command(group(ArgGroup::new("k").required(true).args(["components", "max_error"])))]
struct Args {
    /// The atlas (bandwidth-atlas.asset written by brdf-bandwidth).
    atlas: PathBuf,

    /// The model to write.
    #[arg(long, short, value_name = "FILE")]
    out: PathBuf,

    /// Keep exactly K components.
    #[arg(long, value_name = "K")]
    components: Option<usize>,

    /// Keep the fewest components whose relative RMSE is at most E (e.g. 0.02).
    #[arg(long = "max-error", value_name = "E")]
    max_error: Option<f64>,

    /// The error picture to write; defaults to the model's path with the extension .png.
    #[arg(long)]
    png: Option<PathBuf>,

    /// Print the report as one JSON object on stdout.
    #[arg(long)]
    json: bool,
}

fn main() -> ExitCode {
    cli::main(|| run(Args::parse()))
}

fn run(args: Args) -> Result<ExitCode> {
    let atlas = read_atlas(&args.atlas).with_context(|| format!("reading {}", args.atlas.display()))?;
    let components = match (args.components, args.max_error) {
        (Some(k), _) => Components::Count(k),
        (None, Some(e)) => Components::MaxRelativeRmse(e),
        (None, None) => unreachable!("clap requires one of them"),
    };
    let fitted = fit(&atlas, components)?;
    let report = evaluate(&atlas, &fitted.model);

    write_model(&args.out, &fitted.model, &args.atlas).with_context(|| format!("writing {}", args.out.display()))?;
    let png = args.png.clone().unwrap_or_else(|| args.out.with_extension("png"));
    let range = envmap::colormap::log_range(&report.errors, 3.0).unwrap_or((1.0, 1.0));
    envmap::write_png_rgb8(
        &png,
        atlas.width(),
        atlas.height(),
        &envmap::colormap::false_colour_log(&report.errors, range),
    )
    .with_context(|| format!("writing {}", png.display()))?;

    // The fewest components the eigenvalues predict for a few error levels.
    let k_for = |e: f64| fitted.predicted_relative_rmse.iter().position(|p| *p <= e).unwrap_or(atlas.tile_len());
    let levels = [0.1, 0.05, 0.02, 0.01];
    if args.json {
        let json = serde_json::json!({
            "atlas": args.atlas.display().to_string(),
            "lobes": atlas.n_lobes(),
            "tile_len": atlas.tile_len(),
            "components": report.n_components,
            "relative_rmse": report.relative_rmse,
            "max_abs_error": report.max_abs_error,
            "max_value": report.max_value,
            "size_ratio": report.size_ratio,
            "predicted_components": levels.iter().map(|e| serde_json::json!({"relative_rmse": e, "components": k_for(*e)})).collect::<Vec<_>>(),
        });
        cli::outln!("{json}");
    } else {
        cli::outln!(
            "atlas           {} ({} lobes, tiles of {} texels)",
            args.atlas.display(),
            atlas.n_lobes(),
            atlas.tile_len()
        );
        cli::outln!("components      {}", report.n_components);
        cli::outln!("relative rmse   {:.3}%", 100.0 * report.relative_rmse);
        cli::outln!(
            "max error       {:.4} cycles per radian ({:.2}% of the largest texel, {:.4})",
            report.max_abs_error,
            100.0 * report.max_abs_error / report.max_value.max(f64::MIN_POSITIVE),
            report.max_value
        );
        cli::outln!(
            "size            {:.2}% of the atlas ({} of {} floats), compression {:.1}:1",
            100.0 * report.size_ratio,
            fitted.model.stored_values(),
            atlas.data.len(),
            1.0 / report.size_ratio
        );
        let predicted: Vec<String> = levels.iter().map(|e| format!("{}% -> K = {}", 100.0 * e, k_for(*e))).collect();
        cli::outln!("predicted       {}", predicted.join(", "));
        cli::outln!(
            "png             absolute error, log colour scale from {:.2e} to {:.2e} cycles per radian, black 0",
            range.0,
            range.1
        );
    }
    eprintln!("wrote {} and {}", args.out.display(), png.display());
    Ok(ExitCode::SUCCESS)
}

/// Reads the `bandwidth-atlas` asset written by `brdf-bandwidth`.
fn read_atlas(path: &Path) -> Result<Atlas> {
    let asset = asset::read_file(path)?;
    let asset::Payload::BandwidthAtlas(a) = asset.payload else {
        bail!("expected a bandwidth-atlas asset (from brdf-bandwidth), found {}", asset.payload.kind());
    };
    let name = a.analysis.parameterization.as_str();
    let Some(parameterization) = Parameterization::from_name(name) else {
        bail!(
            "unknown parameterization {name:?}: this build knows {:?}",
            Parameterization::IncidencePlaneEquidistant.name()
        );
    };
    let texels = u64::from(a.lobes_x * a.tile) * u64::from(a.lobes_y * a.tile);
    if texels > MAX_TEXELS as u64 {
        bail!("{texels} texels exceed the limit of {MAX_TEXELS}");
    }
    let atlas = Atlas {
        lobes_x: a.lobes_x as usize,
        lobes_y: a.lobes_y as usize,
        tile: a.tile as usize,
        data: a.data,
        parameterization,
        analysis_size: a.analysis.analysis_size as usize,
        eps: a.analysis.eps,
        c: a.analysis.c,
    };
    atlas.check()?;
    Ok(atlas)
}

/// Writes the model as a `bandwidth-pca` asset (data-schema/README.md).
fn write_model(path: &Path, model: &PcaModel, atlas_path: &Path) -> Result<()> {
    let payload = asset::BandwidthPca {
        lobes_x: model.lobes_x as u32,
        lobes_y: model.lobes_y as u32,
        tile: model.tile as u32,
        analysis: asset::BandwidthAnalysis {
            parameterization: model.parameterization.name().to_string(),
            analysis_size: model.analysis_size as u32,
            eps: model.eps,
            c: model.c,
        },
        n_components: model.n_components as u32,
        mean: model.mean.clone(),
        components: model.components.clone(),
        coefficients: model.coefficients.clone(),
    };
    let provenance = asset::Provenance::of_source(
        atlas_path,
        env!("CARGO_PKG_NAME"),
        env!("CARGO_PKG_VERSION"),
        vec![("components".to_string(), model.n_components.to_string())],
    )
    .with_context(|| format!("hashing {}", atlas_path.display()))?;
    asset::write_file(path, &asset::Asset { provenance, payload: payload.into() })?;
    Ok(())
}
