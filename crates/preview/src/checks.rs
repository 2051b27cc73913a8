//! The checks of a request and of its renders: the output's folder, the limit on its work,
//! finite values, a PSNR under the request's minimum, and the converged estimate a render is
//! measured against.

use std::path::Path;

use render::{Scene, metrics};

use crate::{Brdf, Error, Host, Request, bail};

/// Samples per strategy of the converged estimate a check renders where `--converged` does not
/// say (the adaptive modes' `--validate`, `--compare-fit`).
pub(crate) const CONVERGED_SAMPLES: u32 = 256;

/// The independent converged estimate of a render, and how far the render is from it.
pub(crate) struct Converged {
    pub(crate) image: render::Image,
    /// Its tone-mapped picture.
    pub(crate) picture: Vec<u8>,
    /// PSNR of the render's picture against it.
    pub(crate) psnr: f64,
    /// Relative error of the render's radiance against it.
    pub(crate) relative: f64,
}

/// Renders the converged estimate with `n` samples per strategy and measures `rendered` (the
/// image and its picture) against it.
#[allow(clippy::too_many_arguments)]
pub(crate) fn converged(
    request: &Request,
    scene: &Scene,
    material: &render::Material,
    lighting: &render::Lighting,
    n: u32,
    (image, picture): (&render::Image, &[u8]),
    tone_mapping: &envmap::ToneMapping,
    host: &dyn Host,
) -> Result<Converged, Error> {
    host.step(format!("converged estimate, {n} samples per strategy, on the CPU"));
    let converged = render::converged::converged_with_progress(
        scene,
        material,
        lighting,
        n,
        u64::from(request.seed),
        &|done, all| host.work(done, all),
    )?;
    check_finite(request, &converged.rgb, "the converged estimate")?;
    let converged_picture = metrics::tonemap(&converged, tone_mapping);
    let psnr = metrics::psnr_db(picture, &converged_picture);
    let relative = metrics::relative_error(&image.rgb, &converged.rgb);
    Ok(Converged { image: converged, picture: converged_picture, psnr, relative })
}

/// An output's folder must exist: found before the render rather than after it (nothing is
/// created; `asset::write_atomic`).
pub(crate) fn check_output_folder(path: &Path) -> Result<(), Error> {
    let folder = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    if !folder.is_dir() {
        bail!("writing {}: the folder {} does not exist (create it first)", path.display(), folder.display());
    }
    Ok(())
}

/// The work the arguments ask for, `(what, samples)` by part, within --max-samples; otherwise an
/// error that gives the parts and how to raise the limit.
pub(crate) fn check_work(request: &Request, parts: &[(&str, u128)]) -> Result<(), Error> {
    let total: u128 = parts.iter().map(|(_, n)| n).sum();
    if total <= u128::from(request.max_samples) {
        return Ok(());
    }
    let listed: Vec<String> = parts.iter().filter(|(_, n)| *n > 0).map(|(what, n)| format!("{n} {what}")).collect();
    bail!(
        "this run would take {total} samples ({}; --size, --spp, --frames and --converged set them), above the \
         limit of {} (--max-samples): ask for less, or raise --max-samples for a deliberate long run",
        listed.join(", "),
        request.max_samples
    )
}

/// A render with a pixel that is not a finite number is an error naming what it was rendered
/// from (a damaged or absurd asset can make a BRDF overflow), never a picture with exit 0.
pub(crate) fn check_finite(request: &Request, rgb: &[f32], what: &str) -> Result<(), Error> {
    let bad = rgb.chunks_exact(3).filter(|p| p.iter().any(|v| !v.is_finite())).count();
    if bad == 0 {
        return Ok(());
    }
    let source = match (request.brdf, &request.wavelet_brdf) {
        (Brdf::WaveletBrdf, Some(path)) => path.display().to_string(),
        (Brdf::WaveletBrdf, None) => format!("the wavelet-brdf asset of {}", request.bake.display()),
        (Brdf::Table, _) => format!("the bake in {}", request.bake.display()),
    };
    bail!(
        "rendering {source}: {what} has {bad} of {} pixels that are not finite numbers (an asset's values overflow)",
        rgb.len() / 3
    )
}

pub(crate) fn check_psnr(request: &Request, what: &str, psnr: f64, problems: &mut Vec<String>) {
    if let Some(min) = request.min_psnr
        && psnr < min
    {
        problems.push(format!("PSNR {what} is {psnr:.2} dB, below --min-psnr {min}"));
    }
}
