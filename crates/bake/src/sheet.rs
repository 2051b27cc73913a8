//! The contact sheet of a bake: every picture its stages wrote, labelled, on one page. The
//! pictures are found by role in the manifest (those absent are skipped), read back from their
//! PNG files, reduced by a box filter to at most [`PANEL_WIDTH`] pixels wide where they are
//! wider (a box filter keeps their text readable, where nearest would drop strokes), and laid
//! out in reading order, [`COLUMNS`] to a row, each under a title saying what it is.

use std::path::Path;

use asset::{BakeManifest, FileFormat};
use picture::Canvas;
use picture::layout::Grid;

use crate::Error;

/// The roles of the pictures a bake writes, in the order the sheet shows them, and what each is.
pub const PICTURES: [(&str, &str); 5] = [
    ("importance-picture", "importance samples over the lobe"),
    ("bandwidth-atlas-picture", "bandwidth atlas"),
    ("bandwidth-pca-error-picture", "bandwidth PCA, absolute error"),
    ("environment-bandwidth-picture", "environment bandwidth"),
    ("phong-layers-picture", "Phong layers of the environment"),
];

/// The widest a picture is shown; wider ones are reduced to this width.
pub const PANEL_WIDTH: usize = 1024;
/// Pictures per row.
pub const COLUMNS: usize = 2;

/// The sheet of the bake whose manifest is `manifest`, its files in `dir`: the first picture of
/// each role of `PICTURES` (a bake writes one), so at most that many, however many outputs the
/// manifest lists. Each picture is read inside the folder without following a link and only when
/// it is the file the manifest describes (size and SHA-256: `asset::StageOutput::read`). Errors
/// name the file that could not be read or decoded.
pub fn contact_sheet(dir: &Path, manifest: &BakeManifest) -> Result<Canvas, Error> {
    let folder = fsguard::Folder::open(dir).map_err(|e| Error::read(dir, e))?;
    let mut grid = Grid::new(COLUMNS);
    let title = match &manifest.environment {
        Some(environment) => format!("bake of {} under {}", manifest.material.name, environment.name),
        None => format!("bake of {}", manifest.material.name),
    };
    grid.title(title);
    for (role, what) in PICTURES {
        let mut outputs = manifest.stages.iter().flat_map(|s| &s.outputs);
        if let Some(output) = outputs.find(|o| o.format == FileFormat::Png && o.role == role) {
            let path = dir.join(&output.path);
            let bytes = output.read(&folder).map_err(|e| Error::read(&path, e))?;
            let picture = read_png(&path, &bytes)?;
            grid.add(fit(&picture, PANEL_WIDTH), format!("{what} ({})", output.path));
        }
    }
    Ok(grid.render())
}

/// A PNG file's bytes as an RGB canvas (grey and alpha converted); `path` names it in errors.
fn read_png(path: &Path, bytes: &[u8]) -> Result<Canvas, Error> {
    let image = image::load_from_memory_with_format(bytes, image::ImageFormat::Png)
        .map_err(|e| Error::read(path, e))?
        .to_rgb8();
    let (width, height) = (image.width() as usize, image.height() as usize);
    Ok(Canvas::from_rgb8(width, height, image.into_raw()))
}

/// `picture` reduced to `width` pixels wide, its aspect kept (height rounded, at least 1), when
/// it is wider; unchanged otherwise.
pub fn fit(picture: &Canvas, width: usize) -> Canvas {
    if picture.width <= width {
        return picture.clone();
    }
    let height = ((picture.height * width) as f64 / picture.width as f64).round().max(1.0) as usize;
    picture.resized(width, height)
}

#[cfg(test)]
mod tests {
    use super::*;
    use asset::{SourceFile, Stage, StageOutput, Tool};

    fn source(name: &str) -> SourceFile {
        SourceFile { name: name.into(), source_path: format!("{name}.bin"), source_sha256: "0".repeat(64) }
    }

    /// A manifest whose one stage lists `outputs` (name, format, role) with the bytes in `dir`.
    fn manifest(dir: &Path, outputs: &[(&str, FileFormat, &str)], environment: bool) -> BakeManifest {
        let outputs = outputs
            .iter()
            .map(|(name, format, role)| {
                let bytes = std::fs::read(dir.join(name)).unwrap_or_default();
                StageOutput::of_bytes(name, *format, role, &bytes).unwrap()
            })
            .collect();
        BakeManifest {
            manifest_version: 2,
            material: source("gold-paint"),
            environment: environment.then(|| source("quarry")),
            tool: Tool { name: "test".into(), version: "0".into() },
            parameters: serde_json::Map::new(),
            stages: vec![Stage {
                name: "all".into(),
                parameters: serde_json::Map::new(),
                figures: serde_json::Map::new(),
                outputs,
            }],
        }
    }

    fn write_png(dir: &Path, name: &str, canvas: &Canvas) {
        let bytes = envmap::encode_png_rgb8(canvas.width, canvas.height, &canvas.rgb).unwrap();
        std::fs::write(dir.join(name), bytes).unwrap();
    }

    /// The title names the material and the environment; every picture present is shown under
    /// its title, in the order of `PICTURES` whatever the manifest's order; a wide picture is
    /// reduced to the panel width with its aspect kept; files of other formats and missing roles
    /// are left out.
    #[test]
    fn pictures_by_role_in_reading_order() {
        let dir = tempfile::tempdir().unwrap();
        let atlas = Canvas::new(2048, 1024, [10, 200, 30]);
        let importance = Canvas::new(300, 100, [200, 20, 30]);
        let layers = Canvas::new(500, 60, [20, 30, 220]);
        write_png(dir.path(), "a.png", &atlas);
        write_png(dir.path(), "i.png", &importance);
        write_png(dir.path(), "l.png", &layers);
        std::fs::write(dir.path().join("x.exr"), b"not a picture").unwrap();
        let outputs = [
            ("l.png", FileFormat::Png, "phong-layers-picture"),
            ("a.png", FileFormat::Png, "bandwidth-atlas-picture"),
            ("x.exr", FileFormat::Exr, "importance-picture"),
            ("i.png", FileFormat::Png, "importance-picture"),
        ];
        let sheet = contact_sheet(dir.path(), &manifest(dir.path(), &outputs, true)).unwrap();
        assert!(sheet.find(&Canvas::label("bake of gold-paint under quarry")).is_some());
        let titles = [
            "importance samples over the lobe (i.png)",
            "bandwidth atlas (a.png)",
            "Phong layers of the environment (l.png)",
        ];
        let at: Vec<(usize, usize)> =
            titles.iter().map(|t| sheet.find(&Canvas::label(t)).unwrap_or_else(|| panic!("{t}"))).collect();
        // Two to a row: importance and atlas side by side, the layers under the importance.
        assert!(at[0].1 == at[1].1 && at[0].0 < at[1].0, "{at:?}");
        assert!(at[2].0 == at[0].0 && at[2].1 > at[0].1, "{at:?}");
        assert!(sheet.find(&Canvas::label("bandwidth PCA")).is_none());
        // Each picture under its title: the importance one whole, the atlas halved.
        let below = |(x, y): (usize, usize)| (x, y + Canvas::label("b").height + picture::layout::TITLE_GAP);
        let (x, y) = below(at[0]);
        assert_eq!(sheet.pixel(x, y), Some([200, 20, 30]));
        assert_eq!(sheet.pixel(x + 299, y + 99), Some([200, 20, 30]));
        assert_ne!(sheet.pixel(x + 300, y + 50), Some([200, 20, 30]));
        let (x, y) = below(at[1]);
        assert_eq!(sheet.pixel(x + PANEL_WIDTH - 1, y + 511), Some([10, 200, 30]));
        assert_ne!(sheet.pixel(x + PANEL_WIDTH, y + 256), Some([10, 200, 30]));
        assert_ne!(sheet.pixel(x + 10, y + 512), Some([10, 200, 30]));
        // Without an environment, the title names the material alone.
        let sheet = contact_sheet(dir.path(), &manifest(dir.path(), &outputs[..2], false)).unwrap();
        assert!(sheet.find(&Canvas::label("bake of gold-paint")).is_some());
        assert!(sheet.find(&Canvas::label("under")).is_none());
    }

    /// A manifest listing many pictures of one role (distinct files, each as described) gets the
    /// first of them drawn: a sheet has at most one picture per role, so its size does not grow
    /// with the manifest (drawing every entry, a manifest listing one picture 100 000 times would
    /// make `--sheet` abort on allocation).
    #[test]
    fn one_picture_per_role() {
        let dir = tempfile::tempdir().unwrap();
        let names: Vec<String> = (0..40).map(|i| format!("i{i}.png")).collect();
        for name in &names {
            write_png(dir.path(), name, &Canvas::new(300, 100, [200, 20, 30]));
        }
        let outputs: Vec<(&str, FileFormat, &str)> =
            names.iter().map(|n| (n.as_str(), FileFormat::Png, "importance-picture")).collect();
        let sheet = contact_sheet(dir.path(), &manifest(dir.path(), &outputs, false)).unwrap();
        assert!(sheet.find(&Canvas::label("importance samples over the lobe (i0.png)")).is_some());
        assert!(sheet.find(&Canvas::label("importance samples over the lobe (i1.png)")).is_none());
        let one = contact_sheet(dir.path(), &manifest(dir.path(), &outputs[..1], false)).unwrap();
        assert_eq!((sheet.width, sheet.height), (one.width, one.height));
    }

    /// A missing or damaged picture is an error naming its file.
    #[test]
    fn unreadable_pictures_name_the_file() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("bad.png"), b"\x89PNG\r\n\x1a\n broken").unwrap();
        for name in ["bad.png", "missing.png"] {
            let m = manifest(dir.path(), &[(name, FileFormat::Png, "bandwidth-atlas-picture")], false);
            let error = contact_sheet(dir.path(), &m).unwrap_err();
            assert!(matches!(&error, Error::Read { path, .. } if path.ends_with(name)), "{error:?}");
            assert!(error.chain().contains(name), "{}", error.chain());
        }
    }

    /// A box filter reduces a 2 x 1 pattern of black and white columns to grey, and keeps a
    /// picture that fits.
    #[test]
    fn fitting_reduces_by_area() {
        let stripes = Canvas::from_fn(400, 10, |x, _| if x % 2 == 0 { [0, 0, 0] } else { [255, 255, 255] });
        let fitted = fit(&stripes, 200);
        assert_eq!((fitted.width, fitted.height), (200, 5));
        // Each new pixel averages one black and one white column: 127.5, rounded either way.
        assert!(fitted.rgb.iter().all(|v| (127..=128).contains(v)), "{:?}", &fitted.rgb[..6]);
        assert_eq!(fit(&stripes, 400), stripes);
    }
}
