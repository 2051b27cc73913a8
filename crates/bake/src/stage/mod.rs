//! One module per stage. Each takes its inputs in memory (a stage that reads a file names it in
//! its errors), computes everything, and returns a [`crate::Staged`] without touching the disk.

pub mod atlas;
pub mod env_bandwidth;
pub mod importance;
pub mod layers;
pub mod pca;
pub mod prefilter;
pub mod wavelet;
