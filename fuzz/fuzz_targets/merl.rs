//! Fuzzes the MERL table parser (`fuzzing::merl`) under the counting allocator: a panic, or
//! more memory than `fuzzing::check_memory` allows, is a crash that libFuzzer reports and saves.
#![no_main]

fuzzing::fuzz_target_for!(fuzzing::merl);
