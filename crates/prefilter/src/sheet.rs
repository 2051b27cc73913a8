//! The contact sheet: the source and every layer as one 8-bit picture for a person to look at, a
//! labelled grid of panels tone mapped alike, with the exposure written under it.

use envmap::{EnvMap, MipChain, ToneMapping};
use picture::layout::{Grid, caption};
use picture::{Canvas, format_number};

/// Panels per row of the sheet.
pub const COLUMNS: usize = 4;
/// Panels narrower than this are enlarged by a whole factor (nearest), so that small layers stay
/// visible under their titles.
pub const MIN_PANEL_WIDTH: usize = 256;

/// An 8-bit sRGB picture, interleaved RGB, row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactSheet {
    pub width: usize,
    pub height: usize,
    pub rgb8: Vec<u8>,
    /// The exposure every panel was shown at.
    pub exposure_ev: f32,
    /// Each panel enlarged this many times (nearest).
    pub zoom: usize,
}

/// The panels' titles: `source`, then `n = ` each layer's exponent.
pub fn panel_titles(exponents: impl IntoIterator<Item = u32>) -> Vec<String> {
    std::iter::once("source".to_string()).chain(exponents.into_iter().map(|n| format!("n = {n}"))).collect()
}

/// The source (its mip level nearest the layers' size, looked up at the layers' texel centres)
/// and then each layer, given with its Phong exponent, in a grid of [`COLUMNS`] panels, each
/// titled, all tone mapped alike: exposed so that the source's solid-angle-weighted log-average
/// luminance becomes 0.18, then Reinhard's `x / (1 + x)` (Reinhard et al. 2002); under them a
/// caption with the exposure. The layers must all have the same size.
pub fn contact_sheet(source: &MipChain, layers: &[(u32, &EnvMap)]) -> ContactSheet {
    let (w, h) =
        layers.first().map_or((source.level(0).width(), source.level(0).height()), |(_, l)| (l.width(), l.height()));
    let lod = (source.level(0).width() as f64 / w as f64).log2().max(0.0);
    let mut panels: Vec<Vec<f32>> = Vec::with_capacity(layers.len() + 1);
    let mut panel = Vec::with_capacity(3 * w * h);
    for y in 0..h {
        for x in 0..w {
            let (u, v) = envmap::geometry::texel_center_uv(x, y, w, h);
            panel.extend_from_slice(&source.lookup_uv(u, v, lod));
        }
    }
    panels.push(panel);
    panels.extend(layers.iter().map(|(_, layer)| layer.rgb().to_vec()));

    let preview = ToneMapping::auto(source.level(0));
    let exposure_ev = preview.exposure_ev;
    let zoom = (MIN_PANEL_WIDTH / w.max(1)).max(1);
    let mut grid = Grid::new(COLUMNS);
    grid.title(format!("Phong layers: the map convolved with normalized Phong lobes of exponent n, {w} x {h} each"));
    let titles = panel_titles(layers.iter().map(|(n, _)| *n));
    for (rgb, title) in panels.iter().zip(titles) {
        let mut enlarged = Canvas::new(w * zoom, h * zoom, picture::BACKGROUND);
        enlarged.blit_rgb8(w, h, &envmap::tonemap_rgb8(rgb, &preview), 0, 0, zoom);
        grid.add(enlarged, title);
    }
    let text = format!(
        "Every panel tone mapped alike: exposure {} EV (the source's solid-angle-weighted log-average luminance to \
         0.18), then Reinhard x / (1 + x). Source: its mip chain at level {}, looked up at the layers' texel \
         centres.{}",
        signed(exposure_ev),
        format_number((lod * 100.0).round() / 100.0),
        if zoom > 1 { format!(" Panels enlarged {zoom}x.") } else { String::new() }
    );
    let width = grid.width();
    grid.footer(caption(&text, width));
    let sheet = grid.render();
    ContactSheet { width: sheet.width, height: sheet.height, rgb8: sheet.rgb, exposure_ev, zoom }
}

/// An exposure rounded to hundredths, with its sign: `+1.25`, `-0.5`, `+0`.
pub fn signed(ev: f32) -> String {
    let text = format_number((f64::from(ev) * 100.0).round() / 100.0);
    if ev >= 0.0 { format!("+{text}") } else { text }
}
