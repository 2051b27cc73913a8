//! Importance sampling by numerical inversion of tabulated CDFs: piecewise-constant
//! distributions over the unit interval ([`Distribution1D`]) and the unit square
//! ([`Distribution2D`]) built from non-negative function values, after pbrt-v4's
//! `PiecewiseConstant1D`/`PiecewiseConstant2D`, and the scrambled Sobol' point sets
//! ([`OwenSobol2D`]) that feed them. `merl-importance` tabulates f·cos over a parameterization of
//! incident directions with these; a real-time renderer reads the same CDF tables from a texture,
//! so the tables are flat `f64` arrays meant to be exported as they are.
//!
//! Conventions, the same for every type here:
//! - **Domain** `[0, 1)` in 1D and `[0, 1)^2` in 2D. Bin `i` of `n` covers `[i/n, (i+1)/n)`; a
//!   point exactly on the edge between two bins belongs to the upper one, and `x = 1` (outside
//!   the domain, but where rounding elsewhere may land) is read as the last bin by `pdf` and
//!   `invert`. Anything further outside has pdf 0.
//! - **pdf** is a density with respect to the Lebesgue measure of that domain (length, area):
//!   `pdf(x) = func[i] / integral` with `integral` the mean of `func`, which is its integral over
//!   the domain. A change of variables to solid angle is the caller's.
//! - **sample / pdf / invert** come together (pbrt's habit): `pdf(sample(u).x)` is exactly the
//!   pdf `sample` reported, and `invert(sample(u).x)` is `u` up to rounding. `u` outside `[0, 1)`
//!   is clamped into it (NaN reads as 0), so every sample lies in the domain.
//! - **Tables**: `func` has `n` values, `cdf` has `n + 1` with `cdf[0] = 0` and `cdf[n] = 1`
//!   exactly, non-decreasing. A bin whose value is 0 has zero CDF width and is never sampled.
//! - **2D layout** is row-major, `v` rows of `u` values: `func[iv * nu + iu]`, and points are
//!   `p = [u, v]`. As in pbrt, `u[1]` picks the row through the marginal `p(v)` and `u[0]` the
//!   column through that row's conditional `p(u | v)`.
//! - **An all-zero function** (or one so small that its mean underflows to 0) gives the uniform
//!   distribution, as pbrt does: `cdf[i] = i / n` and pdf 1 everywhere (the true density of the samples, so an estimator `f / pdf` returns 0 rather
//!   than 0/0). `integral()` still reports 0 so a caller can tell. A renderer that evaluates
//!   `func / integral` itself must treat `integral == 0` as pdf 1. In 2D a zero row of a function
//!   that is not all zero gets a uniform conditional and marginal probability 0, so it is never
//!   sampled and its pdf is 0.
//! - **Stored tables**: [`Distribution1D::from_cdf`] and [`Distribution2D::from_cdfs`] sample a
//!   CDF table as it was stored (an asset's `f32` tables, or [`Distribution2D::rounded_to_f32`]
//!   for a GPU's), the bin values following from the table, so that two renderers reading the same
//!   tables choose the same bins for the same `u`.
//!
//! [`LatLong`] puts a 2D distribution on the sphere through the lat-long parameterization (an
//! environment map's importance sampling), with densities per unit solid angle.

pub mod chi2;
mod distribution1d;
mod distribution2d;
mod error;
mod latlong;
mod sobol;

pub use distribution1d::{Distribution1D, Sample1D};
pub use distribution2d::{Distribution2D, Sample2D};
pub use error::Error;
pub use latlong::{LatLong, LatLongSample};
pub use sobol::{OwenSobol2D, owen_sobol_vectors};

/// The largest `f64` below 1: where a `u` in `[0, 1)` is clamped to, and the largest coordinate a
/// sample can have.
pub const ONE_MINUS_EPSILON: f64 = 1.0 - f64::EPSILON / 2.0;
