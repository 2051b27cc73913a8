//! Lat-long (equirectangular) HDR environment maps for the baking tools: loading OpenEXR and
//! Radiance HDR files into validated linear RGB radiance, the parameterization and its texel solid
//! angles, bilinear and mip-mapped (filtered importance sampling) lookups, and the EXR and PNG
//! writers every tool uses for its outputs.
//!
//! # Orientation
//!
//! One convention, kept identical in every tool that reads a map (the `bandwidth` crate assumes
//! exactly this):
//!
//! - `+z` is up; `theta` is measured from `+z`, `phi` from `+x` towards `+y`.
//! - Texel `(x, y)` of a `W x H` map has its centre at `u = (x + 0.5) / W`, `v = (y + 0.5) / H`.
//! - `phi = 2 pi u`: `u = 0` (the left edge) is `phi = 0`, the `+x` direction, and increasing `x`
//!   goes towards `+y`. `theta = pi v`: row 0 is at the `+z` pole, the last row at `-z`.
//! - [`direction`]`(u, v) = (sin theta cos phi, sin theta sin phi, cos theta)`; [`uv`] is its
//!   inverse.
//!
//! The file's own `envmap` attribute (OpenEXR) is not consulted: the top row of the image is
//! always up, as in every lat-long map in circulation.
//!
//! # What is accepted
//!
//! - OpenEXR (via `exr`): scanline or tiled, any compression `exr` reads, the full-resolution
//!   level of mip- and rip-mapped files, the first flat part, its data window. Channels `R`, `G`,
//!   `B` (extra channels such as `A` ignored) or else `Y` (grey); `f16` or `f32` samples.
//! - Radiance HDR (via `image`): `#?` signature (any program name), `FORMAT=32-bit_rle_rgbe`,
//!   `-Y H +X W` orientation, new and old run-length schemes. `EXPOSURE` is not divided out.
//! - The format is recognised by its first bytes, never the extension.
//! - A map must be non-empty, within [`Limits`] (16384 x 8192 and a memory budget of 4 GiB for
//!   the job by default: the job's need, its bytes per texel times the texels, is estimated from
//!   the header, refused over the budget and reserved once, fallibly, before decoding; an OpenEXR
//!   payload is also checked against the file's size first), exactly 2:1 (`width == 2 * height`; a 512 x 768 file is "not a lat-long
//!   map"), and every value finite and non-negative. Negative radiance is rejected, not clamped:
//!   it is a damaged or wrongly converted file, and silently clamping would change its mean. The
//!   error names the first bad texel (x, y, channel).
//! - [`read_image`] reads the same files without the 2:1 requirement; `*_from_memory` read bytes.
//!
//! Errors are split by who is at fault ([`Error`]): invalid input (a short read included),
//! unsupported feature, limit exceeded, IO. No input makes the readers panic. (The `exr` crate's
//! B44 decompressor can panic on damaged data when overflow checks are on; B44 files are decoded
//! on the calling thread, where such a panic is caught and reported as damaged data.)
//!
//! # Example
//!
//! ```no_run
//! use std::path::Path;
//!
//! let map = envmap::load(Path::new("studio.exr"))?;
//! let chain = envmap::MipChain::new(&map);
//! // One of 64 samples drawn uniformly over the sphere, looking straight up.
//! let wi = glam::DVec3::Z;
//! let (_, v) = envmap::uv(wi);
//! let pdf_uv = envmap::geometry::uv_jacobian(v) / (4.0 * std::f64::consts::PI);
//! let radiance = chain.lookup(wi, chain.lod(64, pdf_uv));
//! envmap::write_exr(Path::new("up.exr"), 1, 1, &[("R", &[radiance[0]]), ("G", &[radiance[1]]), ("B", &[radiance[2]])],
//!     envmap::SampleType::F32)?;
//! # Ok::<(), envmap::Error>(())
//! ```

mod error;
pub mod geometry;
mod map;
mod mip;
mod read;
pub mod synthetic;
mod write;

pub use error::Error;
pub use geometry::{direction, texel_solid_angle, uv};
pub use map::EnvMap;
pub use mip::MipChain;
pub use read::{
    DEFAULT_MAX_MEMORY, HdrImage, Limits, READ_BYTES_PER_TEXEL, format_bytes, load, load_from_memory, load_with_limits,
    read_image, read_image_from_memory,
};
pub use write::{
    SampleType, ToneMap, ToneMapping, encode_exr, encode_png_rgb8, tonemap, tonemap_rgb8, write_exr, write_png_rgb8,
};
