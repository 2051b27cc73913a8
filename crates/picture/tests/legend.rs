use picture::colormap::{Scale, inferno, viridis};
use picture::legend::{Legend, ticks};
use picture::{BACKGROUND, Canvas, INK};

/// The bar's rows: those where the middle column has the colour map's middle colour.
fn bar_rows(canvas: &Canvas, map: fn(f64) -> [u8; 3]) -> std::ops::Range<usize> {
    let (left, width) = Legend::bar(canvas.width);
    let x = left + width / 2;
    let colour = map((width / 2) as f64 / (width - 1) as f64);
    let rows: Vec<usize> = (0..canvas.height).filter(|&y| canvas.pixel(x, y) == Some(colour)).collect();
    rows[0]..rows[rows.len() - 1] + 1
}

/// The columns of ink in row `y`.
fn ink_columns(canvas: &Canvas, y: usize) -> Vec<usize> {
    (0..canvas.width).filter(|&x| canvas.pixel(x, y) == Some(INK)).collect()
}

/// The columns of values at positions `t` on the bar.
fn columns(width: usize, positions: impl IntoIterator<Item = f64>) -> Vec<usize> {
    let (left, bar) = Legend::bar(width);
    let mut columns: Vec<usize> =
        positions.into_iter().map(|t| left + (t * (bar - 1) as f64).round() as usize).collect();
    columns.dedup();
    columns
}

/// On a log scale from 0.01 to 100 (4 decades) the major ticks sit at the decades, a quarter
/// of the bar apart, and the minor ticks at 2..9 times them at log10(v / 0.01) / 4; positions
/// computed here from the closed form, the ticks read from the picture's pixels.
#[test]
fn log_ticks_sit_at_their_values() {
    let legend = Legend::new(Scale::log(0.01, 100.0), inferno, "value (log scale)");
    let canvas = legend.render(500);
    let (left, bar) = Legend::bar(500);
    let rows = bar_rows(&canvas, inferno);
    assert_eq!(canvas.pixel(left, rows.start), Some(inferno(0.0)));
    assert_eq!(canvas.pixel(left + bar - 1, rows.start), Some(inferno(1.0)));
    let majors = columns(500, (0..=4).map(|k| f64::from(k) / 4.0));
    let mut all: Vec<f64> = Vec::new();
    for e in -2..=2 {
        for m in 1..=9 {
            let v = f64::from(m) * 10f64.powi(e);
            if v <= 100.0 * (1.0 + 1e-12) {
                all.push((v / 0.01).log10() / 4.0);
            }
        }
    }
    assert_eq!(ink_columns(&canvas, rows.end), columns(500, all));
    // Minor ticks are 4 pixels long, major ones 8.
    assert_eq!(ink_columns(&canvas, rows.end + 6), majors);
    let labels: Vec<String> = ticks(&legend.scale).into_iter().filter_map(|t| t.label).collect();
    assert_eq!(labels, ["0.01", "0.1", "1", "10", "100"]);
    assert_labels_under(&canvas, rows.end + 8, &majors);
}

/// A scale of 3 decades or less labels 2 and 5 times the decades as well.
#[test]
fn short_log_scales_label_two_and_five() {
    let labels: Vec<String> = ticks(&Scale::log(0.2, 50.0)).into_iter().filter_map(|t| t.label).collect();
    assert_eq!(labels, ["0.2", "0.5", "1", "2", "5", "10", "20", "50"]);
    // Without a round value inside, the ends are labelled.
    let labels: Vec<String> = ticks(&Scale::log(1.1, 1.9)).into_iter().filter_map(|t| t.label).collect();
    assert_eq!(labels, ["1.1", "1.9"]);
}

/// On a linear scale from -1 to 1.5 the ticks are at multiples of 0.5 (at most 5 intervals),
/// at (v + 1) / 2.5 along the bar, all labelled with one decimal.
#[test]
fn linear_ticks_sit_at_their_values() {
    let scale = Scale::linear(-1.0, 1.5);
    let legend = Legend::new(scale, viridis, "difference");
    let canvas = legend.render(640);
    let rows = bar_rows(&canvas, viridis);
    let values = [-1.0, -0.5, 0.0, 0.5, 1.0, 1.5];
    let expected = columns(640, values.map(|v| (v + 1.0) / 2.5));
    assert_eq!(ink_columns(&canvas, rows.end), expected);
    assert_eq!(ink_columns(&canvas, rows.end + 6), expected);
    let ticks = ticks(&scale);
    assert_eq!(ticks.iter().map(|t| t.value).collect::<Vec<_>>(), values);
    let labels: Vec<String> = ticks.into_iter().filter_map(|t| t.label).collect();
    assert_eq!(labels, ["-1.0", "-0.5", "0.0", "0.5", "1.0", "1.5"]);
    assert_labels_under(&canvas, rows.end + 8, &expected);
}

/// Under each major tick, within the band of labels, there is text centred on it (the
/// leftmost ink of the label and the rightmost are about equally far from the tick).
fn assert_labels_under(canvas: &Canvas, top: usize, ticks: &[usize]) {
    let band = top..top + 24;
    for &x in ticks {
        let near = |dx: std::ops::Range<usize>| {
            dx.filter(|&c| band.clone().any(|y| canvas.pixel(c, y) == Some(INK))).collect::<Vec<usize>>()
        };
        let ink = near(x.saturating_sub(30)..x + 31);
        assert!(!ink.is_empty(), "no label under the tick at {x}");
        let (first, last) = (ink[0] as f64, ink[ink.len() - 1] as f64);
        assert!(((first + last) / 2.0 - x as f64).abs() <= 12.0, "the label under {x} spans {first} .. {last}");
    }
}

/// Arrows past the ends only where the data exceed the scale, in the end colours; one line per
/// swatch, drawn in its colour.
#[test]
fn arrows_and_swatches() {
    let scale = Scale::log(0.1, 10.0);
    let plain = Legend::new(scale, inferno, "caption");
    let (left, bar) = Legend::bar(400);
    let canvas = plain.render(400);
    let middle = bar_rows(&canvas, inferno).start + 10;
    assert_eq!(canvas.pixel(left + bar + 2, middle), Some(BACKGROUND));
    assert_eq!(canvas.pixel(left - 3, middle), Some(BACKGROUND));

    let cyan = [0, 255, 255];
    let grey = [128, 128, 128];
    let clipped = plain
        .clone()
        .clipped(scale.clipping(&[0.05, 1.0, 50.0]))
        .swatch(cyan, "cyan: at the grid's limit")
        .swatch(grey, "grey: flat");
    let canvas = clipped.render(400);
    assert_eq!(canvas.pixel(left + bar + 2, middle), Some(inferno(1.0)));
    assert_eq!(canvas.pixel(left - 3, middle), Some(inferno(0.0)));
    assert_eq!(clipped.height(), plain.height() + 2 * 24);
    assert_eq!(canvas.height, clipped.height());
    for colour in [cyan, grey] {
        let (x0, y0, x1, y1) = crate::bounding_box(&canvas, colour).unwrap();
        assert_eq!((x1 - x0, y1 - y0), (14, 14), "a glyph-high square swatch");
        assert!(y0 >= plain.height() - 12, "below the caption");
        assert!(crate::count(&canvas, INK) > 0);
    }
}

/// Narrow or empty legends clip; nothing panics.
#[test]
fn tiny_legends() {
    for width in [0, 1, 10, 60] {
        let legend = Legend::new(Scale::linear(0.0, 1.0), inferno, "a long caption that does not fit")
            .clipped((true, true))
            .swatch([1, 2, 3], "x");
        let canvas = legend.render(width);
        assert_eq!((canvas.width, canvas.height), (width, legend.height()));
    }
}
