//! MERL BRDF tables (Matusik et al. 2003): the `.binary` format, the Rusinkiewicz
//! half/difference coordinates it is indexed by, lookups that match the reference MERL reader,
//! generators of tables from analytic BRDFs with known answers, and the directional albedo by a
//! quadrature that converges on peaked materials.
//!
//! Conventions used throughout: radians; `z` is the surface normal; `wi` and `wo` point away
//! from the surface; BRDF values are in 1/sr (raw values times [`SCALE`]). A cell with any
//! negative raw value holds no data (MERL marks the configurations below the horizon so):
//! lookups return `None` there and no sum ever includes it.

pub mod albedo;
pub mod analytic;
pub mod coords;
mod error;
mod io;
pub mod summary;
pub mod table;

pub use coords::{HalfDiff, half_diff, spherical_dir};
pub use error::Error;
pub use io::{MAX_FILE_BYTES, read_bytes, read_file};
pub use table::{Cell, Dims, Interp, MerlTable, NO_DATA_RAW, SCALE};
