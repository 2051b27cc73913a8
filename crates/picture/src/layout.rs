//! Figures made of labelled parts: a [`Grid`] of panels, each with its title above it, under an
//! optional figure title and over an optional footer (a legend); [`heat_map`], an image with
//! ticks, tick labels and titles on its left and bottom axes; [`caption`], a paragraph wrapped
//! to a width; and [`stack`], parts one below the other (a legend and its caption). Titles are
//! written horizontally (the font has no rotated glyphs): the vertical axis's title sits above
//! it.

use crate::colormap::linear_ticks;
use crate::font::{ADVANCE, GLYPH_H, text_height, text_width, wrap};
use crate::{BACKGROUND, Canvas, INK, TEXT_SCALE, format_number};

/// Space between a title and what it labels.
pub const TITLE_GAP: usize = 6;

/// Space after a panel title, beside the gap, before the next column: two characters.
pub const TITLE_SPACE: usize = 2 * ADVANCE * TEXT_SCALE;

/// Panels in rows of `columns`, left to right, top to bottom. A column is as wide as its widest
/// panel or panel title, a title followed by [`TITLE_SPACE`] where another column comes after it
/// (two titles a gap apart read as one line); a row is as high as its highest panel plus the
/// title line (none when no panel of the row has a title).
#[derive(Clone, Debug)]
pub struct Grid {
    columns: usize,
    panels: Vec<(Canvas, String)>,
    title: String,
    footer: Option<Canvas>,
    margin: usize,
    gap: usize,
}

impl Grid {
    /// An empty grid of `columns` columns (at least one), 16-pixel margins and gaps.
    pub fn new(columns: usize) -> Self {
        Grid { columns: columns.max(1), panels: Vec::new(), title: String::new(), footer: None, margin: 16, gap: 16 }
    }

    /// Adds a panel and the title drawn above it (empty: none).
    pub fn add(&mut self, panel: Canvas, title: impl Into<String>) -> &mut Self {
        self.panels.push((panel, title.into()));
        self
    }

    /// The figure's title, above the panels (empty: none).
    pub fn title(&mut self, title: impl Into<String>) -> &mut Self {
        self.title = title.into();
        self
    }

    /// A canvas drawn under the panels at the left edge, e.g. a legend rendered at
    /// [`Grid::width`].
    pub fn footer(&mut self, footer: Canvas) -> &mut Self {
        self.footer = Some(footer);
        self
    }

    /// The space around the figure's content.
    pub fn margin(&mut self, margin: usize) -> &mut Self {
        self.margin = margin;
        self
    }

    /// The space between panels, and between the figure title and the panels.
    pub fn gap(&mut self, gap: usize) -> &mut Self {
        self.gap = gap;
        self
    }

    /// The width of each column.
    fn column_widths(&self) -> Vec<usize> {
        let columns = self.columns.min(self.panels.len());
        let mut widths = vec![0; columns];
        for (i, (panel, title)) in self.panels.iter().enumerate() {
            let followed = i % self.columns + 1 < columns && !title.is_empty();
            let w = &mut widths[i % self.columns];
            *w = (*w).max(panel.width).max(text_width(title, TEXT_SCALE) + if followed { TITLE_SPACE } else { 0 });
        }
        widths
    }

    /// The height of each row's title line and of its panels.
    fn rows(&self) -> Vec<(usize, usize)> {
        self.panels
            .chunks(self.columns)
            .map(|row| {
                let titles = row.iter().filter(|(_, t)| !t.is_empty());
                let title = titles.map(|(_, t)| text_height(t, TEXT_SCALE) + TITLE_GAP).max().unwrap_or(0);
                (title, row.iter().map(|(p, _)| p.height).max().unwrap_or(0))
            })
            .collect()
    }

    /// The width of the figure without its footer: the width to render a legend footer at.
    pub fn width(&self) -> usize {
        let widths = self.column_widths();
        let panels = widths.iter().sum::<usize>() + self.gap * widths.len().saturating_sub(1);
        panels.max(text_width(&self.title, TEXT_SCALE)) + 2 * self.margin
    }

    /// The figure on one canvas: at least [`Grid::width`] wide, wider if the footer is.
    pub fn render(&self) -> Canvas {
        let widths = self.column_widths();
        let rows = self.rows();
        let title = if self.title.is_empty() { 0 } else { text_height(&self.title, TEXT_SCALE) + self.gap };
        let panels = rows.iter().map(|(t, h)| t + h).sum::<usize>() + self.gap * rows.len().saturating_sub(1);
        let body = self.margin + title + panels + self.margin;
        let (footer_width, footer_height) = self.footer.as_ref().map_or((0, 0), |f| (f.width, f.height));
        let mut canvas = Canvas::new(self.width().max(footer_width), body + footer_height, BACKGROUND);
        let m = self.margin as isize;
        canvas.text(m, m, &self.title, TEXT_SCALE, INK);
        let mut y = self.margin + title;
        for (row, (title_height, panel_height)) in self.panels.chunks(self.columns).zip(rows) {
            let mut x = self.margin;
            for ((panel, panel_title), width) in row.iter().zip(&widths) {
                canvas.text(x as isize, y as isize, panel_title, TEXT_SCALE, INK);
                canvas.blit(panel, x as isize, (y + title_height) as isize, 1);
                x += width + self.gap;
            }
            y += title_height + panel_height + self.gap;
        }
        if let Some(footer) = &self.footer {
            canvas.blit(footer, 0, body as isize, 1);
        }
        canvas
    }
}

/// One axis of a [`heat_map`]: its title, the values at the image's two edges (`from` at the
/// left or top edge, `to` at the right or bottom edge; `to < from` for a vertical axis that
/// increases upwards) and the ticks, `(value, label)`.
#[derive(Clone, Debug, PartialEq)]
pub struct Axis {
    pub title: String,
    pub from: f64,
    pub to: f64,
    pub ticks: Vec<(f64, String)>,
}

impl Axis {
    /// An axis with ticks at round values (a 1-2-5 step, at most 4 intervals), labelled with
    /// [`format_number`].
    pub fn new(title: impl Into<String>, from: f64, to: f64) -> Self {
        let (values, _) = linear_ticks(from, to, 4);
        let ticks = values.into_iter().map(|v| (v, format_number(v))).collect();
        Axis { title: title.into(), from, to, ticks }
    }

    /// The same axis with the given ticks instead.
    pub fn with_ticks(mut self, ticks: Vec<(f64, String)>) -> Self {
        self.ticks = ticks;
        self
    }

    /// The pixel of `value` along an edge of `len` pixels, `None` outside the axis.
    fn pixel(&self, value: f64, len: usize) -> Option<usize> {
        let t = (value - self.from) / (self.to - self.from);
        let inside = (-1e-9..=1.0 + 1e-9).contains(&t) && len > 0;
        inside.then(|| ((t * len as f64).round() as usize).min(len - 1))
    }
}

/// Length of a tick outside the axis line.
const TICK: usize = 5;
/// Space between a tick and its label, and between labels and a title.
const PAD: usize = 4;

/// `image` enlarged `zoom` times (nearest) with an axis line, ticks and tick labels on its left
/// and bottom edges, the horizontal axis's title centred below and the vertical axis's title
/// above the labels at the top left. A tick at value `v` marks the pixel at
/// `(v - from) / (to - from)` of the edge's length (the last pixel for `to`).
pub fn heat_map(image: &Canvas, zoom: usize, x: &Axis, y: &Axis) -> Canvas {
    let (w, h) = (image.width * zoom, image.height * zoom);
    let label_h = GLYPH_H * TEXT_SCALE;
    let widest = |axis: &Axis| axis.ticks.iter().map(|(_, l)| text_width(l, TEXT_SCALE)).max().unwrap_or(0);
    let (x_labels, y_labels) = (widest(x), widest(y));
    // Space above the vertical axis's title, so that it does not read as a second line of a
    // panel title drawn just above the canvas.
    let y_title = if y.title.is_empty() { 0 } else { 2 * PAD + text_height(&y.title, TEXT_SCALE) + PAD };
    let x_title = if x.title.is_empty() { 0 } else { PAD + text_height(&x.title, TEXT_SCALE) };
    // Room for the labels that stick out: y labels on the left, half a label past each end of
    // the x axis, half a label height above the top y label.
    let left = (y_labels + PAD + TICK + 1).max(x_labels / 2 + 1);
    let top = y_title + label_h / 2;
    let plot_bottom = top + h + 1 + TICK + PAD + label_h + x_title;
    let width = (left + w + x_labels / 2).max(text_width(&y.title, TEXT_SCALE)).max(text_width(&x.title, TEXT_SCALE));
    let mut canvas = Canvas::new(width, plot_bottom + PAD, BACKGROUND);
    let (left_i, top_i) = (left as isize, top as isize);
    canvas.blit(image, left_i, top_i, zoom);
    canvas.vline(left_i - 1, top_i, h + 1, INK);
    canvas.hline(left_i - 1, top_i + h as isize, w + 1, INK);

    let mut last_end: Option<isize> = None;
    for (value, label) in &x.ticks {
        let Some(px) = x.pixel(*value, w) else { continue };
        let cx = left_i + px as isize;
        canvas.vline(cx, top_i + h as isize + 1, TICK, INK);
        let lw = text_width(label, TEXT_SCALE) as isize;
        let at = cx - lw / 2;
        if last_end.is_none_or(|end| at > end + PAD as isize) {
            canvas.text(at, top_i + (h + 1 + TICK + PAD) as isize, label, TEXT_SCALE, INK);
            last_end = Some(at + lw);
        }
    }
    let mut last_bottom: Option<isize> = None;
    let mut y_ticks: Vec<(usize, &String)> = y.ticks.iter().filter_map(|(v, l)| Some((y.pixel(*v, h)?, l))).collect();
    y_ticks.sort_by_key(|(py, _)| *py);
    for (py, label) in y_ticks {
        let cy = top_i + py as isize;
        canvas.hline(left_i - 1 - TICK as isize, cy, TICK, INK);
        let at = cy - (label_h / 2) as isize;
        if last_bottom.is_none_or(|bottom| at > bottom + PAD as isize) {
            let lw = text_width(label, TEXT_SCALE) as isize;
            canvas.text(left_i - 1 - (TICK + PAD) as isize - lw, at, label, TEXT_SCALE, INK);
            last_bottom = Some(at + label_h as isize);
        }
    }
    canvas.text(0, 2 * PAD as isize, &y.title, TEXT_SCALE, INK);
    let title_w = text_width(&x.title, TEXT_SCALE) as isize;
    let title_x = (left_i + w as isize / 2 - title_w / 2).clamp(0, (width as isize - title_w).max(0));
    canvas.text(title_x, (plot_bottom - x_title + PAD) as isize, &x.title, TEXT_SCALE, INK);
    canvas
}

/// The left and right margin of a [`caption`], the same as a legend's.
pub const CAPTION_MARGIN: usize = 16;

/// `text` wrapped to a canvas `width` pixels wide (less [`CAPTION_MARGIN`] on each side), with
/// half a line of space above and below: a caption under a figure.
pub fn caption(text: &str, width: usize) -> Canvas {
    let lines = wrap(text, width.saturating_sub(2 * CAPTION_MARGIN), TEXT_SCALE);
    let pad = GLYPH_H * TEXT_SCALE / 2;
    let mut canvas = Canvas::new(width, text_height(&lines, TEXT_SCALE) + 2 * pad, BACKGROUND);
    canvas.text(CAPTION_MARGIN as isize, pad as isize, &lines, TEXT_SCALE, INK);
    canvas
}

/// `parts` one below the other, left-aligned, on a canvas as wide as the widest.
pub fn stack(parts: &[Canvas]) -> Canvas {
    let width = parts.iter().map(|p| p.width).max().unwrap_or(0);
    let mut canvas = Canvas::new(width, parts.iter().map(|p| p.height).sum(), BACKGROUND);
    let mut y = 0;
    for part in parts {
        canvas.blit(part, 0, y as isize, 1);
        y += part.height;
    }
    canvas
}

/// Two 8-bit RGB pictures of `width` x `height` compared: a heat map of the largest channel's
/// absolute difference per pixel, in 8-bit levels, on a linear scale from 0 to the largest
/// difference (at least 1, so identical pictures show the scale's bottom colour, not a stretched
/// rounding), with its legend and a caption that gives the largest difference, where it is, and
/// how many pixels differ. `what` names the two pictures (`"GPU - CPU"`).
///
/// # Panics
/// If either picture is not `width * height * 3` bytes.
pub fn difference(a: &[u8], b: &[u8], width: usize, height: usize, what: &str) -> Canvas {
    assert!(a.len() == width * height * 3 && b.len() == a.len(), "pictures of {width} x {height} RGB");
    let levels: Vec<u8> = a
        .chunks_exact(3)
        .zip(b.chunks_exact(3))
        .map(|(p, q)| p.iter().zip(q).map(|(x, y)| x.abs_diff(*y)).max().unwrap_or(0))
        .collect();
    let (largest_at, largest) = levels.iter().enumerate().max_by_key(|(i, v)| (**v, std::cmp::Reverse(*i))).unwrap();
    let differing = levels.iter().filter(|&&v| v > 0).count();
    let scale = crate::colormap::Scale::linear(0.0, f64::from((*largest).max(1)));
    let image = Canvas::from_fn(width, height, |x, y| {
        crate::colormap::inferno(scale.position(f64::from(levels[y * width + x])))
    });
    let zoom = (256 / width.max(height).max(1)).max(1);
    let axes = (Axis::new("x, pixels", 0.0, width as f64), Axis::new("y, pixels", 0.0, height as f64));
    let mut panels = Grid::new(1);
    panels.add(heat_map(&image, zoom, &axes.0, &axes.1), format!("|{what}|"));
    let panel_width = panels.width().max(360);
    let text = match differing {
        0 => "Per pixel, the largest channel's difference of the two 8-bit pictures. They are identical.".to_string(),
        _ => format!(
            "Per pixel, the largest channel's difference of the two 8-bit pictures. Largest: {largest} level{} \
             (of 255) at x {}, y {}; {differing} of {} pixels differ.",
            if *largest == 1 { "" } else { "s" },
            largest_at % width,
            largest_at / width,
            width * height
        ),
    };
    panels.footer(stack(&[
        crate::legend::Legend::new(scale, crate::colormap::inferno, format!("|{what}|, 8-bit levels"))
            .render(panel_width),
        caption(&text, panel_width),
    ]));
    panels.render()
}
