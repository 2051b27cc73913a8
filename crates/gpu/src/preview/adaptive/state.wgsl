// An adaptive frame's state on the GPU after its prediction (`predict.wgsl`), which the passes of
// `plan.wgsl`, `samples.wgsl` and `frame.wgsl` share: their uniform, the buffers, the control
// words and the helpers that read them (`render::adaptive`'s indexing of levels and blocks).
// `Renderer::render_adaptive` (`mod.rs` beside this file) records the passes (and, for the other
// allocations, allocates the samples on the host between two submissions); `state.rs` makes the
// buffers and pipelines. The files are composed as `gpu::wgsl` lists them.
//
// Group 3, bindings 2 and up (bindings 0 and 1 are the prediction's): one uniform slot per pass,
// then the frame's state, one buffer per kind so that each stays within the adapter's largest
// binding (128 MiB on lavapipe: a 2048 x 2048 render's records take 64 MiB each), and the control
// words (counts, the allocation, the list's prefix sums).

struct AdaptivePass {
    // The pass's level (`adaptive_reduce`, `adaptive_upsample`) and the pyramid's top.
    level: u32,
    top: u32,
    // The render's size and the output's, `ss` render pixels per output pixel along each axis.
    width: u32,
    height: u32,
    out_width: u32,
    out_height: u32,
    ss: u32,
    // Items of the pass (pixels, blocks or shaded blocks).
    count: u32,
    // Word offsets in `tables`.
    level_table: u32,
    sharpness: u32,
    // Rows of the lobe weight's sharpness (0: no lobe weight).
    n_rows: u32,
    // 1: the bandwidth section holds an oracle's bandwidths, read instead of the prediction's.
    oracle: u32,
    depth_sigma: f32,
    rescue_below: f32,
    candidates: u32,
    // The frame's samples, and at most this many per block (a power of two, at most 2^16).
    budget: u32,
    max_spp: u32,
    // `shade_blocks`' items at most (the accumulation buffer's entries).
    capacity: u32,
    // 1: `adaptive_allocate` gives the samples (`render::adaptive::area_allocation`) and
    // `adaptive_list` writes `shade_blocks`' items; 0: the host does both from the list.
    allocate: u32,
    _pad: u32,
}

// A render pixel's `render::adaptive::Pixel` as `preview/adaptive/state.rs` writes it, in two
// records: what the levels and the output read, and the lobe the up-sampling weights read.
struct RecordSurface {
    // -1 where no triangle covers the pixel, 0 where one covers it but it is not shadeable.
    depth: f32,
    cos_o: f32,
    // The screen-projected normal.
    screen_normal: vec2<f32>,
}

struct RecordLobe {
    // The mirror direction.
    mirror: vec3<f32>,
    // The index of its prediction; `NONE` where the pixel is not shadeable.
    prediction: u32,
}

// The state, per render pixel or per block of every level (blocks of level k start at the level
// table's offset for k):
// - records, per render pixel (`RecordSurface`, `RecordLobe`);
// - bandwidths, per render pixel: its image bandwidth (cycles per pixel);
// - levels, per block: the min pyramid (i32), the max pyramid of the variance, the action
//   (`ACTION_*`, with the parents' count in bits 8 and up), unused;
// - parents and weights, per block: the parents' block indices in the next level, their weights;
// - values, per block: its value (RGB) once shaded or up-sampled;
// - list, per block: the shaded blocks in the plan's order (`adaptive_list`), as (level, block,
//   max variance, pixel) for the host to allocate, then as (the block's index among every
//   level's blocks, the first of its parts in `shade_blocks`' items, their count, its samples);
// - tables: the level table, 4 words per level and one more (width and height in blocks, the
//   offset of its first block, the offset of its first candidate; the last row's: the
//   candidates' count); the candidates, 1 word per block that holds a shadeable pixel, level by
//   level: its index among every level's blocks (the other blocks have no variance and are never
//   valid: the host writes their min level (-1) and action (skipped) once per geometry, and the
//   passes run over the candidates only); `n_rows` lobe sharpnesses per view row.
@group(3) @binding(2) var<uniform> adapt: AdaptivePass;
@group(3) @binding(3) var<storage, read> records_surface: array<RecordSurface>;
@group(3) @binding(4) var<storage, read> records_lobe: array<RecordLobe>;
@group(3) @binding(5) var<storage, read_write> bandwidths: array<f32>;
@group(3) @binding(6) var<storage, read_write> levels: array<vec4<u32>>;
@group(3) @binding(7) var<storage, read_write> parents: array<vec4<u32>>;
@group(3) @binding(8) var<storage, read_write> weights: array<vec4<f32>>;
@group(3) @binding(9) var<storage, read_write> values: array<vec4<f32>>;
@group(3) @binding(10) var<storage, read_write> list: array<vec4<u32>>;
@group(3) @binding(11) var<storage, read> tables: array<u32>;
@group(3) @binding(12) var<storage, read_write> control: array<atomic<u32>>;

// The control words, zero at the start of a frame (the host clears them all):
// shaded blocks in all, the status (1: the budget is below a sample per shaded block), the
// samples given, `shade_blocks`' items, their workgroups (x, y, 1) and the list's (x, y, 1), the
// samples per part; from CONTROL_COUNTS the shaded blocks per level; from CONTROL_LEVELS per
// level its samples, how many of its blocks get twice that, its first item and its first rank
// in the list (`adaptive_allocate`); from CONTROL_CHUNKS the shaded candidates per chunk of
// CHUNK (`adaptive_plan`), then the shaded candidates before each chunk (`adaptive_offsets`).
const CONTROL_SHADED: u32 = 0u;
const CONTROL_STATUS: u32 = 1u;
const CONTROL_SAMPLES: u32 = 2u;
const CONTROL_PARTS: u32 = 3u;
const CONTROL_ARGS: u32 = 4u;
const CONTROL_PART: u32 = 10u;
const CONTROL_COUNTS: u32 = 16u;
const CONTROL_LEVELS: u32 = 32u;
const CONTROL_CHUNKS: u32 = 96u;
const MAX_LEVELS: u32 = 16u;
const CHUNK: u32 = 256u;
const RUN: u32 = 4u;

const NONE: u32 = 0xffffffffu;
const ACTION_SKIP: u32 = 0u;
const ACTION_SHADE: u32 = 1u;
const ACTION_RESCUED: u32 = 2u;
const ACTION_UPSAMPLE: u32 = 3u;
// `render::adaptive::MIN_WEIGHT`: 2^-100.
const MIN_WEIGHT: f32 = 7.888609052210118e-31;

// The item of this invocation in a dispatch of `(x, y)` workgroups of 64.
// No Rust twin: workgroup indexing.
fn adaptive_item(group: vec3<u32>, local: u32, groups: vec3<u32>) -> u32 {
    return workgroup_index(group, groups) * 64u + local;
}

// The index of workgroup `group` in a dispatch of `(x, y)` workgroups.
// No Rust twin: workgroup indexing.
fn workgroup_index(group: vec3<u32>, groups: vec3<u32>) -> u32 {
    return group.y * groups.x + group.x;
}

// a / b rounded up.
// No Rust twin: Rust's `u32::div_ceil`.
fn div_ceil(a: u32, b: u32) -> u32 {
    return (a + b - 1u) / b;
}

struct Record {
    depth: f32,
    cos_o: f32,
    screen_normal: vec2<f32>,
    mirror: vec3<f32>,
    prediction: u32,
}

// Render pixel `pixel`'s `render::adaptive::Pixel`, as `preview/adaptive/state.rs` packs it.
fn record(pixel: u32) -> Record {
    let a = records_surface[pixel];
    let b = records_lobe[pixel];
    return Record(a.depth, a.cos_o, a.screen_normal, b.mirror, b.prediction);
}

// Level k's width, height and first block.
// `render::adaptive::Level`'s size, and where its blocks start.
fn level_info(k: u32) -> vec3<u32> {
    let i = adapt.level_table + 4u * k;
    return vec3<u32>(tables[i], tables[i + 1u], tables[i + 2u]);
}

// The candidates of every level.
// No Rust twin: the CPU runs over every block, not a list of candidates.
fn candidates_total() -> u32 {
    return tables[adapt.level_table + 4u * (adapt.top + 1u) + 3u];
}

// The level of block `block` (its index among every level's blocks).
// No Rust twin: the CPU keeps each level's blocks apart (`render::adaptive::Plan`).
fn level_of_block(block: u32) -> u32 {
    var k = 0u;
    while (k < adapt.top && block >= level_info(k + 1u).z) {
        k += 1u;
    }
    return k;
}

// Level k's first candidate and their count.
// No Rust twin: the CPU runs over every block, not a list of candidates.
fn level_candidates(k: u32) -> vec2<u32> {
    let i = adapt.level_table + 4u * k + 3u;
    return vec2<u32>(tables[i], tables[i + 4u] - tables[i]);
}

// Candidate `i` of level k, as the index of the block within its level; NONE past the last.
// No Rust twin: the CPU runs over every block, not a list of candidates.
fn candidate(k: u32, i: u32) -> u32 {
    let range = level_candidates(k);
    if (i >= range.y) {
        return NONE;
    }
    return tables[adapt.candidates + range.x + i] - level_info(k).z;
}

// The min pyramid's entry: `render::adaptive::Level`'s `min_level`.
fn min_level(block: u32) -> i32 {
    return bitcast<i32>(levels[block].x);
}

// `render::adaptive::SAMPLES_PER_CYCLE`: a power of two.
const SAMPLES_PER_CYCLE: f32 = 4.0;

// `render::adaptive::level_of` of an f32 bandwidth: the largest level k <= top with
// SAMPLES_PER_CYCLE * bandwidth <= 2^-k (eq. 11, floor(log2(1 / (4 b)))), 0 when none; the top
// where the bandwidth is 0. Exact comparisons with powers of two: for f32 bandwidths they give
// the CPU's f64 logarithm's levels.
fn level_of(bandwidth: f32, top: u32) -> i32 {
    if (!(bandwidth > 0.0)) {
        return i32(top);
    }
    var k = 0u;
    while (k < top && SAMPLES_PER_CYCLE * bandwidth * exp2(f32(k + 1u)) <= 1.0) {
        k += 1u;
    }
    return i32(k);
}

// `render::adaptive::block_pixel`: the render pixel block (bx, by) of level k stands for.
fn block_pixel(k: u32, bx: u32, by: u32) -> u32 {
    let size = 1u << k;
    let x = min(bx * size + size / 2u, adapt.width - 1u);
    let y = min(by * size + size / 2u, adapt.height - 1u);
    return y * adapt.width + x;
}
