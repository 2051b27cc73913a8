//! The GPU side of the toolchain: a headless wgpu device ([`Gpu`]) and the WGSL port of the MERL
//! nearest lookup ([`MERL_LOOKUP_WGSL`]) that the previewer shades with. [`MerlLookup`] runs that
//! port on batches of direction pairs and reads the results back, so that tests can hold the
//! shader to the CPU reference in the `merl` crate, cell for cell.
//!
//! Architecture Invariant: the WGSL is the only copy of the lookup on the GPU. The previewer
//! includes [`MERL_LOOKUP_WGSL`] rather than a rewrite, so the agreement the tests establish is
//! the agreement of what is drawn.

mod context;
mod error;
mod merl_lookup;

pub use context::Gpu;
pub use error::GpuError;
pub use merl_lookup::{GpuSample, MERL_LOOKUP_WGSL, MerlDimsUniform, MerlLookup, gpu_table_values};
