//! An 8-bit RGB image to draw on. Positions are signed and every drawing call clips at the
//! edges, so a label or panel that sticks out is cut, never a panic: layouts can place things
//! without checking bounds first.

use crate::font::{ADVANCE, GLYPH_H, GLYPH_W, LINE_HEIGHT, MISSING, glyph, text_height, text_width};

/// Interleaved RGB bytes, three per pixel, row-major, top row first: what
/// `envmap::write_png_rgb8(path, width, height, &rgb)` takes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Canvas {
    pub width: usize,
    pub height: usize,
    pub rgb: Vec<u8>,
}

impl Canvas {
    /// A `width` x `height` canvas filled with `background`.
    pub fn new(width: usize, height: usize, background: [u8; 3]) -> Self {
        Canvas { width, height, rgb: background.repeat(width * height) }
    }

    /// Wraps an RGB8 buffer.
    ///
    /// # Panics
    /// When `rgb` does not hold `3 * width * height` bytes.
    pub fn from_rgb8(width: usize, height: usize, rgb: Vec<u8>) -> Self {
        assert_eq!(rgb.len(), 3 * width * height, "a {width} x {height} rgb canvas needs {} bytes", 3 * width * height);
        Canvas { width, height, rgb }
    }

    /// A canvas whose pixel `(x, y)` is `colour(x, y)`: the usual way to turn values into a
    /// heat map, e.g. `|x, y| inferno(scale.position(values[y * w + x]))`.
    pub fn from_fn(width: usize, height: usize, mut colour: impl FnMut(usize, usize) -> [u8; 3]) -> Self {
        let mut rgb = Vec::with_capacity(3 * width * height);
        for y in 0..height {
            for x in 0..width {
                rgb.extend_from_slice(&colour(x, y));
            }
        }
        Canvas { width, height, rgb }
    }

    /// The colour at `(x, y)`; `None` outside the canvas.
    pub fn pixel(&self, x: usize, y: usize) -> Option<[u8; 3]> {
        (x < self.width && y < self.height).then(|| {
            let i = 3 * (y * self.width + x);
            [self.rgb[i], self.rgb[i + 1], self.rgb[i + 2]]
        })
    }

    /// Sets one pixel (nothing outside the canvas).
    pub fn put(&mut self, x: isize, y: isize, colour: [u8; 3]) {
        self.fill(x as i128, y as i128, 1, 1, colour);
    }

    /// Fills the `w` x `h` rectangle whose top-left corner is `(x, y)`.
    pub fn fill_rect(&mut self, x: isize, y: isize, w: usize, h: usize, colour: [u8; 3]) {
        self.fill(x as i128, y as i128, w as i128, h as i128, colour);
    }

    /// A horizontal line of `len` pixels from `(x, y)` to the right.
    pub fn hline(&mut self, x: isize, y: isize, len: usize, colour: [u8; 3]) {
        self.fill_rect(x, y, len, 1, colour);
    }

    /// A vertical line of `len` pixels from `(x, y)` down.
    pub fn vline(&mut self, x: isize, y: isize, len: usize, colour: [u8; 3]) {
        self.fill_rect(x, y, 1, len, colour);
    }

    /// Copies `src` with its top-left corner at `(x, y)`, each source pixel drawn as a
    /// `scale` x `scale` block (nearest; 0 draws nothing).
    pub fn blit(&mut self, src: &Canvas, x: isize, y: isize, scale: usize) {
        self.blit_rgb8(src.width, src.height, &src.rgb, x, y, scale);
    }

    /// [`Canvas::blit`] from an RGB8 buffer of `width` x `height` pixels.
    ///
    /// # Panics
    /// When `rgb` does not hold `3 * width * height` bytes.
    pub fn blit_rgb8(&mut self, width: usize, height: usize, rgb: &[u8], x: isize, y: isize, scale: usize) {
        assert_eq!(rgb.len(), 3 * width * height, "a {width} x {height} rgb buffer needs {} bytes", 3 * width * height);
        let s = scale as i128;
        let xs = clip(x as i128, (width as i128).saturating_mul(s), self.width);
        let ys = clip(y as i128, (height as i128).saturating_mul(s), self.height);
        for dy in ys {
            let sy = ((dy as i128 - y as i128) / s) as usize;
            for dx in xs.clone() {
                let sx = ((dx as i128 - x as i128) / s) as usize;
                let (i, j) = (3 * (dy * self.width + dx), 3 * (sy * width + sx));
                self.rgb[i..i + 3].copy_from_slice(&rgb[j..j + 3]);
            }
        }
    }

    /// Draws `text` with its top-left corner at `(x, y)`, `scale` pixels per font pixel; `\n`
    /// starts a new line. It covers [`crate::font::text_width`] x [`crate::font::text_height`]
    /// pixels. A character the font lacks is drawn as a hollow box.
    pub fn text(&mut self, x: isize, y: isize, text: &str, scale: usize, colour: [u8; 3]) {
        let s = scale as i128;
        for (l, line) in text.split('\n').enumerate() {
            let top = y as i128 + (l * LINE_HEIGHT) as i128 * s;
            if top >= self.height as i128 {
                break;
            }
            for (i, c) in line.chars().enumerate() {
                let left = x as i128 + (i * ADVANCE) as i128 * s;
                if left >= self.width as i128 {
                    break;
                }
                let rows = glyph(c).unwrap_or(MISSING);
                for (r, bits) in rows.iter().enumerate().take(GLYPH_H) {
                    for col in 0..GLYPH_W {
                        if bits >> (GLYPH_W - 1 - col) & 1 == 1 {
                            self.fill(left + col as i128 * s, top + r as i128 * s, s, s, colour);
                        }
                    }
                }
            }
        }
    }

    /// The canvas resampled to `width` x `height` by a box filter: each new pixel is the mean of
    /// the old pixels under it, weighted by the area they share (so text and thin lines fade
    /// instead of vanishing, as they would with nearest). Means are taken of the sRGB bytes, as
    /// previews do. An empty side gives an empty canvas.
    pub fn resized(&self, width: usize, height: usize) -> Canvas {
        if width == 0 || height == 0 || self.width == 0 || self.height == 0 {
            return Canvas::new(width, height, crate::BACKGROUND);
        }
        // Separable: rows first into `width` columns, then the columns into `height` rows.
        let columns = box_weights(self.width, width);
        let rows = box_weights(self.height, height);
        let mut narrow = vec![0.0f64; 3 * width * self.height];
        for y in 0..self.height {
            for (x, weights) in columns.iter().enumerate() {
                for &(sx, w) in weights {
                    let i = 3 * (y * self.width + sx);
                    for c in 0..3 {
                        narrow[3 * (y * width + x) + c] += w * f64::from(self.rgb[i + c]);
                    }
                }
            }
        }
        let mut rgb = vec![0u8; 3 * width * height];
        for (y, weights) in rows.iter().enumerate() {
            for x in 0..width {
                for c in 0..3 {
                    let v: f64 = weights.iter().map(|&(sy, w)| w * narrow[3 * (sy * width + x) + c]).sum();
                    rgb[3 * (y * width + x) + c] = v.round().clamp(0.0, 255.0) as u8;
                }
            }
        }
        Canvas { width, height, rgb }
    }

    /// The top-left corner of the first place (row by row) where `needle` appears pixel for
    /// pixel: how tests find a label in a figure (`needle` = [`Canvas::label`]). `None` when it
    /// does not appear or is empty.
    pub fn find(&self, needle: &Canvas) -> Option<(usize, usize)> {
        if needle.width == 0 || needle.height == 0 || needle.width > self.width || needle.height > self.height {
            return None;
        }
        for y in 0..=self.height - needle.height {
            for x in 0..=self.width - needle.width {
                if (0..needle.height).all(|r| span(self, x, y + r, needle.width) == span(needle, 0, r, needle.width)) {
                    return Some((x, y));
                }
            }
        }
        None
    }

    /// `text` in [`crate::INK`] at [`crate::TEXT_SCALE`] on a [`crate::BACKGROUND`] canvas just
    /// large enough: a label as every layout of this crate draws it.
    pub fn label(text: &str) -> Canvas {
        let (w, h) = (text_width(text, crate::TEXT_SCALE), text_height(text, crate::TEXT_SCALE));
        let mut canvas = Canvas::new(w, h, crate::BACKGROUND);
        canvas.text(0, 0, text, crate::TEXT_SCALE, crate::INK);
        canvas
    }

    /// The one place pixels are written: the rectangle clipped to the canvas. Wide integers, so
    /// that no position or size overflows on the way.
    fn fill(&mut self, x: i128, y: i128, w: i128, h: i128, colour: [u8; 3]) {
        let xs = clip(x, w, self.width);
        for row in clip(y, h, self.height) {
            let start = 3 * (row * self.width);
            for px in self.rgb[start + 3 * xs.start..start + 3 * xs.end].chunks_exact_mut(3) {
                px.copy_from_slice(&colour);
            }
        }
    }
}

/// The part of `start .. start + len` inside `0 .. limit`.
fn clip(start: i128, len: i128, limit: usize) -> std::ops::Range<usize> {
    let limit = limit as i128;
    let lo = start.clamp(0, limit);
    let hi = start.saturating_add(len.max(0)).clamp(lo, limit);
    lo as usize..hi as usize
}

/// For each of `to` new pixels along an axis of `from` old ones: the old pixels it overlaps and
/// the share of the new pixel each covers (the shares sum to 1).
fn box_weights(from: usize, to: usize) -> Vec<Vec<(usize, f64)>> {
    let ratio = from as f64 / to as f64;
    (0..to)
        .map(|i| {
            let (lo, hi) = (i as f64 * ratio, (i + 1) as f64 * ratio);
            let first = lo.floor() as usize;
            let last = (hi.ceil() as usize).min(from);
            (first..last)
                .map(|s| (s, ((s + 1) as f64).min(hi) - (s as f64).max(lo)))
                .filter(|(_, w)| *w > 0.0)
                .map(|(s, w)| (s, w / ratio))
                .collect()
        })
        .collect()
}

/// The `w` pixels of row `y` of `c` from column `x`, as bytes.
fn span(c: &Canvas, x: usize, y: usize, w: usize) -> &[u8] {
    &c.rgb[3 * (y * c.width + x)..3 * (y * c.width + x + w)]
}
