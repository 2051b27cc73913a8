//! The render crate's integration tests, one module per topic.

#[path = "fixtures/bandwidths.rs"]
mod fixtures;
mod support;

mod adaptive;
mod converged;
mod determinism;
mod estimators;
mod known_answer;
mod mesh;
mod metrics;
mod obj;
mod raster;
mod sample_choice;
mod validation;
