//! The false-colour picture: the bandwidth map on a logarithmic colour scale (matplotlib's
//! inferno: dark is low, bright is high), pixels at the grid's Nyquist limit in cyan (their true
//! bandwidth may be higher than the value shown), flat pixels (no significant detail) in grey;
//! and below the map a legend: the colour bar with ticks at every decade (and at 2 and 5 times
//! them when the range is short), labelled in the map's unit, and the two special colours.
//!
//! Layout: the map at the top, `k` pixels per map pixel (`k = max(1, 512 / max(width, height))`,
//! so small textures stay visible), left-aligned on a canvas at least [`MIN_WIDTH`] wide; the
//! legend is a strip of [`LEGEND_HEIGHT`] pixels below it.

use envmap::colormap::inferno;

use crate::font::{ADVANCE, GLYPH_H, glyph, text_width};

/// The canvas is at least this wide, so the legend's lines fit.
pub const MIN_WIDTH: usize = 640;
/// The height of the legend strip below the map: 144 pixels.
pub const LEGEND_HEIGHT: usize = FLAT_TOP + GLYPH_H * SCALE + 12;

/// Pixels at the Nyquist limit: a colour inferno never reaches.
pub const NYQUIST: [u8; 3] = [0, 255, 255];
/// Flat pixels (no significant level).
pub const FLAT: [u8; 3] = [128, 128, 128];
const BACKGROUND: [u8; 3] = [24, 24, 24];
const INK: [u8; 3] = [235, 235, 235];

/// Font pixels per glyph pixel.
const SCALE: usize = 2;
/// Left and right margin of the legend.
const MARGIN: usize = 16;
/// Length of the arrow after the bar when the scale is clipped.
const ARROW: usize = 14;
const BAR_TOP: usize = 10;
const BAR_HEIGHT: usize = 20;
const MAJOR_TICK: usize = 8;
const MINOR_TICK: usize = 4;
const LABELS_TOP: usize = BAR_TOP + BAR_HEIGHT + MAJOR_TICK + 4;
const LINE: usize = GLYPH_H * SCALE + 10;
const CAPTION_TOP: usize = LABELS_TOP + LINE + 4;
const NYQUIST_TOP: usize = CAPTION_TOP + LINE;
const FLAT_TOP: usize = NYQUIST_TOP + LINE;

/// What the picture shows of one map.
#[derive(Debug)]
pub struct Input<'a> {
    pub width: usize,
    pub height: usize,
    /// The bandwidth per pixel, row-major, in `unit`.
    pub values: &'a [f64],
    /// The wavelet level `j*` per pixel (`BandwidthMap::level`): 0 flat, 1 at the Nyquist limit.
    pub levels: &'a [u8],
    /// "cycles per radian" or "cycles per pixel".
    pub unit: &'a str,
}

/// An 8-bit RGB image, row-major.
#[derive(Debug)]
pub struct Picture {
    pub width: usize,
    pub height: usize,
    pub rgb: Vec<u8>,
}

impl Picture {
    fn new(width: usize, height: usize) -> Self {
        Picture { width, height, rgb: BACKGROUND.repeat(width * height) }
    }

    #[cfg(test)]
    pub fn pixel(&self, x: usize, y: usize) -> [u8; 3] {
        let i = 3 * (y * self.width + x);
        [self.rgb[i], self.rgb[i + 1], self.rgb[i + 2]]
    }

    fn fill(&mut self, x0: usize, y0: usize, w: usize, h: usize, colour: [u8; 3]) {
        for y in y0..(y0 + h).min(self.height) {
            for x in x0..(x0 + w).min(self.width) {
                let i = 3 * (y * self.width + x);
                self.rgb[i..i + 3].copy_from_slice(&colour);
            }
        }
    }

    /// Draws `text` with its top-left corner at `(x, y)`; a character the font lacks is drawn as
    /// a box, so a missing glyph shows instead of vanishing.
    fn text(&mut self, x: usize, y: usize, text: &str) {
        for (i, c) in text.chars().enumerate() {
            let left = x + i * ADVANCE * SCALE;
            let rows = glyph(c).unwrap_or([0b11111, 0b10001, 0b10001, 0b10001, 0b10001, 0b10001, 0b11111]);
            for (r, bits) in rows.iter().enumerate() {
                for col in 0..5 {
                    if bits >> (4 - col) & 1 == 1 {
                        self.fill(left + col * SCALE, y + r * SCALE, SCALE, SCALE, INK);
                    }
                }
            }
        }
    }
}

/// The colour scale: logarithmic from `lo` to `hi`, both 1, 2 or 5 times a power of ten, from
/// the smallest positive value to the 99th percentile. The top percent is drawn in the end colour
/// (an arrow at the bar's end says so): on a lat-long map it is the rows nearest the poles,
/// where the conversion to cycles per radian multiplies by `1 / sin(theta)` (up to 326 at
/// 1024 x 512), and spending the scale on them would leave the rest of the map in a few colours.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LogScale {
    pub lo: f64,
    pub hi: f64,
    /// Some value is above `hi`.
    pub clipped: bool,
}

/// The percentile of the positive values at the top of the scale.
const TOP_PERCENTILE: f64 = 0.99;

impl LogScale {
    /// The scale of `values`; `0.001 .. 1` when none is positive.
    pub fn around(values: &[f64]) -> Self {
        let mut positive: Vec<f64> = values.iter().copied().filter(|v| *v > 0.0).collect();
        if positive.is_empty() {
            return LogScale { lo: 1e-3, hi: 1.0, clipped: false };
        }
        positive.sort_by(f64::total_cmp);
        let top = positive[((positive.len() - 1) as f64 * TOP_PERCENTILE).round() as usize];
        let lo = nice_at_most(positive[0]);
        let hi = nice_at_least(top).max(nice_at_least(lo * 1.01));
        LogScale { lo, hi, clipped: positive[positive.len() - 1] > hi }
    }

    /// The position of `v` on the scale, `0..=1` (clamped).
    pub fn position(&self, v: f64) -> f64 {
        ((v / self.lo).log10() / (self.hi / self.lo).log10()).clamp(0.0, 1.0)
    }
}

/// The mantissas of the scale's ends and labelled ticks.
const NICE: [f64; 3] = [1.0, 2.0, 5.0];

/// The largest `m 10^e <= v`, `m` in [`NICE`]. Compared with a relative tolerance, so that a
/// value that is a nice number up to rounding is its own end.
fn nice_at_most(v: f64) -> f64 {
    let e = v.log10().floor() as i32;
    let candidates = (e - 1..=e + 1).flat_map(|e| NICE.map(|m| m * 10f64.powi(e)));
    candidates.filter(|n| *n <= v * (1.0 + 1e-9)).fold(0.0, f64::max)
}

/// The smallest `m 10^e >= v`, `m` in [`NICE`].
fn nice_at_least(v: f64) -> f64 {
    let e = v.log10().floor() as i32;
    let candidates = (e - 1..=e + 1).flat_map(|e| NICE.map(|m| m * 10f64.powi(e)));
    candidates.filter(|n| *n >= v * (1.0 - 1e-9)).fold(f64::INFINITY, f64::min)
}

/// The colour of one map pixel.
pub fn colour(value: f64, level: u8, scale: &LogScale) -> [u8; 3] {
    match level {
        0 => FLAT,
        1 => NYQUIST,
        _ => inferno(scale.position(value)),
    }
}

/// Map pixels per image pixel: small images are enlarged so that they stay visible.
pub fn zoom(width: usize, height: usize) -> usize {
    (512 / width.max(height)).max(1)
}

/// The size of the picture of a `width` x `height` map.
pub fn size(width: usize, height: usize) -> (usize, usize) {
    let k = zoom(width, height);
    ((k * width).max(MIN_WIDTH), k * height + LEGEND_HEIGHT)
}

/// Renders the map and its legend.
pub fn render(input: &Input<'_>) -> Picture {
    let (w, h) = (input.width, input.height);
    assert!(input.values.len() == w * h && input.levels.len() == w * h, "values and levels must be {w}x{h}");
    let scale = LogScale::around(input.values);
    let (pw, ph) = size(w, h);
    let k = zoom(w, h);
    let mut picture = Picture::new(pw, ph);
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            picture.fill(k * x, k * y, k, k, colour(input.values[i], input.levels[i], &scale));
        }
    }
    legend(&mut picture, k * h, &scale, input.unit);
    picture
}

/// The legend strip, starting at row `top`.
fn legend(picture: &mut Picture, top: usize, scale: &LogScale, unit: &str) {
    let bar_width = (picture.width - 2 * MARGIN - ARROW).min(1024);
    let bar_x = |t: f64| MARGIN + (t * (bar_width - 1) as f64).round() as usize;
    for i in 0..bar_width {
        picture.fill(MARGIN + i, top + BAR_TOP, 1, BAR_HEIGHT, inferno(i as f64 / (bar_width - 1) as f64));
    }
    if scale.clipped {
        // A triangle pointing right: values beyond the bar's end take its colour.
        for i in 0..ARROW {
            let half = (BAR_HEIGHT / 2) * (ARROW - i) / ARROW;
            picture.fill(MARGIN + bar_width + i, top + BAR_TOP + BAR_HEIGHT / 2 - half, 1, 2 * half, inferno(1.0));
        }
    }
    let decades = (scale.hi / scale.lo).log10();
    let mut last_label_end = None;
    let (e0, e1) = (scale.lo.log10().floor() as i32, scale.hi.log10().ceil() as i32);
    for e in e0..=e1 {
        for m in 1..10 {
            let v = f64::from(m) * 10f64.powi(e);
            if v < scale.lo * (1.0 - 1e-9) || v > scale.hi * (1.0 + 1e-9) {
                continue;
            }
            let x = bar_x(scale.position(v));
            let is_end = (v / scale.lo - 1.0).abs() < 1e-9 || (v / scale.hi - 1.0).abs() < 1e-9;
            let major = m == 1 || is_end || (decades <= 3.0 && (m == 2 || m == 5));
            picture.fill(x, top + BAR_TOP + BAR_HEIGHT, 1, if major { MAJOR_TICK } else { MINOR_TICK }, INK);
            if major {
                let label = tick_label(m, e);
                let width = text_width(&label, SCALE);
                let left = x.saturating_sub(width / 2).max(MARGIN / 2);
                // A label that would touch the previous one or leave the canvas is skipped.
                let clear = last_label_end.is_none_or(|end| left >= end + SCALE * ADVANCE);
                if clear && left + width <= picture.width {
                    picture.text(left, top + LABELS_TOP, &label);
                    last_label_end = Some(left + width);
                }
            }
        }
    }
    picture.text(MARGIN, top + CAPTION_TOP, &format!("local bandwidth, {unit} (log scale)"));
    let swatch = GLYPH_H * SCALE;
    let text_x = MARGIN + swatch + 8;
    picture.fill(MARGIN, top + NYQUIST_TOP, swatch, swatch, NYQUIST);
    picture.text(text_x, top + NYQUIST_TOP, "at the Nyquist limit: may be higher");
    picture.fill(MARGIN, top + FLAT_TOP, swatch, swatch, FLAT);
    picture.text(text_x, top + FLAT_TOP, "flat: no significant detail");
}

/// `m 10^e` as a short decimal: `0.001`, `0.2`, `50`, `10000`; outside `1e-4 .. 1e6`, `5E-7`.
pub fn tick_label(m: i32, e: i32) -> String {
    if (-4..6).contains(&e) {
        let v = f64::from(m) * 10f64.powi(e);
        let decimals = (-e).max(0) as usize;
        format!("{v:.decimals$}")
    } else {
        format!("{m}e{e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tick_labels() {
        let labels: Vec<String> =
            [(1, -3), (2, -1), (5, 0), (1, 4), (1, 6), (5, -7)].map(|(m, e)| tick_label(m, e)).into();
        assert_eq!(labels, ["0.001", "0.2", "5", "10000", "1e6", "5e-7"]);
    }

    /// The ends are nice numbers around the smallest value and the 99th percentile.
    #[test]
    fn the_scale_runs_from_the_minimum_to_the_99th_percentile() {
        let mut values = vec![0.0, 0.03];
        values.extend((0..98).map(|i| 1.0 + f64::from(i) / 10.0));
        values.push(4700.0);
        let s = LogScale::around(&values);
        assert_eq!((s.lo, s.hi, s.clipped), (0.02, 20.0, true));
        assert_eq!(LogScale::around(&[0.1]), LogScale { lo: 0.1, hi: 0.2, clipped: false });
        assert_eq!(LogScale::around(&[0.0, 0.0]), LogScale { lo: 1e-3, hi: 1.0, clipped: false });
        assert_eq!(
            (nice_at_most(0.3173), nice_at_least(12.53), nice_at_least(5.0), nice_at_most(0.999)),
            (0.2, 20.0, 5.0, 0.5)
        );
        let s = LogScale { lo: 0.01, hi: 1e4, clipped: false };
        assert_eq!((s.position(0.01), s.position(1e4), s.position(1e9), s.position(1e-3)), (0.0, 1.0, 1.0, 0.0));
        assert!((s.position(1.0) - 1.0 / 3.0).abs() < 1e-12);
    }

    /// Inferno's ends and lightness order: higher values are never darker.
    #[test]
    fn inferno_is_dark_to_bright() {
        assert_eq!(inferno(0.0), [0, 0, 4]);
        assert_eq!(inferno(1.0), [252, 255, 164]);
        let luma = |c: [u8; 3]| 0.2126 * f64::from(c[0]) + 0.7152 * f64::from(c[1]) + 0.0722 * f64::from(c[2]);
        for i in 0..100 {
            assert!(luma(inferno(f64::from(i + 1) / 100.0)) >= luma(inferno(f64::from(i) / 100.0)), "at {i}");
        }
        assert!((0..=100).all(|i| inferno(f64::from(i) / 100.0) != NYQUIST && inferno(f64::from(i) / 100.0) != FLAT));
    }

    /// Every map pixel gets the colour of its class and value, small maps are enlarged, and the
    /// legend shows the bar and the two special colours.
    #[test]
    fn pixels_and_legend() {
        let (w, h) = (4, 2);
        let values = [0.0, 0.01, 0.1, 1.0, 10.0, 100.0, 0.05, 0.05];
        let levels = [0, 9, 7, 5, 3, 1, 8, 8];
        let p = render(&Input { width: w, height: h, values: &values, levels: &levels, unit: "cycles per pixel" });
        assert_eq!((p.width, p.height), (MIN_WIDTH, 256 + LEGEND_HEIGHT));
        assert_eq!((p.width, p.height), size(w, h));
        let k = zoom(w, h);
        assert_eq!(k, 128);
        let scale = LogScale::around(&values);
        assert_eq!((scale.lo, scale.hi, scale.clipped), (0.01, 100.0, false));
        for (i, (&v, &l)) in values.iter().zip(&levels).enumerate() {
            let (x, y) = (i % w, i / w);
            assert_eq!(p.pixel(k * x + k / 2, k * y + k / 2), colour(v, l, &scale), "pixel {i}");
        }
        assert_eq!(p.pixel(k, 0), inferno(0.0));
        assert_eq!(p.pixel(k, k), NYQUIST);
        assert_eq!(p.pixel(0, 0), FLAT);
        let top = k * h;
        assert_eq!(p.pixel(MARGIN, top + BAR_TOP + 1), inferno(0.0));
        assert_eq!(p.pixel(MARGIN + (p.width - 2 * MARGIN - ARROW).min(1024) - 1, top + BAR_TOP + 1), inferno(1.0));
        assert_eq!(p.pixel(MARGIN + 2, top + NYQUIST_TOP + 2), NYQUIST);
        assert_eq!(p.pixel(MARGIN + 2, top + FLAT_TOP + 2), FLAT);
        let ink = p.rgb.chunks_exact(3).skip(top * p.width).filter(|c| *c == INK).count();
        assert!(ink > 1000, "the legend has {ink} pixels of text and ticks");
        assert_eq!(LEGEND_HEIGHT, 144);
    }

    /// A 1024 x 512 map is drawn at one pixel per map pixel, and its width sets the canvas.
    #[test]
    fn real_map_size() {
        assert_eq!(size(1024, 512), (1024, 512 + LEGEND_HEIGHT));
        assert_eq!(size(300, 200), (MIN_WIDTH, 200 + LEGEND_HEIGHT));
        assert_eq!(size(64, 64), (512.max(MIN_WIDTH), 512 + LEGEND_HEIGHT));
    }
}
