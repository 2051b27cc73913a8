//! The GPU side of the toolchain: a wgpu device ([`Gpu`], headless, or able to present to a
//! window's surface that the caller made: the crate knows no windowing library), the WGSL port of
//! the MERL nearest lookup ([`wgsl::MERL_LOOKUP`]) and the previewer's renderer
//! ([`preview::Renderer`]), which shades with it, accumulates frames progressively and is drawn,
//! tone mapped, into a texture or a window by [`preview::Presenter`]. [`MerlLookup`] runs that
//! port on batches of direction pairs and reads the results back, so that tests can hold the
//! shader to the CPU reference in the `merl` crate, cell for cell; the renderer is held the same
//! way to the CPU renderer of the `render` crate, and the present pass to `envmap::tonemap_rgb8`.
//!
//! Architecture Invariant: the WGSL file is the only WGSL copy of the lookup. The previewer
//! includes [`wgsl::MERL_LOOKUP`] rather than a rewrite, so the agreement the tests establish is
//! the agreement of what is drawn. (The three.js port holds a GLSL port of it, held to the
//! previewer by the browser tests.)

mod context;
mod device;
mod error;
#[cfg(test)]
mod layout;
mod merl_lookup;
pub mod preview;
pub mod surface;
pub mod wgsl;

pub use context::Gpu;
pub use error::GpuError;
pub use merl_lookup::{MerlDimsUniform, MerlLookup, MerlSample, gpu_table_values};
