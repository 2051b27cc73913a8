//! The colour-bar legend every false-colour picture carries: the colour map as a bar across the
//! width, ticks below it at round values of its [`Scale`] (log: every decade, with 2 and 5 times
//! them when the range is three decades or less, and minor ticks at the other multiples; linear:
//! a 1-2-5 step), labelled; an arrow at an end when some data lie beyond it (they are drawn in
//! the end colour); a caption line (what and in which unit); and one swatch line per special
//! colour ("grey: flat").

use crate::colormap::{LEGEND_INTERVALS, Scale, ScaleKind, decimal, linear_ticks};
use crate::font::{ADVANCE, GLYPH_H, text_height, text_width};
use crate::{BACKGROUND, Canvas, INK, TEXT_SCALE, format_number};

/// Space left and right of the bar, outside the arrows.
const MARGIN: usize = 16;
/// Length of an end arrow; the space is kept whether or not the arrow is drawn, so that the bar
/// does not move.
const ARROW: usize = 14;
const BAR_TOP: usize = 10;
const BAR_HEIGHT: usize = 20;
const MAJOR_TICK: usize = 8;
const MINOR_TICK: usize = 4;
const LABELS_TOP: usize = BAR_TOP + BAR_HEIGHT + MAJOR_TICK + 4;
/// Space between lines of text.
const LEADING: usize = 10;
const CAPTION_TOP: usize = LABELS_TOP + GLYPH_H * TEXT_SCALE + LEADING + 4;
const BOTTOM: usize = 12;
/// Between a swatch and its label.
const SWATCH_GAP: usize = 8;

/// One tick of the bar: its value and, for a major tick, its label.
#[derive(Clone, Debug, PartialEq)]
pub struct Tick {
    pub value: f64,
    pub label: Option<String>,
}

/// What a legend shows. Build with [`Legend::new`], then [`Legend::swatch`] and
/// [`Legend::clipped`]; draw with [`Legend::render`].
#[derive(Clone, Debug)]
pub struct Legend {
    pub scale: Scale,
    /// The colour map the picture uses, e.g. [`crate::colormap::inferno`].
    pub colormap: fn(f64) -> [u8; 3],
    /// The caption under the labels: what the colours mean and in which unit, e.g.
    /// "local bandwidth, cycles per radian (log scale)". Empty: no caption line.
    pub caption: String,
    /// Special colours and what they mean, one line each under the caption.
    pub swatches: Vec<([u8; 3], String)>,
    /// Some data lie below the scale (drawn in the bottom colour): an arrow at the left end.
    pub below: bool,
    /// Some data lie above the scale: an arrow at the right end.
    pub above: bool,
}

impl Legend {
    pub fn new(scale: Scale, colormap: fn(f64) -> [u8; 3], caption: impl Into<String>) -> Self {
        Legend { scale, colormap, caption: caption.into(), swatches: Vec::new(), below: false, above: false }
    }

    /// Adds a special colour and its meaning, e.g. `([0, 255, 255], "at the grid's limit")`.
    pub fn swatch(mut self, colour: [u8; 3], label: impl Into<String>) -> Self {
        self.swatches.push((colour, label.into()));
        self
    }

    /// Sets the clipping arrows; [`Scale::clipping`] says where the data exceed the scale.
    pub fn clipped(mut self, (below, above): (bool, bool)) -> Self {
        self.below = below;
        self.above = above;
        self
    }

    /// The height of the rendered legend (it does not depend on the width).
    pub fn height(&self) -> usize {
        self.lines().last().map_or(CAPTION_TOP, |(top, h)| top + h) + BOTTOM
    }

    /// The top row and height of the caption and of each swatch line.
    fn lines(&self) -> Vec<(usize, usize)> {
        let mut top = CAPTION_TOP;
        let mut lines = Vec::new();
        let texts = std::iter::once(&self.caption).filter(|c| !c.is_empty()).chain(self.swatches.iter().map(|s| &s.1));
        for text in texts {
            let h = text_height(text, TEXT_SCALE);
            lines.push((top, h));
            top += h + LEADING;
        }
        lines
    }

    /// The bar's left column and width on a legend `width` pixels wide: the tick of value `v`
    /// is at column `left + round(scale.position(v) * (bar_width - 1))`.
    pub fn bar(width: usize) -> (usize, usize) {
        (MARGIN + ARROW, width.saturating_sub(2 * (MARGIN + ARROW)).max(2))
    }

    /// The legend on a canvas `width` pixels wide, [`Legend::height`] high.
    pub fn render(&self, width: usize) -> Canvas {
        let mut canvas = Canvas::new(width, self.height(), BACKGROUND);
        let (left, bar_width) = Legend::bar(width);
        let column = |t: f64| (left + (t * (bar_width - 1) as f64).round() as usize) as isize;
        for i in 0..bar_width {
            let colour = (self.colormap)(i as f64 / (bar_width - 1) as f64);
            canvas.vline((left + i) as isize, BAR_TOP as isize, BAR_HEIGHT, colour);
        }
        // Triangles pointing outwards: values beyond an end take its colour.
        for i in 0..ARROW {
            let half = (BAR_HEIGHT / 2) * (ARROW - i) / ARROW;
            let y = (BAR_TOP + BAR_HEIGHT / 2 - half) as isize;
            if self.above {
                canvas.vline((left + bar_width + i) as isize, y, 2 * half, (self.colormap)(1.0));
            }
            if self.below {
                canvas.vline(left as isize - 1 - i as isize, y, 2 * half, (self.colormap)(0.0));
            }
        }
        let mut last_label_end: Option<isize> = None;
        for tick in ticks(&self.scale) {
            let x = column(self.scale.position(tick.value));
            let length = if tick.label.is_some() { MAJOR_TICK } else { MINOR_TICK };
            canvas.vline(x, (BAR_TOP + BAR_HEIGHT) as isize, length, INK);
            if let Some(label) = tick.label {
                let w = text_width(&label, TEXT_SCALE) as isize;
                // Centred under the tick, pushed inside the canvas at the ends.
                let at = (x - w / 2).min(width as isize - w).max(0);
                // A label that would touch the previous one is left out.
                if last_label_end.is_none_or(|end| at >= end + (TEXT_SCALE * ADVANCE) as isize) {
                    canvas.text(at, LABELS_TOP as isize, &label, TEXT_SCALE, INK);
                    last_label_end = Some(at + w);
                }
            }
        }
        let swatch = GLYPH_H * TEXT_SCALE;
        let mut lines = self.lines().into_iter();
        if !self.caption.is_empty()
            && let Some((top, _)) = lines.next()
        {
            canvas.text(MARGIN as isize, top as isize, &self.caption, TEXT_SCALE, INK);
        }
        for ((colour, label), (top, _)) in self.swatches.iter().zip(lines) {
            canvas.fill_rect(MARGIN as isize, top as isize, swatch, swatch, *colour);
            canvas.text((MARGIN + swatch + SWATCH_GAP) as isize, top as isize, label, TEXT_SCALE, INK);
        }
        canvas
    }
}

/// The ticks of `scale`'s bar, in increasing order, majors labelled. A scale with fewer than two
/// round labels gets its ends labelled as well.
pub fn ticks(scale: &Scale) -> Vec<Tick> {
    let (lo, hi) = (scale.lo(), scale.hi());
    let mut ticks = match scale.kind() {
        ScaleKind::Log => log_ticks(lo, hi),
        ScaleKind::Linear => {
            let (values, step) = linear_ticks(lo, hi, LEGEND_INTERVALS);
            let decimals = (-step.e).max(0) as usize;
            let plain = (1e-3..=1e5).contains(&lo.abs().max(hi.abs()));
            let label = |v: f64| if plain { format!("{v:.decimals$}") } else { format_number(v) };
            values.into_iter().map(|v| Tick { value: v, label: Some(label(v)) }).collect()
        }
    };
    if ticks.iter().filter(|t| t.label.is_some()).count() < 2 {
        let is_at = |v: f64, end: f64| (v - end).abs() <= 1e-9 * end.abs().max(f64::MIN_POSITIVE);
        ticks.retain(|t| !is_at(t.value, lo) && !is_at(t.value, hi));
        ticks.insert(0, Tick { value: lo, label: Some(format_number(lo)) });
        ticks.push(Tick { value: hi, label: Some(format_number(hi)) });
    }
    ticks
}

/// Decades are major; 2 and 5 times them too on a short scale, and so is a tick at an end. The
/// other multiples are minor ticks, left out beyond 8 decades where they would merge.
fn log_ticks(lo: f64, hi: f64) -> Vec<Tick> {
    let decades = (hi / lo).log10();
    let mut ticks = Vec::new();
    for e in lo.log10().floor() as i32..=hi.log10().ceil() as i32 {
        for m in 1..10 {
            let v = decimal(m, e);
            if v < lo * (1.0 - 1e-9) || v > hi * (1.0 + 1e-9) {
                continue;
            }
            let is_end = (v / lo - 1.0).abs() < 1e-9 || (v / hi - 1.0).abs() < 1e-9;
            let major = m == 1 || is_end || (decades <= 3.0 && (m == 2 || m == 5));
            if major || decades <= 8.0 {
                ticks.push(Tick { value: v, label: major.then(|| format_number(v)) });
            }
        }
    }
    ticks
}
