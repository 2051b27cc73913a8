//! Fuzzes the Wavefront OBJ reader of `brdf-preview --mesh` (`fuzzing::obj`:
//! `render::Mesh::from_obj` on UTF-8 text, and the mesh it accepts checked for consistency) under
//! the counting allocator: a panic, or more memory than `fuzzing::check_memory` allows, is a crash
//! that libFuzzer reports and saves.
#![no_main]

fuzzing::fuzz_target_for!(fuzzing::obj);
