//! Fuzzes the OpenEXR environment reader (`fuzzing::envmap_exr`) under the counting allocator: a
//! panic, or more memory than `fuzzing::check_memory` allows, is a crash that libFuzzer reports
//! and saves.
#![no_main]

fuzzing::fuzz_target_for!(fuzzing::envmap_exr);
