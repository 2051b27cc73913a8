//! WGSL port of the MERL nearest-cell lookup: `merl::half_diff`, `merl::Dims::nearest_cell` and
//! `merl::MerlTable::cell_value`, line for line, in f32. Only functions and the table's bindings:
//! the batch evaluator of the `gpu` crate appends `merl_lookup_batch.wgsl` (its entry point) to
//! check it against the CPU, and the previewer appends its own shader to the same text, so what
//! the tests establish holds for what is drawn.
//!
//! Conventions are those of the `merl` crate: radians, `z` is the surface normal, `wi` and `wo`
//! point away from the surface. Group 0 is the table, in every shader that includes this file.

const PI: f32 = 3.14159265358979;
const HALF_PI: f32 = 1.5707963267948966;

struct MerlDimsUniform {
    n_theta_h: u32,
    n_theta_d: u32,
    n_phi_d: u32,
    // `merl::Dims::phi_d_range` (pi when reciprocity folds phi_d, 2 pi for 360 cells), passed in
    // rather than re-derived so that the rule lives in one place.
    phi_d_range: f32,
}

struct MerlHalfDiff {
    theta_h: f32,
    phi_h: f32,
    theta_d: f32,
    phi_d: f32,
}

@group(0) @binding(0) var<uniform> merl_dims: MerlDimsUniform;
// Channel-major like the file (all red, then all green, then all blue) and already multiplied by
// `merl::SCALE`, so in 1/sr. A cell without data is negative in every channel.
@group(0) @binding(1) var<storage, read> merl_table: array<f32>;

// GLSL.std.450 leaves atan2(0, 0) undefined, and it occurs at the poles: in the mirror
// configuration h is the normal, and for wi = wo the difference vector is h. Rust's atan2 gives 0
// there; any azimuth is right at a pole, so agreeing with the CPU is all that matters.
// No Rust twin: Rust's `f64::atan2` already gives 0 at (0, 0).
fn merl_atan2(y: f32, x: f32) -> f32 {
    if (x == 0.0 && y == 0.0) {
        return 0.0;
    }
    return atan2(y, x);
}

// atan2 rather than acos: acos loses all precision near the pole, where MERL's square-root spacing
// of theta_h puts its finest cells (cell 1 starts at 1.9e-4 rad).
// `merl::coords::theta_of`.
fn merl_theta_of(v: vec3<f32>) -> f32 {
    return merl_atan2(length(v.xy), v.z);
}

// `merl::coords::rotate_z`: `v` turned by `angle` about `z`.
fn merl_rotate_z(v: vec3<f32>, angle: f32) -> vec3<f32> {
    let s = sin(angle);
    let c = cos(angle);
    return vec3<f32>(v.x * c - v.y * s, v.x * s + v.y * c, v.z);
}

// `merl::coords::rotate_y`: `v` turned by `angle` about `y`.
fn merl_rotate_y(v: vec3<f32>, angle: f32) -> vec3<f32> {
    let s = sin(angle);
    let c = cos(angle);
    return vec3<f32>(v.x * c + v.z * s, v.y, -v.x * s + v.z * c);
}

// `wi` and `wo` unit vectors with `wi + wo != 0`, as for `merl::half_diff`. `phi_d` is in
// (-pi, pi], as atan2 returns it.
fn merl_half_diff(wi: vec3<f32>, wo: vec3<f32>) -> MerlHalfDiff {
    let h = normalize(wi + wo);
    let theta_h = merl_theta_of(h);
    let phi_h = merl_atan2(h.y, h.x);
    let d = merl_rotate_y(merl_rotate_z(wi, -phi_h), -theta_h);
    return MerlHalfDiff(theta_h, phi_h, merl_theta_of(d), merl_atan2(d.y, d.x));
}

// Continuous grid coordinates (theta_h, theta_d, phi_d): sample i sits at coordinate i, the lower
// edge of cell i.
// `merl::Dims::grid_coords`.
fn merl_grid_coords(dims: MerlDimsUniform, hd: MerlHalfDiff) -> vec3<f32> {
    let x_h = sqrt(max(hd.theta_h, 0.0) / HALF_PI) * f32(dims.n_theta_h);
    let x_d = hd.theta_d / HALF_PI * f32(dims.n_theta_d);
    var phi_d = hd.phi_d;
    if (phi_d < 0.0) {
        // With 180 cells this is reciprocity (swapping wi and wo adds pi to phi_d); with 360 it
        // is the same angle.
        phi_d += dims.phi_d_range;
    }
    let x_p = phi_d / dims.phi_d_range * f32(dims.n_phi_d);
    return vec3<f32>(x_h, x_d, x_p);
}

// Truncate and clamp, as the reference MERL reader does (`merl::Dims::nearest_cell`).
fn merl_axis_index(x: f32, n: u32) -> u32 {
    return u32(clamp(floor(x), 0.0, f32(n - 1u)));
}

// Flat index of the cell within a channel, in the MERL order (`merl::Dims::index`).
fn merl_nearest_cell(dims: MerlDimsUniform, hd: MerlHalfDiff) -> u32 {
    let x = merl_grid_coords(dims, hd);
    let i_h = merl_axis_index(x.x, dims.n_theta_h);
    let i_d = merl_axis_index(x.y, dims.n_theta_d);
    let i_p = merl_axis_index(x.z, dims.n_phi_d);
    return (i_h * dims.n_theta_d + i_d) * dims.n_phi_d + i_p;
}

// BRDF of a cell in 1/sr; negative in every channel where the table holds no data.
// `merl::MerlTable::raw_cell`, uploaded already times `merl::SCALE`.
fn merl_cell_value(cell: u32) -> vec3<f32> {
    let cells = merl_dims.n_theta_h * merl_dims.n_theta_d * merl_dims.n_phi_d;
    return vec3<f32>(merl_table[cell], merl_table[cells + cell], merl_table[2u * cells + cell]);
}

// Whether a cell holds data: the test of `merl::MerlTable::cell_value`.
fn merl_has_data(rgb: vec3<f32>) -> bool {
    return all(rgb >= vec3<f32>(0.0));
}

// The nearest lookup of `merl::MerlTable::lookup`, with no data as a negative value.
fn merl_lookup_nearest(wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    return merl_cell_value(merl_nearest_cell(merl_dims, merl_half_diff(wi, wo)));
}
