//! What the previewer's shading module binds and every part of it shares: the constants (the
//! modes, the rasterizer's), group 1 (what the scene, material and lighting upload once) and
//! group 2 (the render: `ShadeUniform`, `FrameUniform`, the G-buffer, the accumulation and the
//! backdrop behind it).


// The host rounds the image up to whole workgroups of this size (`SHADE_WORKGROUP` in Rust; a
// test there checks the two agree).
const SHADE_WORKGROUP: u32 = 8u;

const MODE_REFERENCE: u32 = 0u;
const MODE_FIS: u32 = 1u;
const MODE_PREFILTERED: u32 = 2u;
// Not estimators: write the G-buffer's interpolated (position, triangle) or (normal, covered) of
// each pixel in place of the sum, so that tests can hold visibility to `render::raster` alone.
const MODE_GBUFFER_POSITION: u32 = 3u;
const MODE_GBUFFER_NORMAL: u32 = 4u;
// Debug views, accumulated like the estimators (so that their average is the value) and with the
// environment behind the mesh as in every mode: per covered pixel the interpolated normal; or
// (index, 1, 0) with the prefiltered layer the view-layer table picks (-1 without a table) or
// the sample slice, and (0, 0, 0) where the pixel has no shading frame (black in the picture).
const MODE_DEBUG_NORMAL: u32 = 5u;
const MODE_DEBUG_LAYER: u32 = 6u;
const MODE_DEBUG_SLICE: u32 = 7u;

// `render::raster::GUARD_BAND`: triangles reaching beyond it are clipped on the CPU. (A test in
// Rust checks both constants against `render::raster`.)
const GUARD_BAND: f32 = 4.0;
// 2^`render::raster::SUBPIXEL_BITS`: viewport coordinates snap to 1/256 pixel.
const SUBPIXELS: f32 = 256.0;

// Group 1: the samples, every environment map, the mesh, the sampling tables and the view-layer
// table, in as few buffers as they can share (each binding counts against the adapter's storage
// buffers per stage).

// `render::SampleSet::texels`: (wi_local.xyz, pdf), slice-major, then vector, then sample.
@group(1) @binding(0) var<storage, read> samples: array<vec4<f32>>;
// Every map's texels, RGB interleaved and row-major like `envmap::EnvMap::rgb`. Storage rather
// than textures: float32 textures need not be filterable, and doing the bilinear weights by hand
// makes them the CPU's arithmetic.
@group(1) @binding(1) var<storage, read> env_texels: array<f32>;
// The mesh, as `preview_raster.wgsl` reads it: twelve values per vertex, three indices per
// triangle; after the indices, from `shade.map_records` on, one lat-long map per record of four
// words ([`env_map`]). Per vertex: the clip-space position with the current camera and the snapped viewport
// x and y in 1/256 pixels (integers, exact in f32 within the guard band; 0 outside the clip
// volume), both as `render::raster` computes them on the CPU, then the position and the normal.
// The CPU's rather than the GPU's own: a GPU may fuse multiply-adds and divide to 2.5 ULP
// (Vulkan allows both), which moves a vertex whose coordinate lies near a rounding tie by a
// sub-pixel step, and a small triangle's interpolation with it.
@group(1) @binding(2) var<storage, read> mesh_vertices: array<f32>;
@group(1) @binding(3) var<storage, read> mesh_indices_and_maps: array<u32>;
// The CDF tables the estimators sample, f32 as the CPU samples them (`render::SampleSet::tables`,
// `render::Lighting::environment` and the peaks' `sampling`), then the view-layer table
// (`render::Material::view_layers`: each view row's Phong layer coordinate, `shade.n_view_rows` of
// them, then the `shade.n_layers` layers' exponents, `render::Lighting::exponents`, and the
// exponent of the one past the sharpest, `render::past_exponent`), where `ShadeUniform` says each
// starts.
@group(1) @binding(4) var<storage, read> sampling_tables: array<f32>;

// Group 2: the render.

struct ShadeUniform {
    // The camera: the eye, and the pixel ray's basis as `render::Camera::ray` builds it,
    // `forward`, `right tan(fov_y / 2) aspect` and `up tan(fov_y / 2)`.
    eye: vec4<f32>,
    ray_forward: vec4<f32>,
    ray_right: vec4<f32>,
    ray_up: vec4<f32>,
    width: u32,
    height: u32,
    seed: u32,
    mode: u32,
    spp: u32,
    n_slices: u32,
    n_vectors: u32,
    n_samples: u32,
    // Mip levels (of `mips_first`'s chain).
    n_levels: u32,
    n_view_rows: u32,
    // Prefiltered layers; the prefiltered estimator reads the layers `layer_shift` layers sharper
    // than the view's (an adaptive frame's shaded blocks: `render::adaptive::Settings`).
    n_layers: u32,
    layer_shift: u32,
    // Maps among the records (map 0 is level 0 of the environment, whole): the first level of the
    // mip chain the fis estimator reads and the first Phong layer (`render::Lighting::smooth_mips`
    // and `smooth_layers`), and the peaks' level 0 (`NO_MAP` where the environment has none); then
    // where the records start in `mesh_indices_and_maps`.
    mips_first: u32,
    layers_first: u32,
    peak_map: u32,
    map_records: u32,
    // In `sampling_tables`: the BRDF tables' rows (of half vectors) and sectors (of phi_h); where the row
    // edges `t = 1 - cos theta_h` (R + 1), the slices' marginal CDFs (R + 1 each) and their
    // conditional CDFs (R rows of C + 1 each) start.
    brdf_rows: u32,
    brdf_sectors: u32,
    t_edges: u32,
    brdf_marginal: u32,
    brdf_conditional: u32,
    // Level 0's distribution and the peaks': marginal (H + 1) and conditional (H rows of W + 1)
    // CDFs over map 0's texels.
    env_marginal: u32,
    env_conditional: u32,
    peak_marginal: u32,
    peak_conditional: u32,
    // The view-layer table, in `sampling_tables` after the CDF tables.
    view_layers: u32,
    // The length of the list a pass over items reads (`predict_blocks`, `shade_blocks`): their
    // items arrive in `accumulation`.
    items: u32,
    // The samples the filtered estimators' footprints are sized for: `spp` times the frames the
    // picture averages; in `shade_blocks` the frames alone, times each block's samples.
    filter_samples: u32,
    // `render::diffuse_split` (w unused): the BRDF's diffuse part `f_d`, which the filtered
    // estimators read from the cosine layer (the first) at the normal.
    diffuse: vec4<f32>,
}

// `ShadeUniform::peak_map` where the environment has no peaks.
const NO_MAP: u32 = 0xffffffffu;

// Map `m`'s record: (width, height, offset of its first value in `env_texels`, unused). Maps
// 0 .. n_levels are the mip chain (level 0 first), then one per prefiltered layer.
// No Rust twin: the CPU holds each map as an `envmap::EnvMap`.
fn env_map(m: u32) -> vec4<u32> {
    let at = shade.map_records + 4u * m;
    return vec4<u32>(
        mesh_indices_and_maps[at],
        mesh_indices_and_maps[at + 1u],
        mesh_indices_and_maps[at + 2u],
        mesh_indices_and_maps[at + 3u],
    );
}

// Its own uniform, at a dynamic offset: one command buffer holds many frames.
struct FrameUniform {
    index: u32,
}

@group(2) @binding(0) var<uniform> shade: ShadeUniform;
@group(2) @binding(1) var<uniform> frame: FrameUniform;
// The index plus one of the triangle that covers the pixel centre, 0 where none does.
@group(2) @binding(2) var gbuffer_triangle: texture_2d<u32>;
// Per pixel: the sum of the frames' radiance, and in w whether a triangle covers it; then, one
// binding for both, per pixel the backdrop ([`backdrop_index`]).
@group(2) @binding(3) var<storage, read_write> accumulation: array<vec4<f32>>;

// Where pixel `p`'s backdrop sits in `accumulation`, after the image's sums: the environment seen
// along its camera ray, drawn where no triangle covers the pixel (`shade_backdrop`, once per
// camera with the G-buffer).
// No Rust twin: the CPU looks the environment up where it draws the pixel (`render::shade`).
fn backdrop_index(p: u32) -> u32 {
    return shade.width * shade.height + p;
}

// The item of invocation `local` of workgroup `group` in a list of items (`shade_blocks`,
// `predict_blocks`) dispatched as a power of two of workgroups (`Renderer::run_items`): the
// workgroups take their runs of 64 items in bit-reversed order. A driver that hands each thread
// a contiguous range of workgroups (lavapipe does) then gives every thread an even share of any
// contiguous run of items: an adaptive frame's shaded blocks come level by level, and a coarse
// level's get many times the samples of a fine level's.
// No Rust twin: the order of a dispatch's items (`gpu::preview::item_groups` sizes it).
fn item_index(group: vec3<u32>, local: u32, groups: vec3<u32>) -> u32 {
    let g = group.y * groups.x + group.x;
    let bits = countTrailingZeros(groups.x * groups.y);
    var run = 0u;
    if (bits > 0u) {
        run = reverseBits(g) >> (32u - bits);
    }
    return run * 64u + local;
}
