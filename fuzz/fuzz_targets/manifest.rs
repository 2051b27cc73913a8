//! Fuzzes the bake manifest reader (`fuzzing::manifest`: `asset::BakeManifest::from_bytes`, then
//! what the bake and the previewer do with a manifest it accepts) under the counting allocator: a
//! panic, or more memory than `fuzzing::check_memory` allows, is a crash that libFuzzer reports
//! and saves.
#![no_main]

fuzzing::fuzz_target_for!(fuzzing::manifest);
