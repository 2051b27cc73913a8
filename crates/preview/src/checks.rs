//! What the previews share: the scene a request names, the limit on its work, the checks of a
//! render (finite values, a PSNR under the request's minimum, the converged estimate), tone
//! mapping and captioned pictures.

use std::path::{Path, PathBuf};

use picture::Canvas;
use render::{Camera, Mesh, Scene, metrics};

use crate::{Brdf, Error, Host, Request, bail};

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

/// How pictures are tone mapped: --exposure, or the environment's automatic exposure.
pub(crate) fn tone_mapping(request: &Request, lighting: &render::Lighting) -> envmap::ToneMapping {
    match request.exposure {
        Some(ev) => envmap::ToneMapping { exposure_ev: ev, tone_map: envmap::ToneMap::Reinhard },
        None => metrics::auto_tone_mapping(lighting.mips.level(0)),
    }
}

/// An 8-bit RGB picture as PNG bytes.
pub(crate) fn png(rgb: &[u8], width: usize, height: usize) -> Result<Vec<u8>, Error> {
    Ok(envmap::encode_png_rgb8(width, height, rgb)?)
}

/// Every picture of the bake on one labelled page (`bake::sheet`).
pub(crate) fn contact_sheet(loaded: &bake::Loaded) -> Result<Canvas, Error> {
    Ok(bake::sheet::contact_sheet(&loaded.dir, &loaded.manifest)?)
}

/// The mesh `name` names: `sphere` (the unit UV sphere every preview, test and benchmark shows),
/// `torus`, or the path of a Wavefront OBJ file (scaled to the unit sphere; a regular file only,
/// its size checked against [`Mesh::MAX_OBJ_BYTES`] before it is read).
pub fn mesh(name: &str) -> Result<Mesh, Error> {
    Ok(match name {
        "sphere" => Mesh::sphere(1.0, 128, 64),
        "torus" => Mesh::torus(0.7, 0.3, 128, 48),
        path => {
            let bytes = fsguard::read_regular(Path::new(path), Mesh::MAX_OBJ_BYTES as u64)
                .map_err(|e| Error::Invalid(format!("reading {path}: {e}")))?;
            let text = String::from_utf8(bytes)
                .map_err(|_| Error::Invalid(format!("reading {path}: not utf-8 text (an obj file)")))?;
            Mesh::from_obj(&text).map_err(|e| Error::Invalid(format!("reading {path}: {e}")))?
        }
    })
}

/// The scene the request describes.
pub(crate) fn scene(request: &Request) -> Result<Scene, Error> {
    let mesh = mesh(&request.mesh)?;
    let default = Camera::default();
    let (azimuth, elevation) = request.camera;
    let camera = Camera::orbit(
        default.target(),
        default.distance(),
        azimuth.to_radians(),
        elevation.to_radians(),
        default.fov_y(),
    )
    .map_err(|e| Error::Invalid(format!("--camera: {e}")))?;
    Ok(Scene { mesh, camera, width: request.size.0, height: request.size.1 })
}

/// "material under environment", from the manifest.
pub(crate) fn names(manifest: &asset::BakeManifest) -> String {
    match &manifest.environment {
        Some(env) => format!("{} under {}", manifest.material.name, env.name),
        None => manifest.material.name.clone(),
    }
}

/// `out` with `-suffix` before its extension: preview.png -> preview-difference.png.
pub(crate) fn sibling(out: &Path, suffix: &str) -> PathBuf {
    let stem = out.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    out.with_file_name(format!("{stem}-{suffix}.png"))
}

pub(crate) fn db(psnr: f64) -> String {
    if psnr.is_finite() { format!("{psnr:.2}") } else { "infinite (identical)".to_string() }
}

/// PSNR in JSON: a number, or null for identical pictures (JSON has no infinity).
pub(crate) fn json_db(psnr: f64) -> serde_json::Value {
    if psnr.is_finite() { serde_json::json!(psnr) } else { serde_json::Value::Null }
}

pub(crate) fn check_psnr(request: &Request, what: &str, psnr: f64, problems: &mut Vec<String>) {
    if let Some(min) = request.min_psnr
        && psnr < min
    {
        problems.push(format!("PSNR {what} is {psnr:.2} dB, below --min-psnr {min}"));
    }
}

/// The picture with a strip of text below it.
pub(crate) fn with_caption(rgb: &[u8], width: usize, height: usize, caption: &str) -> Canvas {
    let scale = if width >= 480 { 2 } else { 1 };
    let line = picture::font::LINE_HEIGHT * scale;
    let lines = wrap(caption, (width.saturating_sub(8)) / (picture::font::ADVANCE * scale));
    let mut canvas = Canvas::new(width, height + 8 + lines.len() * line, picture::BACKGROUND);
    canvas.blit_rgb8(width, height, rgb, 0, 0, 1);
    for (i, text) in lines.iter().enumerate() {
        canvas.text(4, (height + 5 + i * line) as isize, text, scale, picture::INK);
    }
    canvas
}

/// Breaks `text` at ` | ` separators (then anywhere) into lines of at most `columns` characters.
fn wrap(text: &str, columns: usize) -> Vec<String> {
    let columns = columns.max(8);
    let mut lines: Vec<String> = Vec::new();
    for part in text.split(" | ") {
        match lines.last_mut() {
            Some(last) if last.len() + 3 + part.len() <= columns => {
                last.push_str(" | ");
                last.push_str(part);
            }
            _ => {
                let mut rest = part;
                while rest.len() > columns {
                    let (head, tail) = rest.split_at(rest.floor_char_boundary(columns));
                    lines.push(head.to_string());
                    rest = tail;
                }
                lines.push(rest.to_string());
            }
        }
    }
    lines
}
