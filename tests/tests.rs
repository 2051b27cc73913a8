//! End-to-end tests: they build the tools once, run them on fixtures and generated inputs, and
//! print the command, its stdout and stderr when a check fails.

mod support;

mod architecture;
mod asset_info;
mod bake_folders;
mod brdf_bake;
mod brdf_bandwidth;
mod brdf_fit;
mod brdf_wavelet;
mod envmap_bandwidth;
mod envmap_prefilter;
mod importance;
mod invalid_inputs;
mod json_output;
mod merl_info;
mod preview;
mod ranges_and_messages;
mod three;
