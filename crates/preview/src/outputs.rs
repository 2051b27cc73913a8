//! What a preview writes and prints: tone mapping, PNG bytes, captioned pictures, the bake's
//! contact sheet, the names of siblings, and PSNR in text and JSON.

use std::path::{Path, PathBuf};

use picture::Canvas;
use render::metrics;

use crate::{Error, Request};

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
