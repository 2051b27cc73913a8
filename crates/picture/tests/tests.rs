//! All integration tests of the `picture` crate, one module per topic, in one binary.

mod canvas;
mod colormap;
mod demo;
mod font;
mod layout;
mod legend;
mod number;

use picture::Canvas;

/// The bounding box `(x0, y0, x1, y1)` (exclusive ends) of the pixels of `colour`, `None` when
/// there are none.
pub fn bounding_box(canvas: &Canvas, colour: [u8; 3]) -> Option<(usize, usize, usize, usize)> {
    let mut bbox: Option<(usize, usize, usize, usize)> = None;
    for y in 0..canvas.height {
        for x in 0..canvas.width {
            if canvas.pixel(x, y) == Some(colour) {
                let b = bbox.get_or_insert((x, y, x + 1, y + 1));
                *b = (b.0.min(x), b.1.min(y), b.2.max(x + 1), b.3.max(y + 1));
            }
        }
    }
    bbox
}

/// The number of pixels of `colour`.
pub fn count(canvas: &Canvas, colour: [u8; 3]) -> usize {
    canvas.rgb.chunks_exact(3).filter(|c| *c == colour).count()
}
