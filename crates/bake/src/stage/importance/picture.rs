//! The picture of what the tables do: one panel per shown slice, titled with its `theta_o`: the
//! lobe `L(f) cos theta_i` over the hemisphere of `wi` (orthographic view from above: `x = wi.x`
//! to the right, `y = wi.y` up; `wo` lies on the `+x` side, so the mirror direction is at
//! `(-sin theta_o, 0)`, left of the centre), on a log scale of six decades below the panel's
//! peak (inferno), the outside of the hemisphere in grey, and the first vector of the slice's
//! samples in cyan on top. A mirror-like lobe is a few pixels wide and hides under its own
//! samples, so when some panel's core (the pixels within a decade of its peak) is narrow, a
//! second row shows every panel again around its peak, enlarged (the factor is in its title).
//! Under the panels: the colour bar and a caption.

use color::luminance;
use glam::DVec3;
use merl::{Interp, MerlTable};
use picture::colormap::{Scale, inferno};
use picture::layout::{Grid, caption, stack};
use picture::legend::Legend;
use picture::{Canvas, format_number};

use importance::ImportanceTables;

/// The outside of the hemisphere: a neutral grey that no colour of inferno comes near, lighter
/// than its black, so that it does not read as "zero".
pub const OUTSIDE: [u8; 3] = [96, 96, 96];
/// Samples: a colour inferno never reaches.
pub const SAMPLE: [u8; 3] = [0, 255, 255];
/// Decades below the panel's peak that the colour scale spans.
pub const DECADES: i32 = 6;
/// The core of a lobe: the pixels within this fraction of the peak (a decade), so that a
/// specular spike over a diffuse base counts as narrow.
const CORE: f64 = 0.1;
/// A panel's core narrower than this fraction of the panel (in radius) asks for the zoomed row.
const NARROW: f64 = 1.0 / 8.0;
/// The largest enlargement of the zoomed row.
const MAX_ZOOM: usize = 32;

/// The colour scale of every panel: fractions of the panel's peak, `10^-6 ..= 1`.
pub fn scale() -> Scale {
    Scale::log(10f64.powi(-DECADES), 1.0)
}

/// One panel's view: the square `[cx - half, cx + half] x [cy - half, cy + half]` of the
/// projected hemisphere (`(x, y) = (wi.x, wi.y)`, the disk of radius 1), drawn on `size` x
/// `size` pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    pub cx: f64,
    pub cy: f64,
    pub half: f64,
    pub size: usize,
}

impl View {
    /// The whole hemisphere.
    pub fn whole(size: usize) -> View {
        View { cx: 0.0, cy: 0.0, half: 1.0, size }
    }

    /// The projected point at the centre of pixel `(px, py)`.
    fn point(&self, px: usize, py: usize) -> (f64, f64) {
        let t = |p: usize| (p as f64 + 0.5) / self.size as f64 * 2.0 - 1.0;
        (self.cx + t(px) * self.half, self.cy - t(py) * self.half)
    }

    /// The pixel of a projected point (may lie outside the panel).
    pub fn pixel(&self, x: f64, y: f64) -> (isize, isize) {
        let p = |t: f64| ((t / self.half + 1.0) / 2.0 * self.size as f64).floor() as isize;
        (p(x - self.cx), p(self.cy - y))
    }
}

/// `L(f) cos theta_i` (luminance, nearest lookup) at each pixel of `view`, row-major; `None`
/// outside the hemisphere, 0 where the table holds no data.
fn lobe_values(table: &MerlTable, wo: DVec3, view: &View) -> Vec<Option<f64>> {
    (0..view.size * view.size)
        .map(|p| {
            let (x, y) = view.point(p % view.size, p / view.size);
            let z2 = 1.0 - x * x - y * y;
            (z2 > 0.0).then(|| {
                let wi = DVec3::new(x, y, z2.sqrt());
                table.lookup(wi, wo, Interp::Nearest).map_or(0.0, |f| luminance(f) * wi.z)
            })
        })
        .collect()
}

/// The panel of `values` (a [`View`] of `size` x `size` pixels) relative to `peak`, with
/// `samples` (directions) on top.
fn panel(values: &[Option<f64>], peak: f64, view: &View, samples: &[DVec3]) -> Canvas {
    let scale = scale();
    let mut canvas = Canvas::from_fn(view.size, view.size, |x, y| match values[y * view.size + x] {
        None => OUTSIDE,
        Some(v) if v > 0.0 && peak > 0.0 => inferno(scale.position(v / peak)),
        Some(_) => inferno(0.0),
    });
    for wi in samples {
        let (px, py) = view.pixel(wi.x, wi.y);
        canvas.fill_rect(px, py, 2, 2, SAMPLE);
    }
    canvas
}

/// The zoomed view of a panel, centred on the peak pixel, enlarged by the largest power of two
/// from 2 to [`MAX_ZOOM`] that keeps the core within half the view's width, and whether the core
/// is narrow (the zoom is needed); `None` for a panel without a positive value.
fn zoomed(values: &[Option<f64>], whole: &View) -> Option<(View, bool)> {
    let size = whole.size;
    let (peak_at, peak) = values
        .iter()
        .enumerate()
        .filter_map(|(i, v)| v.map(|v| (i, v)))
        .fold((0, 0.0), |best, (i, v)| if v > best.1 { (i, v) } else { best });
    if peak <= 0.0 {
        return None;
    }
    let (cx, cy) = whole.point(peak_at % size, peak_at / size);
    // The core's radius around the peak, in the projected plane.
    let radius = values
        .iter()
        .enumerate()
        .filter(|(_, v)| v.is_some_and(|v| v >= CORE * peak))
        .map(|(i, _)| {
            let (x, y) = whole.point(i % size, i / size);
            (x - cx).hypot(y - cy)
        })
        .fold(0.0f64, f64::max)
        + 1.0 / size as f64;
    let mut zoom = 2;
    while zoom < MAX_ZOOM && radius * (2 * zoom) as f64 <= 0.5 {
        zoom *= 2;
    }
    Some((View { cx, cy, half: 1.0 / zoom as f64, size }, radius <= NARROW))
}

/// The figure: panels of `size` x `size` pixels for the slices `slices` of `tables` (built from
/// `table`, a material called `name`), the zoomed row when some lobe is narrow, the colour bar
/// and the caption.
pub fn lobes(name: &str, table: &MerlTable, tables: &ImportanceTables, slices: &[usize], size: usize) -> Canvas {
    let whole = View::whole(size);
    let mut below_scale = false;
    let mut n_samples = 0;
    let mut rows: [Vec<(Canvas, String)>; 2] = [Vec::new(), Vec::new()];
    let mut zooms = Vec::new();
    for &k in slices {
        let slice = &tables.slices()[k];
        let samples: Vec<DVec3> =
            tables.samples(k, 0).iter().filter(|s| s.pdf > 0.0 && s.wi.z > 0.0).map(|s| s.wi).collect();
        n_samples = n_samples.max(tables.samples(k, 0).len());
        let values = lobe_values(table, slice.wo(), &whole);
        let peak = values.iter().flatten().fold(0.0f64, |m, v| m.max(*v));
        let floor = 10f64.powi(-DECADES) * peak;
        below_scale |= values.iter().flatten().any(|v| *v < floor);
        let title = format!("theta_o = {}\u{b0}", format_number((slice.theta_o().to_degrees() * 10.0).round() / 10.0));
        rows[0].push((panel(&values, peak, &whole, &samples), title));
        zooms.push(zoomed(&values, &whole).map(|view| (view, slice.wo(), peak, samples)));
    }
    if zooms.iter().flatten().any(|(zoom, ..)| zoom.1) {
        for zoom in zooms {
            rows[1].push(match zoom {
                Some(((view, _), wo, peak, samples)) => {
                    let values = lobe_values(table, wo, &view);
                    let factor = (1.0 / view.half).round();
                    (panel(&values, peak, &view, &samples), format!("{factor}x around the peak"))
                }
                None => (Canvas::new(size, size, picture::BACKGROUND), "no positive value".to_string()),
            });
        }
    }
    let zoomed_row = !rows[1].is_empty();
    let mut grid = Grid::new(slices.len());
    grid.title(format!("importance sampling of {name}: the lobe L(f) cos theta_i and {n_samples} samples per slice"));
    for (canvas, title) in rows.into_iter().flatten() {
        grid.add(canvas, title);
    }
    let width = grid.width();
    let legend =
        Legend::new(scale(), inferno, "L(f) cos theta_i (luminance), fraction of the panel's peak (log scale)")
            .clipped((below_scale, false))
            .swatch(OUTSIDE, "outside the hemisphere (below the horizon)")
            .swatch(SAMPLE, "samples of the first vector, drawn on top");
    let mut text = "Each panel: the hemisphere of wi seen from above (orthographic): wi.x to the right, wi.y up. wo \
                    lies on the +x side, so the mirror direction is at (-sin theta_o, 0), left of the centre, on \
                    the rim at grazing angles. Black: below 1e-6 of the peak, or no data in the table."
        .to_string();
    if zoomed_row {
        text.push_str(
            " Second row: the panel above around its brightest pixel, enlarged, on the same colour scale (a \
             mirror-like lobe is a few pixels wide in the first row).",
        );
    }
    grid.footer(stack(&[legend.render(width), caption(&text, width)]));
    grid.render()
}

#[cfg(test)]
mod tests {
    use super::*;
    use importance::Config;
    use merl::Dims;
    use merl::analytic::Analytic;
    use picture::INK;
    use picture::legend::ticks;

    /// Tables small enough for a unit test: few slices, few samples.
    fn build(analytic: Analytic) -> (MerlTable, ImportanceTables) {
        let table = analytic.table(Dims::MERL);
        let config = Config { n_theta_o: 9, n_vectors: 1, n_samples: 64, ..Config::default() };
        let tables = importance::build(&table, &config).unwrap();
        (table, tables)
    }

    /// The row and column where the legend's bar starts in a figure `width` wide: the first row
    /// whose bar columns hold inferno's ends.
    fn bar(figure: &Canvas) -> (usize, usize, usize) {
        let (left, bar_width) = Legend::bar(figure.width);
        let row = (0..figure.height)
            .find(|&y| {
                figure.pixel(left, y) == Some(inferno(0.0))
                    && figure.pixel(left + bar_width - 1, y) == Some(inferno(1.0))
            })
            .expect("a colour bar");
        (row, left, bar_width)
    }

    /// Titles with each slice's angle, the disk's outside in grey, the lobe's peak at the mirror
    /// direction in the top colour, samples in cyan, and every labelled tick of the bar at the
    /// column of its fraction of the peak (10^-3 half-way along the six decades).
    #[test]
    fn a_glossy_lobe() {
        let (table, tables) = build(Analytic::Ggx { alpha: 0.3, f0: [0.9, 0.9, 0.9] });
        let size = 96;
        let figure = lobes("ggx", &table, &tables, &[0, 3], size);
        for title in ["theta_o = 0\u{b0}", "theta_o = 30\u{b0}", "importance sampling of ggx"] {
            assert!(figure.find(&Canvas::label(title)).is_some(), "title {title:?}");
        }
        assert!(figure.find(&Canvas::label("around the peak")).is_none(), "a wide lobe needs no zoom");
        // The first panel sits under its title.
        let (tx, ty) = figure.find(&Canvas::label("theta_o = 0\u{b0}")).unwrap();
        let top = ty + Canvas::label("x").height + picture::layout::TITLE_GAP;
        assert_eq!(figure.pixel(tx, top), Some(OUTSIDE), "the panel's corner is outside the disk");
        // At theta_o = 0 the mirror direction is the normal: the centre is the peak.
        assert_eq!(figure.pixel(tx + size / 2, top + size / 2).map(|c| c == inferno(1.0) || c == SAMPLE), Some(true));
        assert!(figure.rgb.chunks_exact(3).any(|c| c == SAMPLE));

        let (row, left, bar_width) = bar(&figure);
        let labelled: Vec<_> = ticks(&scale()).into_iter().filter(|t| t.label.is_some()).collect();
        assert_eq!(labelled.len(), 7, "one per decade from 1e-6 to 1");
        for tick in labelled {
            let column = left + (scale().position(tick.value) * (bar_width - 1) as f64).round() as usize;
            let expected = left + ((tick.value.log10() + 6.0) / 6.0 * (bar_width - 1) as f64).round() as usize;
            assert_eq!(column, expected);
            assert_eq!(figure.pixel(column, row + 20), Some(INK), "tick {:?}", tick.label);
        }
    }

    /// A near-mirror lobe gets the zoomed row; there its core (within a decade of the peak) is
    /// whole and covers about the square of the enlargement times as many pixels.
    #[test]
    fn a_mirror_like_lobe_is_enlarged() {
        let (table, tables) = build(Analytic::Ggx { alpha: 0.02, f0: [0.9, 0.9, 0.9] });
        let size = 128;
        let whole = View::whole(size);
        let values = lobe_values(&table, tables.slices()[0].wo(), &whole);
        let (view, narrow) = zoomed(&values, &whole).unwrap();
        assert!(narrow && view.half <= 0.25, "{view:?}");
        let peak = values.iter().flatten().fold(0.0f64, |m, v| m.max(*v));
        let core = |values: &[Option<f64>]| values.iter().flatten().filter(|v| **v >= CORE * peak).count();
        let enlarged = lobe_values(&table, tables.slices()[0].wo(), &view);
        let ratio = (1.0 / view.half).powi(2);
        // Area grows with the square of the zoom; a factor 2 of slack for the core's ragged edge
        // on so few pixels.
        assert!(
            core(&enlarged) as f64 >= core(&values) as f64 * ratio / 2.0,
            "{} vs {}",
            core(&enlarged),
            core(&values)
        );
        // The whole core is in the view: none of it on the view's edges.
        let on_edge = |i: usize| [i % size, i / size].iter().any(|&c| c == 0 || c == size - 1);
        assert!(enlarged.iter().enumerate().all(|(i, v)| !(on_edge(i) && v.is_some_and(|v| v >= CORE * peak))));
        let figure = lobes("mirror", &table, &tables, &[0], size);
        let title = format!("{}x around the peak", 1.0 / view.half);
        assert!(figure.find(&Canvas::label(&title)).is_some(), "{title}");
    }
}
