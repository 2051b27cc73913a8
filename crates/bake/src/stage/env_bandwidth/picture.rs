//! The false-colour picture of a bandwidth map: the map on a logarithmic colour scale (inferno:
//! dark is low, bright is high) with axes (`phi` and `theta` in degrees for a lat-long map,
//! pixels for an image), pixels at the grid's Nyquist limit in cyan (their true bandwidth may be
//! higher than the value shown), flat pixels (no significant detail) in grey; under it the
//! colour bar in the map's unit and a caption.
//!
//! The colour range is the 1st to 99th percentile of the pixels drawn in colour, each weighted by
//! its solid angle (`sin theta` per row) on a lat-long map and counted alike on an image, widened
//! to round ends. On a lat-long map the conversion to cycles per radian multiplies by the
//! mapping's Jacobian, `W / (2 pi sin theta)` pixels per radian, so the few rows nearest the poles
//! read up to hundreds of times the equator's value (1174 against about 80 on
//! `quarry_01_1k.hdr`): they cover almost no solid angle, and letting them set the top of the
//! scale would leave the rest of the map in a few colours. They are drawn in the end colour,
//! and an arrow at the bar's end says so.
//!
//! Thin lines one level coarser (half the bandwidth, so darker) than both neighbours, along
//! columns and rows next to multiples of a power of two (e.g. `x = 447, 448` on
//! `quarry_01_1k.hdr`, rows 65 to 128), are what the estimator says, not a drawing artefact:
//! the discrete synthesis support of a level-`j` D4 coefficient is `3 2^j - 2` pixels, so a pixel
//! at either edge of a `2^j` block (`x = 0` or `-1` modulo `2^j`) is covered by 2 coefficients
//! per axis where its neighbours have 3. At `x = 447` and `448` (`448 = 7 x 64`) that holds at
//! every level from 1 to 6 at once, and in a smooth region, where level 6 is only just
//! significant, losing one of its coefficients makes level 7 the finest significant one. The
//! caption says so.
//!
//! Layout: the map enlarged `k = max(1, 512 / max(width, height))` times (so small textures stay
//! visible) in a heat map with axes, under a title, over the legend and the caption.

use picture::colormap::{Scale, inferno, range_by_percentiles};
use picture::font::wrap;
use picture::layout::{Axis, CAPTION_MARGIN, Grid, caption, heat_map, stack};
use picture::legend::Legend;
use picture::{Canvas, TEXT_SCALE, format_number};

/// Pixels at the Nyquist limit: a colour inferno never reaches.
pub const NYQUIST: [u8; 3] = [0, 255, 255];
/// Flat pixels (no significant level).
pub const FLAT: [u8; 3] = [128, 128, 128];
/// The quantiles of the colour range.
pub const RANGE: (f64, f64) = (0.01, 0.99);

/// What the picture shows of one map.
#[derive(Debug)]
pub struct Input<'a> {
    /// The map's file name, for the title.
    pub name: &'a str,
    pub width: usize,
    pub height: usize,
    /// The bandwidth per pixel, row-major, in `unit`.
    pub values: &'a [f64],
    /// The wavelet level `j*` per pixel (`BandwidthMap::level`): 0 flat, 1 at the Nyquist limit.
    pub levels: &'a [u8],
    /// "cycles per radian" or "cycles per pixel".
    pub unit: &'a str,
    /// A lat-long map: pixels weigh their solid angle, axes in degrees.
    pub latlong: bool,
    /// How eq. 7 compared the levels (`bandwidth::Reading`), for the title.
    pub reading: bandwidth::Reading,
}

/// Whether a pixel is drawn with the colour map (neither flat nor at the Nyquist limit).
fn in_colour(level: u8) -> bool {
    level >= 2
}

/// The colour scale: the weighted [`RANGE`] of the pixels drawn in colour, widened to round ends;
/// `0.001 ..= 1` when there are none.
pub fn scale(input: &Input<'_>) -> Scale {
    let mut values = Vec::new();
    let mut weights = Vec::new();
    for (i, (&v, &level)) in input.values.iter().zip(input.levels).enumerate() {
        if in_colour(level) && v > 0.0 {
            values.push(v);
            let theta = ((i / input.width) as f64 + 0.5) / input.height as f64 * std::f64::consts::PI;
            weights.push(if input.latlong { theta.sin() } else { 1.0 });
        }
    }
    match range_by_percentiles(&values, Some(&weights), RANGE.0, RANGE.1) {
        Some((lo, hi)) => Scale::log(lo, hi).nice(),
        None => Scale::log(1e-3, 1.0),
    }
}

/// The colour of one map pixel.
pub fn colour(value: f64, level: u8, scale: &Scale) -> [u8; 3] {
    match level {
        0 => FLAT,
        1 => NYQUIST,
        _ => inferno(scale.position(value)),
    }
}

/// Map pixels per image pixel: small images are enlarged so that they stay visible.
pub fn zoom(width: usize, height: usize) -> usize {
    (512 / width.max(height).max(1)).max(1)
}

/// The figure: title, map with axes, legend and caption.
pub fn render(input: &Input<'_>) -> Canvas {
    let (w, h) = (input.width, input.height);
    assert!(input.values.len() == w * h && input.levels.len() == w * h, "values and levels must be {w}x{h}");
    let scale = scale(input);
    let image = Canvas::from_fn(w, h, |x, y| colour(input.values[y * w + x], input.levels[y * w + x], &scale));
    let degrees = |ticks: &[f64]| ticks.iter().map(|&v| (v, format!("{}\u{b0}", format_number(v)))).collect();
    let (x_axis, y_axis) = if input.latlong {
        (
            Axis::new("phi", 0.0, 360.0).with_ticks(degrees(&[0.0, 90.0, 180.0, 270.0, 360.0])),
            Axis::new("theta", 0.0, 180.0).with_ticks(degrees(&[0.0, 45.0, 90.0, 135.0, 180.0])),
        )
    } else {
        (Axis::new("x, pixels", 0.0, w as f64), Axis::new("y, pixels", 0.0, h as f64))
    };
    let mut grid = Grid::new(1);
    let mode = if input.latlong { "lat-long map" } else { "image" };
    grid.title(format!("local bandwidth of {} ({mode}, {w} x {h}, {} reading)", input.name, input.reading.name()));
    grid.add(heat_map(&image, zoom(w, h), &x_axis, &y_axis), "");
    let width = grid.width();
    let weighting = if input.latlong { "weighted by solid angle (sin theta per row)" } else { "counting pixels alike" };
    // The words for RANGE.
    let legend_caption = format!(
        "local bandwidth, {} (log scale); colours span the 1st to 99th percentile of the coloured pixels, {weighting}",
        input.unit
    );
    let coloured: Vec<f64> =
        input.values.iter().zip(input.levels).filter(|(_, l)| in_colour(**l)).map(|(v, _)| *v).collect();
    let legend = Legend::new(scale, inferno, wrap(&legend_caption, width - 2 * CAPTION_MARGIN, TEXT_SCALE))
        .clipped(scale.clipping(&coloured))
        .swatch(NYQUIST, "at the Nyquist limit: may be higher")
        .swatch(FLAT, "flat: no significant detail");
    let mut notes = String::new();
    if input.latlong {
        let max = coloured.iter().copied().fold(0.0f64, f64::max);
        notes.push_str(&format!(
            "The rows nearest the poles read up to 1 / sin theta times more (the lat-long Jacobian; largest here {}): \
             they take the end colour. ",
            format_number(max)
        ));
    }
    notes.push_str(
        "Thin darker lines (half the bandwidth of their neighbours) next to multiples of 64 or another power of two \
         are the estimator's, not the drawing's: a pixel at the edge of a block of 2, 4, 8, ... pixels is covered by \
         2 of that level's D4 coefficients per axis instead of 3.",
    );
    grid.footer(stack(&[legend.render(width), caption(&notes, width)]));
    grid.render()
}

#[cfg(test)]
mod tests {
    use super::*;
    use picture::INK;

    /// The map's top-left corner: the first pixel of `colour`, unique to the map's corner.
    fn corner(figure: &Canvas, colour: [u8; 3]) -> (usize, usize) {
        let i = figure.rgb.chunks_exact(3).position(|c| c == colour).expect("the map's corner");
        (i % figure.width, i / figure.width)
    }

    /// Every map pixel gets the colour of its class and value, small maps are enlarged, and the
    /// legend shows the two special colours.
    #[test]
    fn pixels_and_classes() {
        let (w, h) = (4, 2);
        let values = [0.0, 0.01, 0.1, 1.0, 10.0, 100.0, 0.05, 0.05];
        let levels = [0, 9, 7, 5, 3, 1, 8, 8];
        let input = Input {
            name: "tiny.exr",
            width: w,
            height: h,
            values: &values,
            levels: &levels,
            unit: "cycles per pixel",
            latlong: false,
            reading: bandwidth::Reading::Paper,
        };
        let figure = render(&input);
        let k = zoom(w, h);
        assert_eq!(k, 128);
        let scale = scale(&input);
        let (x0, y0) = corner(&figure, FLAT);
        for (i, (&v, &l)) in values.iter().zip(&levels).enumerate() {
            let (x, y) = (i % w, i / w);
            assert_eq!(figure.pixel(x0 + k * x + k / 2, y0 + k * y + k / 2), Some(colour(v, l, &scale)), "pixel {i}");
        }
        assert_eq!(figure.pixel(x0 + k, y0 + k), Some(NYQUIST));
        for label in ["at the Nyquist limit: may be higher", "flat: no significant detail", "y, pixels"] {
            assert!(figure.find(&Canvas::label(label)).is_some(), "{label}");
        }
        assert!(figure.find(&Canvas::label("local bandwidth of tiny.exr (image, 4 x 2, paper reading)")).is_some());
    }

    /// A lat-long map whose values grow like 1 / sin(theta) towards the poles, as the Jacobian
    /// makes them: weighted by solid angle, the scale's top stays far below the pole rows'
    /// values, which are clipped (the arrow beyond the bar's end is drawn); the bar's labelled
    /// ticks sit at their values' columns.
    #[test]
    fn the_poles_do_not_set_the_scale() {
        let (w, h) = (256, 128);
        let theta = |y: usize| (y as f64 + 0.5) / h as f64 * std::f64::consts::PI;
        let values: Vec<f64> = (0..w * h).map(|i| (2.0 + ((i % w) as f64 * 0.3).sin()) / theta(i / w).sin()).collect();
        let levels = vec![5u8; w * h];
        let input = Input {
            name: "m",
            width: w,
            height: h,
            values: &values,
            levels: &levels,
            unit: "cycles per radian",
            latlong: true,
            reading: bandwidth::Reading::Paper,
        };
        let s = scale(&input);
        let max = values.iter().copied().fold(0.0, f64::max);
        // The pole rows reach 3 / sin(pi / 256) = 245; 98% of the solid angle lies within
        // sin(theta) >= 0.2 or so, where values stay below 3 / 0.2 = 15.
        assert!(max > 200.0 && s.hi() <= 20.0, "max {max}, scale {s:?}");
        // Unweighted, the 99th percentile of the rows lands closer to the poles.
        let unweighted = scale(&Input { latlong: false, ..input });
        assert!(unweighted.hi() > s.hi(), "{unweighted:?} vs {s:?}");

        let figure = render(&input);
        let (left, bar_width) = Legend::bar(figure.width);
        let row = (0..figure.height)
            .find(|&y| {
                figure.pixel(left, y) == Some(inferno(0.0))
                    && figure.pixel(left + bar_width - 1, y) == Some(inferno(1.0))
            })
            .expect("the bar");
        // The arrow: the end colour just past the bar's end, half-way down the bar.
        assert_eq!(figure.pixel(left + bar_width + 2, row + 10), Some(inferno(1.0)));
        for tick in picture::legend::ticks(&s).into_iter().filter(|t| t.label.is_some()) {
            let t = (tick.value / s.lo()).ln() / (s.hi() / s.lo()).ln();
            let column = left + (t * (bar_width - 1) as f64).round() as usize;
            assert_eq!(figure.pixel(column, row + 20), Some(INK), "tick {:?}", tick.label);
        }
        for label in ["weighted", "solid", "theta", "phi", "180\u{b0}"] {
            assert!(figure.find(&Canvas::label(label)).is_some(), "{label}");
        }
    }

    /// Flat and Nyquist pixels do not enter the colour range; with no coloured pixel the scale is
    /// the default.
    #[test]
    fn special_pixels_stay_out_of_the_range() {
        let values = [1.0, 2.0, 1000.0, 1e-6];
        let levels = [4, 4, 1, 0];
        let input = Input {
            name: "m",
            width: 2,
            height: 2,
            values: &values,
            levels: &levels,
            unit: "u",
            latlong: false,
            reading: bandwidth::Reading::Paper,
        };
        let s = scale(&input);
        assert_eq!((s.lo(), s.hi()), (1.0, 2.0));
        let none = Input { levels: &[0, 1, 0, 1], ..input };
        assert_eq!(scale(&none), Scale::log(1e-3, 1.0));
    }
}
