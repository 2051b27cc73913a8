//! Writes the DFG table at its default size to stdout as `prefilter::dfg` embeds it:
//! `DFG_SIZE^2` pairs of little-endian `f32`, `A` then `B`, row-major.
//! `cargo run --release -p prefilter --example dfg-table > crates/prefilter/src/dfg-128.bin`

use std::io::Write;

use prefilter::dfg::{DFG_SIZE, compute_table};

fn main() {
    let bytes: Vec<u8> =
        compute_table(DFG_SIZE).iter().flat_map(|[a, b]| a.to_le_bytes().into_iter().chain(b.to_le_bytes())).collect();
    std::io::stdout().write_all(&bytes).expect("writing the table to stdout");
}
