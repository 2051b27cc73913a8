//! Fuzzes the asset reader, on the file as it is and with its header fixed up (`fuzzing::asset`),
//! under the counting allocator: a panic, or more memory than `fuzzing::check_memory` allows, is a
//! crash that libFuzzer reports and saves.
#![no_main]

fuzzing::fuzz_target_for!(fuzzing::asset);
