//! The figures of a bandwidth atlas and of its PCA's error: the texels as a heat map (viridis on
//! a log scale, black for 0) with the incident grid's axes (`phi_i` across the lobe columns,
//! `theta_i` down the rows, which are equal in `cos theta_i`), a title, a colour bar in cycles
//! per radian and a caption. An atlas whose longer side is 512 to 1024 texels is shown 1:1 (the
//! default, 1024 x 1024, included); a smaller one is enlarged by a whole factor (nearest), a
//! larger one reduced by a whole factor, each pixel the maximum of the texels it covers (like the
//! atlas itself, so that no peak disappears), and the title says which.

use bandwidth_atlas::Atlas;
use picture::colormap::{Scale, viridis};
use picture::layout::{Axis, Grid, caption, heat_map, stack};
use picture::legend::Legend;
use picture::{Canvas, format_number};
use rayon::prelude::*;

/// Texels of value 0.
pub const ZERO: [u8; 3] = [0, 0, 0];
/// The longest side the figure shows texels 1:1 at; the shortest it enlarges to.
const LARGEST: usize = 1024;
const SMALLEST: usize = 512;
/// Decades below the largest value the colour scale reaches down to, at most.
const DECADES: i32 = 3;
/// The values of `theta_i` labelled on the vertical axis, in degrees.
const THETA_TICKS_DEG: [f64; 7] = [0.0, 30.0, 45.0, 60.0, 70.0, 80.0, 90.0];

/// The words of one figure.
#[derive(Clone, Debug)]
pub struct Text<'a> {
    pub title: &'a str,
    /// The legend's caption: what the values are, in which unit.
    pub legend: &'a str,
    /// What black (0) means.
    pub zero: &'a str,
    /// A paragraph under the legend.
    pub notes: &'a str,
}

/// How the texels are drawn: enlarged `zoom` times, or each pixel the maximum of `reduce` x
/// `reduce` texels (one of the two is 1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shown {
    pub zoom: usize,
    pub reduce: usize,
}

impl Shown {
    pub fn of(width: usize, height: usize) -> Shown {
        let side = width.max(height).max(1);
        if side > LARGEST {
            Shown { zoom: 1, reduce: side.div_ceil(LARGEST) }
        } else {
            Shown { zoom: (SMALLEST / side).max(1), reduce: 1 }
        }
    }

    /// "shown 1:1", "enlarged 4x", "reduced 2x: each pixel the maximum of 2 x 2 texels".
    pub fn words(&self) -> String {
        match (self.zoom, self.reduce) {
            (1, 1) => "shown 1:1".to_string(),
            (z, 1) => format!("enlarged {z}x"),
            (_, r) => format!("reduced {r}x: each pixel the maximum of {r} x {r} texels"),
        }
    }
}

/// The colour scale of `values`: log, from the smallest positive value (but at most
/// [`DECADES`] below the largest) to the largest, widened to round ends.
pub fn scale(values: &[f32]) -> Scale {
    let hi = values.iter().fold(0.0f64, |m, v| m.max(f64::from(*v)));
    let lo = values.iter().filter(|v| **v > 0.0).fold(hi, |m, v| m.min(f64::from(*v)));
    Scale::log(lo.max(hi * 10f64.powi(-DECADES)), hi).nice()
}

/// The colour of one value.
fn colour(v: f32, scale: &Scale) -> [u8; 3] {
    if v > 0.0 { viridis(scale.position(f64::from(v))) } else { ZERO }
}

/// The figure of `values`, laid out like `atlas` (one value per texel), and its colour scale.
pub fn figure(atlas: &Atlas, values: &[f32], text: &Text<'_>) -> (Canvas, Scale) {
    let (w, h) = (atlas.width(), atlas.height());
    assert_eq!(values.len(), w * h, "one value per texel");
    let scale = scale(values);
    let shown = Shown::of(w, h);
    let r = shown.reduce;
    // Row by row in parallel: a million colours (a logarithm each) are most of the figure's time.
    let (image_w, image_h) = (w.div_ceil(r), h.div_ceil(r));
    let mut rgb = vec![0; 3 * image_w * image_h];
    rgb.par_chunks_exact_mut(3 * image_w).enumerate().for_each(|(y, row)| {
        for (x, pixel) in row.chunks_exact_mut(3).enumerate() {
            let block =
                (y * r..((y + 1) * r).min(h)).flat_map(|ty| (x * r..((x + 1) * r).min(w)).map(move |tx| (tx, ty)));
            let v = block.map(|(tx, ty)| values[ty * w + tx]).fold(0.0f32, f32::max);
            pixel.copy_from_slice(&colour(v, &scale));
        }
    });
    let image = Canvas::from_rgb8(image_w, image_h, rgb);
    let degrees = |v: f64| format!("{}\u{b0}", format_number(v));
    let x_axis = Axis::new(format!("phi_i, {} lobe columns", atlas.lobes_x), 0.0, 360.0)
        .with_ticks([0.0, 90.0, 180.0, 270.0, 360.0].map(|v| (v, degrees(v))).into());
    let y_axis = Axis::new(format!("theta_i, {} lobe rows equal in cos theta_i", atlas.lobes_y), 1.0, 0.0)
        .with_ticks(THETA_TICKS_DEG.map(|t| (t.to_radians().cos(), degrees(t))).into());
    let mut grid = Grid::new(1);
    grid.title(format!("{}\n{} x {} texels, {}", text.title, w, h, shown.words()));
    grid.add(heat_map(&image, shown.zoom, &x_axis, &y_axis), "");
    let width = grid.width();
    let positive: Vec<f64> = values.iter().map(|v| f64::from(*v)).collect();
    let legend = Legend::new(scale, viridis, text.legend).clipped(scale.clipping(&positive)).swatch(ZERO, text.zero);
    grid.footer(stack(&[legend.render(width), caption(text.notes, width)]));
    (grid.render(), scale)
}

/// The paragraph under an atlas's legend: what a tile is.
pub fn tile_notes(atlas: &Atlas) -> String {
    format!(
        "Each {t} x {t} tile is one lobe: f(wi, wo) over the hemisphere of wo in the plane of incidence of wi, \
         azimuthal equidistant (centre: the normal; rim: the horizon; the mirror direction towards -x). Every \
         tile of a row is the same for an isotropic material.",
        t = atlas.tile
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use bandwidth_atlas::Parameterization;
    use picture::INK;

    fn atlas(lobes: usize, tile: usize, value: impl Fn(usize, usize) -> f32) -> Atlas {
        let side = lobes * tile;
        Atlas {
            lobes_x: lobes,
            lobes_y: lobes,
            tile,
            data: (0..side * side).map(|i| value(i % side, i / side)).collect(),
            parameterization: Parameterization::IncidencePlaneEquidistant,
            analysis_size: 64,
            eps: 0.01,
            c: 0.177,
        }
    }

    const TEXT: Text<'static> = Text { title: "test atlas", legend: "cycles per radian", zero: "flat", notes: "notes" };

    /// The image's top-left corner in a figure: the first pixel of `colour` (unique to the map).
    fn corner(figure: &Canvas, colour: [u8; 3]) -> (usize, usize) {
        let i = figure.rgb.chunks_exact(3).position(|c| c == colour).expect("the map's corner");
        (i % figure.width, i / figure.width)
    }

    /// The map is shown whole, at the stated size: a 1024-texel atlas 1:1, a 128-texel one
    /// enlarged 4x, a 2048-texel one reduced 2x by maxima (a single hot texel survives). Texel
    /// `(x, y)` lands at pixel `corner + (x, y) * zoom / reduce`.
    #[test]
    fn the_figure_follows_the_atlas_size() {
        for (lobes, tile, zoom, reduce) in [(64, 16, 1, 1), (16, 8, 4, 1), (128, 16, 1, 2)] {
            let side = lobes * tile;
            // A 2 x 2 corner of its own value, a hot texel, zeros in one tile, a ramp elsewhere.
            let hot = (side - 3, 5);
            let a = atlas(lobes, tile, |x, y| match (x, y) {
                _ if x < 2 && y < 2 => 0.05,
                _ if (x, y) == hot => 9.0,
                _ if x < tile && (tile..2 * tile).contains(&y) => 0.0,
                _ => 0.1 + (x + y) as f32 / side as f32,
            });
            let shown = Shown::of(side, side);
            assert_eq!(shown, Shown { zoom, reduce });
            let (figure, scale) = figure(&a, &a.data, &TEXT);
            let title = format!("test atlas\n{side} x {side} texels, {}", shown.words());
            assert!(figure.find(&Canvas::label(&title)).is_some(), "{title}");
            let (x0, y0) = corner(&figure, colour(0.05, &scale));
            let at = |x: usize, y: usize| figure.pixel(x0 + x * zoom / reduce, y0 + y * zoom / reduce);
            assert_eq!(at(hot.0, hot.1), Some(colour(9.0, &scale)), "the hot texel");
            assert_eq!((scale.lo(), scale.hi()), (0.05, 10.0));
            assert_eq!(at(1, tile + 1), Some(ZERO), "zeros are black");
            assert_eq!(at(side - 1, side - 1), Some(colour(a.data[side * side - 1], &scale)), "the last texel");
            // The axis line runs along the left and bottom edges, one pixel outside the map.
            let shown_side = side * zoom / reduce;
            assert_eq!(figure.pixel(x0 - 1, y0 + shown_side / 2), Some(INK));
            assert_eq!(figure.pixel(x0 + shown_side / 2, y0 + shown_side), Some(INK));
            assert_ne!(figure.pixel(x0 + shown_side, y0 + shown_side / 2), at(side - 1, side / 2));
        }
    }

    /// The vertical axis places theta_i at its cos: 60 degrees half-way down, with a tick; phi_i
    /// = 180 degrees half-way across.
    #[test]
    fn axes_ticks_at_the_right_pixels() {
        let a = atlas(32, 16, |_, _| 1.0);
        let (figure, scale) = figure(&a, &a.data, &TEXT);
        let (x0, y0) = corner(&figure, colour(1.0, &scale));
        let side = 512;
        // Ticks are 5 pixels long, outside the axis line.
        assert_eq!(figure.pixel(x0 - 3, y0 + side / 2), Some(INK), "theta_i = 60 degrees at cos = 0.5");
        assert_eq!(figure.pixel(x0 - 3, y0 + side / 2 - 5), Some(picture::BACKGROUND));
        assert_eq!(figure.pixel(x0 + side / 2, y0 + side + 3), Some(INK), "phi_i = 180 degrees");
        for label in ["60\u{b0}", "180\u{b0}", "90\u{b0}", "0\u{b0}"] {
            assert!(figure.find(&Canvas::label(label)).is_some(), "{label}");
        }
    }

    /// The colour scale's ends are round and cover the data down to three decades, and the
    /// legend's bar shows viridis with a black swatch for zero.
    #[test]
    fn scale_and_legend() {
        let s = scale(&[0.0, 0.013, 2.7]);
        assert_eq!((s.lo(), s.hi()), (0.01, 5.0));
        let s = scale(&[1e-9, 2.7]);
        assert_eq!((s.lo(), s.hi()), (0.002, 5.0));
        let a = atlas(32, 16, |x, _| x as f32);
        let (figure, _) = figure(&a, &a.data, &TEXT);
        let (left, bar_width) = Legend::bar(figure.width);
        let row = (0..figure.height).find(|&y| figure.pixel(left, y) == Some(viridis(0.0))).unwrap();
        assert_eq!(figure.pixel(left + bar_width - 1, row), Some(viridis(1.0)));
        for words in ["flat", "cycles per radian", "notes"] {
            assert!(figure.find(&Canvas::label(words)).is_some(), "{words}");
        }
    }
}
