//! The `gpu` crate's integration tests, one binary: the WGSL MERL lookup against the CPU's
//! (`merl_lookup`), the previewer's renderer against the CPU renderer (`preview`), and its
//! progressive accumulation, present pass and debug views (`present`).

/// The adaptive tests' bandwidths, `render`'s own.
#[path = "../../render/tests/fixtures/bandwidths.rs"]
mod fixtures;
mod merl_lookup;
mod present;
mod preview;
mod support;
