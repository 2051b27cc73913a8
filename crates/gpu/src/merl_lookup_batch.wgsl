//! The batch entry point of the MERL lookup, compiled after `merl_lookup.wgsl` (whose functions
//! and group 0 it uses) so that tests can look up any direction pairs and compare with the CPU.
//! Group 1 is the batch.

// The host rounds batches up to whole workgroups with this size (`WORKGROUP_SIZE` in Rust; a test
// there checks the two agree).
const MERL_WORKGROUP_SIZE: u32 = 64u;

// vec4 so that the host layout is two plain [f32; 4] with no padding rules to get wrong; w unused.
struct MerlDirPair {
    wi: vec4<f32>,
    wo: vec4<f32>,
}

// 16 bytes: vec3 then u32 in its fourth slot, the layout of `gpu::MerlSample`.
struct MerlSample {
    rgb: vec3<f32>,
    cell: u32,
}

@group(1) @binding(0) var<storage, read> merl_pairs: array<MerlDirPair>;
// Bound to exactly the pairs of this dispatch, so its length is the batch size.
@group(1) @binding(1) var<storage, read_write> merl_samples: array<MerlSample>;

// One pair per invocation: `merl::MerlTable::lookup_half_diff` with `Interp::Nearest`, and the
// cell's index.
@compute @workgroup_size(MERL_WORKGROUP_SIZE)
fn merl_lookup_batch(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= arrayLength(&merl_samples)) {
        return;
    }
    let pair = merl_pairs[i];
    let cell = merl_nearest_cell(merl_dims, merl_half_diff(pair.wi.xyz, pair.wo.xyz));
    merl_samples[i] = MerlSample(merl_cell_value(cell), cell);
}
