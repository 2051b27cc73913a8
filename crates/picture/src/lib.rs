//! The toolchain's 8-bit pictures, so that every PNG a tool writes says what it shows: an RGB
//! [`Canvas`] with a 5 x 7 bitmap [`font`] (no font crate), perceptually uniform [`colormap`]s
//! with linear and logarithmic scales and outlier-proof ranges, colour-bar [`legend`]s with ticks,
//! units, clipping arrows and special-colour swatches, and [`layout`]s: labelled grids of panels
//! and heat maps with axes. Pure functions on memory, no IO and no domain knowledge; callers
//! write the bytes with `envmap::write_png_rgb8`.

pub mod canvas;
pub mod colormap;
pub mod font;
pub mod layout;
pub mod legend;
mod number;

pub use canvas::Canvas;
pub use number::format_number;

/// The background of legends, grids and axes: dark, so that the dark end of inferno and viridis
/// still stands out against it.
pub const BACKGROUND: [u8; 3] = [24, 24, 24];
/// Text, ticks and axis lines.
pub const INK: [u8; 3] = [235, 235, 235];
/// Screen pixels per font pixel for every label this crate draws (14-pixel-high capitals).
pub const TEXT_SCALE: usize = 2;
