//! The contact sheet: the source and every layer in a titled grid, tone mapped alike, with the
//! exposure written under it.

use envmap::{EnvMap, MipChain};
use picture::Canvas;
use picture::layout::TITLE_GAP;
use prefilter::{COLUMNS, Config, contact_sheet, panel_titles, prefilter, signed};

/// Each layer panel sits under its title ("n = 16"), enlarged to the minimum panel width, and is
/// its layer tone mapped at the sheet's exposure, texel for texel; the panels run left to right
/// and wrap after `COLUMNS`; the caption names the exposure.
#[test]
fn titled_panels_in_a_grid() {
    let map = crate::point_source(64, 32, 10, 8, [50.0, 20.0, 5.0]);
    let exponents = vec![1, 16, 256, 1024];
    let config = Config { exponents: exponents.clone(), width: 16, height: 8, ..Config::default() };
    let layers = prefilter(&map, &config).unwrap();
    let maps: Vec<(u32, &EnvMap)> = layers.layers.iter().map(|l| (l.exponent, &l.map)).collect();
    let sheet = contact_sheet(&MipChain::new(&map), &maps);
    assert_eq!(sheet.rgb8.len(), 3 * sheet.width * sheet.height);
    // 16-texel layers are enlarged to 256 pixels.
    assert_eq!(sheet.zoom, 16);
    let canvas = Canvas::from_rgb8(sheet.width, sheet.height, sheet.rgb8.clone());
    let titles = panel_titles(exponents.iter().copied());
    assert_eq!(titles, ["source", "n = 1", "n = 16", "n = 256", "n = 1024"]);
    let title_height = Canvas::label("n").height + TITLE_GAP;
    let preview = envmap::ToneMapping { exposure_ev: sheet.exposure_ev, tone_map: envmap::ToneMap::Reinhard };
    let mut corners = Vec::new();
    for (k, title) in titles.iter().enumerate() {
        let (x, y) = canvas.find(&Canvas::label(title)).unwrap_or_else(|| panic!("no title {title:?}"));
        let (x0, y0) = (x, y + title_height);
        corners.push((x0, y0));
        if k == 0 {
            continue;
        }
        let expected = envmap::tonemap_rgb8(maps[k - 1].1.rgb(), &preview);
        for py in 0..8 * sheet.zoom {
            for px in 0..16 * sheet.zoom {
                let i = 3 * ((py / sheet.zoom) * 16 + px / sheet.zoom);
                let want = [expected[i], expected[i + 1], expected[i + 2]];
                assert_eq!(canvas.pixel(x0 + px, y0 + py), Some(want), "{title}, pixel ({px}, {py})");
            }
        }
    }
    // Reading order: the first row left to right, then the fifth panel under the first.
    for pair in corners[..COLUMNS].windows(2) {
        assert!(pair[1].0 > pair[0].0 + 16 * sheet.zoom && pair[1].1 == pair[0].1, "{corners:?}");
    }
    assert_eq!(corners[COLUMNS].0, corners[0].0);
    assert!(corners[COLUMNS].1 > corners[0].1 + 8 * sheet.zoom, "{corners:?}");
    // The exposure is written in the caption, as the panels were shown.
    let exposure = format!("{} EV", signed(sheet.exposure_ev));
    assert!(canvas.find(&Canvas::label(&exposure)).is_some(), "{exposure}");
}

#[test]
fn signed_exposures() {
    assert_eq!([signed(1.254), signed(-0.5), signed(0.0), signed(12.0)], ["+1.25", "-0.5", "+0", "+12"]);
}
