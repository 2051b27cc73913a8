//! The contact sheet: the source and every layer side by side, tone mapped alike.

use envmap::{EnvMap, MipChain};
use prefilter::{Config, contact_sheet, prefilter};

#[test]
fn panels_sit_side_by_side_with_grey_gaps() {
    let map = crate::point_source(64, 32, 10, 8, [50.0, 20.0, 5.0]);
    let config = Config { exponents: vec![1, 16, 256], width: 16, height: 8, ..Config::default() };
    let layers = prefilter(&map, &config).unwrap();
    let maps: Vec<&EnvMap> = layers.layers.iter().map(|l| &l.map).collect();
    let sheet = contact_sheet(&MipChain::new(&map), &maps);
    // The source and 3 layers of 16 texels, 3 gaps of 4.
    assert_eq!((sheet.width, sheet.height), (4 * 16 + 3 * 4, 8));
    assert_eq!(sheet.rgb8.len(), 3 * sheet.width * sheet.height);
    for x in [16, 19, 36, 39, 56, 59] {
        for y in 0..8 {
            let i = 3 * (y * sheet.width + x);
            assert_eq!(&sheet.rgb8[i..i + 3], &[64, 64, 64], "gap column {x}");
        }
    }
    // Each layer panel is its layer, tone mapped with the sheet's exposure.
    let preview = envmap::Preview { exposure_ev: sheet.exposure_ev, tone_map: envmap::ToneMap::Reinhard };
    for (k, layer) in maps.iter().enumerate() {
        let expected = envmap::tonemap_rgb8(layer.rgb(), &preview);
        let x0 = (k + 1) * 20;
        for y in 0..8 {
            let row = &sheet.rgb8[3 * (y * sheet.width + x0)..3 * (y * sheet.width + x0 + 16)];
            assert_eq!(row, &expected[3 * y * 16..3 * (y + 1) * 16], "layer {k}, row {y}");
        }
    }
}
