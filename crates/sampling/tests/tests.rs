//! All integration tests of the `sampling` crate, one binary with a module per topic.

mod chi2;
mod distribution_1d;
mod distribution_2d;
mod errors;
mod lat_long;
mod point_sets;
