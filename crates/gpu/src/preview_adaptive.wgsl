// An adaptive frame on the GPU after its prediction (`render::adaptive`, step for step; with the
// files `gpu::wgsl` lists: the accumulation and backdrop of `preview_bindings.wgsl`, the wide
// integers of `preview_geometry.wgsl`): the
// levels of the bandwidth buffer, the min and max pyramids, the plan, the samples (the area
// allocation) and the list of shaded blocks, the shaded blocks' estimates put in place, the
// up-sampling from coarse to fine and the output image. `Renderer::render_adaptive`
// (`preview/adaptive/mod.rs`) records the passes (and, for the other allocations, allocates the
// samples on the host between two submissions).
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

// The state, per render pixel or per block of every level (blocks of level k start at the level
// table's offset for k):
// - records, per render pixel: its depth (-1 where no triangle covers it, 0 where one covers it
//   but it is not shadeable), cos theta_o and the screen-projected normal (x, y); and its mirror
//   direction (x, y, z) with the index of its prediction (`NONE` where it is not shadeable);
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
@group(3) @binding(3) var<storage, read> records_surface: array<vec4<f32>>;
@group(3) @binding(4) var<storage, read> records_lobe: array<vec4<u32>>;
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
    var r: Record;
    r.depth = a.x;
    r.cos_o = a.y;
    r.screen_normal = a.zw;
    r.mirror = bitcast<vec3<f32>>(b.xyz);
    r.prediction = b.w;
    return r;
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

// `render::adaptive::level_of` of an f32 bandwidth: the largest level k <= top with bandwidth <=
// 2^-(k+1) (eq. 11 with the Nyquist rate, floor(log2(1 / (2 b)))), 0 when none; the top where
// the bandwidth is 0. Exact comparisons with powers of two: for f32 bandwidths they give the
// CPU's f64 logarithm's levels.
fn level_of(bandwidth: f32, top: u32) -> i32 {
    if (!(bandwidth > 0.0)) {
        return i32(top);
    }
    var k = 0u;
    while (k < top && bandwidth * exp2(f32(k + 2u)) <= 1.0) {
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

// Level 0 of the pyramids: each shadeable render pixel's level and variance from its prediction
// (in `accumulation`, as `predict_blocks` leaves it), or the oracle's bandwidth. A prediction whose pixel the GPU's raster does not find shadeable (-1) stands for
// the Nyquist rate, as `Renderer::predict_blocks` reads it. Level 0 of `render::adaptive::pyramid`,
// with the oracle as `render::adaptive::render_with` reads it.
@compute @workgroup_size(64)
fn adaptive_levels(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let p = candidate(0u, adaptive_item(group, local, groups));
    if (p == NONE) {
        return;
    }
    let v = accumulation[record(p).prediction];
    var bandwidth = v.x;
    var variance = v.y;
    if (bandwidth < 0.0) {
        bandwidth = 0.5;
        variance = 0.0;
    }
    if (adapt.oracle != 0u) {
        bandwidth = bandwidths[p];
    }
    let level = level_of(bandwidth, adapt.top);
    bandwidths[p] = bandwidth;
    levels[p] = vec4<u32>(bitcast<u32>(level), bitcast<u32>(variance), 0u, 0u);
}

// Level `adapt.level` of the pyramids from the level below: the least level and the largest
// variance of each block's children.
// `render::adaptive::pyramid` above level 0.
@compute @workgroup_size(64)
fn adaptive_reduce(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let b = candidate(adapt.level, adaptive_item(group, local, groups));
    if (b == NONE) {
        return;
    }
    let me = level_info(adapt.level);
    let child = level_info(adapt.level - 1u);
    let bx = b % me.x;
    let by = b / me.x;
    var level = 2147483647;
    var variance = 0.0;
    for (var j = 0u; j < 4u; j++) {
        let cx = 2u * bx + j % 2u;
        let cy = 2u * by + j / 2u;
        if (cx < child.x && cy < child.y) {
            let c = levels[child.z + cy * child.x + cx];
            level = min(level, bitcast<i32>(c.x));
            variance = max(variance, bitcast<f32>(c.y));
        }
    }
    levels[me.z + b] = vec4<u32>(bitcast<u32>(level), bitcast<u32>(variance), 0u, 0u);
}

// `render::adaptive::lobe_similarity` in f32, with `d - (l_i + l_j)` written as
// `-l_i l_j |xi_i - xi_j|^2 / (d + l_i + l_j)` (the same for unit axes) so that sharp lobes
// keep their precision.
fn lobe_similarity(xi_i: vec3<f32>, l_i: f32, xi_j: vec3<f32>, l_j: f32) -> f32 {
    let a_i = select(l_i / (1.0 - exp(-4.0 * l_i)), 0.25, l_i < 1e-9);
    let a_j = select(l_j / (1.0 - exp(-4.0 * l_j)), 0.25, l_j < 1e-9);
    let sum = l_i + l_j;
    let d = length(l_i * xi_i + l_j * xi_j);
    var sinh_over = exp(-sum);
    if (d >= 1e-9) {
        let gap = xi_i - xi_j;
        let d_minus_sum = -l_i * l_j * dot(gap, gap) / (d + sum);
        sinh_over = (exp(d_minus_sum) - exp(-d - sum)) / (2.0 * d);
    }
    return 4.0 * sqrt(a_i * a_j) * sinh_over;
}

// The lobe's sharpness at a pixel's view row: the `lambda` of `render::adaptive::upsample_weights`.
fn sharpness(r: Record) -> f32 {
    let row = min(u32((1.0 - r.cos_o) * f32(adapt.n_rows)), adapt.n_rows - 1u);
    return bitcast<f32>(tables[adapt.sharpness + row]);
}

// A block's pixel centre along one axis: b 2^k + floor(2^k / 2) + 1/2.
// The `centre` of `render::adaptive::upsample_weights`.
fn block_centre(b: u32, k: u32) -> f32 {
    return f32(b * (1u << k) + (1u << k) / 2u) + 0.5;
}

// `render::adaptive::upsample_weights` of block (bx, by) of level k from level k + 1: writes the
// parents and their weights into the block's plan entry and returns how many count (0: rescue).
fn upsample_weights(k: u32, bx: u32, by: u32, block: u32) -> u32 {
    let parent = level_info(k + 1u);
    let me = record(block_pixel(k, bx, by));
    if (me.prediction == NONE) {
        return 0u;
    }
    let spacing = f32(1u << (k + 1u));
    let offset = block_centre(0u, k + 1u);
    var first = vec2<u32>(0u);
    var frac = vec2<f32>(0.0);
    if (parent.x > 1u) {
        let t = clamp((block_centre(bx, k) - offset) / spacing, 0.0, f32(parent.x - 1u));
        first.x = min(u32(floor(t)), parent.x - 2u);
        frac.x = t - f32(first.x);
    }
    if (parent.y > 1u) {
        let t = clamp((block_centre(by, k) - offset) / spacing, 0.0, f32(parent.y - 1u));
        first.y = min(u32(floor(t)), parent.y - 2u);
        frac.y = t - f32(first.y);
    }
    let cos_x = max(me.cos_o, 0.1);
    var n = me.screen_normal;
    if (n.x == 0.0 && n.y == 0.0) {
        n = vec2<f32>(1.0, 0.0);
    }
    // The counted parents and their weights, slot `count` the next: vectors written and searched
    // by masks (an array indexed by a variable would live in scratch memory, which costs about
    // 1.5 ms a dispatch on llvmpipe).
    let slots = vec4<u32>(0u, 1u, 2u, 3u);
    var chosen = vec4<u32>(0u);
    var w = vec4<f32>(0.0);
    var count = 0u;
    var total = 0.0;
    for (var j = 0u; j < 4u; j++) {
        let dx = j % 2u;
        let dy = j / 2u;
        let alpha = select(1.0 - frac.x, frac.x, dx == 1u) * select(1.0 - frac.y, frac.y, dy == 1u);
        let px = min(first.x + dx, parent.x - 1u);
        let py = min(first.y + dy, parent.y - 1u);
        let b = py * parent.x + px;
        let seen = any((chosen == vec4<u32>(b)) & (slots < vec4<u32>(count)));
        if (alpha <= 0.0 || min_level(parent.z + b) < i32(k + 1u) || seen) {
            continue;
        }
        let them = record(block_pixel(k + 1u, px, py));
        if (them.prediction == NONE) {
            continue;
        }
        let dz = (me.depth - them.depth) / (adapt.depth_sigma * me.depth);
        let g_z = exp(-0.5 * dz * dz);
        let v = vec2<f32>(block_centre(px, k + 1u) - block_centre(bx, k), block_centre(py, k + 1u) - block_centre(by, k))
            / spacing;
        let along = v.x * n.x + v.y * n.y;
        let across = -v.x * n.y + v.y * n.x;
        let g_a = exp(-(along * along / (cos_x * cos_x) + across * across));
        var g_lobe = 1.0;
        if (adapt.n_rows > 0u) {
            g_lobe = lobe_similarity(me.mirror, sharpness(me), them.mirror, sharpness(them));
        }
        let weight = g_z * g_a * alpha * g_lobe;
        if (weight >= MIN_WEIGHT) {
            let slot = slots == vec4<u32>(count);
            chosen = select(chosen, vec4<u32>(b), slot);
            w = select(w, vec4<f32>(weight), slot);
            total += weight;
            count += 1u;
        }
    }
    if (count == 0u || !(total > adapt.rescue_below)) {
        return 0u;
    }
    parents[block] = chosen;
    weights[block] = w / total;
    return count;
}

// The plan (`render::adaptive`, "Coarse to fine") of every candidate block of every level: skipped,
// shaded (appended to the list), rescued (shaded, appended) or up-sampled with its weights.
@compute @workgroup_size(64)
fn adaptive_plan(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let c = adaptive_item(group, local, groups);
    if (c >= adapt.count) {
        return;
    }
    let block = tables[adapt.candidates + c];
    let k = level_of_block(block);
    let me = level_info(k);
    let b = block - me.z;
    let bx = b % me.x;
    let by = b / me.x;
    let entry = levels[block];
    var action = ACTION_SKIP;
    if (bitcast<i32>(entry.x) >= i32(k)) {
        action = ACTION_SHADE;
        if (k < adapt.top) {
            let parent = level_info(k + 1u);
            if (min_level(parent.z + (by / 2u) * parent.x + bx / 2u) >= i32(k + 1u)) {
                let count = upsample_weights(k, bx, by, block);
                action = select(ACTION_RESCUED, ACTION_UPSAMPLE | (count << 8u), count > 0u);
            }
        }
        if (action == ACTION_SHADE || action == ACTION_RESCUED) {
            atomicAdd(&control[CONTROL_SHADED], 1u);
            atomicAdd(&control[CONTROL_COUNTS + k], 1u);
            atomicAdd(&control[CONTROL_CHUNKS + c / CHUNK], 1u);
        }
    }
    levels[block].z = action;
}

// The allocation's 64-bit values, `preview_geometry.wgsl`'s `Wide` read as unsigned: every factor
// but a count is a power of two, so shifts, sums and comparisons do. The largest, a share's
// numerator (`W + spare 2^k`: the budget below 2^32, k at most 15) times 2^16, stays below
// 2^64.
// No Rust twin: 64-bit integer emulation; the CPU (`render::adaptive::area_allocation`) uses u128.
fn wide(x: u32) -> Wide {
    return Wide(0u, x);
}

// No Rust twin: 64-bit integer emulation; the CPU uses u128.
fn wide_shl(a: Wide, s: u32) -> Wide {
    if (s == 0u) {
        return a;
    }
    if (s >= 32u) {
        return Wide(a.lo << (s - 32u), 0u);
    }
    return Wide((a.hi << s) | (a.lo >> (32u - s)), a.lo << s);
}

// No Rust twin: 64-bit integer emulation; the CPU uses u128.
fn wide_sub(a: Wide, b: Wide) -> Wide {
    return wide_add(a, wide_negate(b));
}

// a <= b, unsigned.
// No Rust twin: 64-bit integer emulation; the CPU uses u128.
fn wide_le(a: Wide, b: Wide) -> bool {
    return a.hi < b.hi || (a.hi == b.hi && a.lo <= b.lo);
}

// No Rust twin: a control word (read).
fn control_word(i: u32) -> u32 {
    return atomicLoad(&control[i]);
}

// No Rust twin: a control word (written).
fn set_control(i: u32, value: u32) {
    atomicStore(&control[i], value);
}

// Workgroups of 64 for `count` items as (x, y), at least one: `gpu::preview::adaptive::groups`,
// and with `power_of_two` the power of two of `gpu::preview::item_groups` (`item_index`'s order).
fn set_groups(at: u32, count: u32, power_of_two: bool) {
    var n = max(div_ceil(count, 64u), 1u);
    if (power_of_two && n > 1u) {
        n = 1u << (32u - countLeadingZeros(n - 1u));
    }
    set_control(at, min(n, 32768u));
    set_control(at + 1u, div_ceil(n, 32768u));
    set_control(at + 2u, 1u);
}

// The parts of a level's `count` blocks of `samples` samples, the first `doubled` of twice that.
// The items `gpu::preview::adaptive::parts` makes of them.
fn level_items(count: u32, doubled: u32, samples: u32, part: u32) -> u32 {
    return doubled * div_ceil(2u * samples, part) + (count - doubled) * div_ceil(samples, part);
}

// `adaptive_allocate`'s per-level state, in workgroup memory (its one invocation's): arrays in
// function memory indexed by a variable live in scratch memory on llvmpipe, which costs about
// 1.5 ms a dispatch there however little the shader runs.
var<workgroup> alloc_counts: array<u32, MAX_LEVELS>;
var<workgroup> alloc_capped: array<bool, MAX_LEVELS>;
var<workgroup> alloc_shift: array<u32, MAX_LEVELS>;
var<workgroup> alloc_doubled: array<u32, MAX_LEVELS>;
var<workgroup> alloc_full: array<bool, MAX_LEVELS>;
var<workgroup> alloc_done: array<bool, MAX_LEVELS>;

// `render::adaptive::area_allocation` of the shaded blocks per level (`adaptive_plan`'s counts),
// step for step in integers, and `gpu::preview::adaptive::parts` of its samples: the samples per
// part, each level's first item and first rank, the items in all and the workgroups of
// `shade_blocks` and of the list's passes. One invocation: a few levels.
@compute @workgroup_size(1)
fn adaptive_allocate() {
    let levels_n = adapt.top + 1u;
    var n = 0u;
    for (var k = 0u; k < MAX_LEVELS; k++) {
        alloc_counts[k] = 0u;
        if (k < levels_n) {
            alloc_counts[k] = control_word(CONTROL_COUNTS + k);
        }
        n += alloc_counts[k];
        alloc_capped[k] = false;
        alloc_shift[k] = 0u;
        alloc_doubled[k] = 0u;
        alloc_done[k] = false;
    }
    if (n > adapt.budget) {
        set_control(CONTROL_STATUS, 1u);
        return;
    }
    let cap_shift = countTrailingZeros(adapt.max_spp);
    // The water filling: spare 2^k >= (max_spp - 1) W fills level k.
    var spare = adapt.budget - n;
    var total = 0u;
    var sharing = false;
    loop {
        total = 0u;
        for (var k = 0u; k < levels_n; k++) {
            if (alloc_counts[k] > 0u && !alloc_capped[k]) {
                total += alloc_counts[k] << k;
            }
        }
        if (spare == 0u || total == 0u) {
            break;
        }
        let bar = wide_sub(wide_shl(wide(total), cap_shift), wide(total));
        var some_full = false;
        for (var k = 0u; k < levels_n; k++) {
            alloc_full[k] = alloc_counts[k] > 0u && !alloc_capped[k] && wide_le(bar, wide_shl(wide(spare), k));
            some_full = some_full || alloc_full[k];
        }
        if (!some_full) {
            sharing = true;
            break;
        }
        for (var k = 0u; k < levels_n; k++) {
            if (alloc_full[k]) {
                spare -= alloc_counts[k] * (adapt.max_spp - 1u);
                alloc_capped[k] = true;
            }
        }
    }
    // Each level's power of two below its share (total + spare 2^k over total where shared).
    var left = adapt.budget;
    for (var k = 0u; k < levels_n; k++) {
        if (alloc_capped[k]) {
            alloc_shift[k] = cap_shift;
        } else if (sharing && alloc_counts[k] > 0u) {
            let share = wide_add(wide(total), wide_shl(wide(spare), k));
            while (alloc_shift[k] < cap_shift && wide_le(wide_shl(wide(total), alloc_shift[k] + 1u), share)) {
                alloc_shift[k] += 1u;
            }
        }
        left -= alloc_counts[k] << alloc_shift[k];
    }
    // Doubling, furthest below the share first (the lesser level among equals): only the shared
    // levels can (a capped level is at max_spp; without a shared round nothing is left).
    if (sharing) {
        loop {
            var best = MAX_LEVELS;
            for (var k = 0u; k < levels_n; k++) {
                if (alloc_capped[k] || alloc_counts[k] == 0u || alloc_done[k]) {
                    continue;
                }
                if (best == MAX_LEVELS) {
                    best = k;
                    continue;
                }
                // share_k / 2^shift_k > share_best / 2^shift_best
                let mine = wide_shl(wide_add(wide(total), wide_shl(wide(spare), k)), alloc_shift[best]);
                let theirs = wide_shl(wide_add(wide(total), wide_shl(wide(spare), best)), alloc_shift[k]);
                if (!wide_le(mine, theirs)) {
                    best = k;
                }
            }
            if (best == MAX_LEVELS) {
                break;
            }
            alloc_done[best] = true;
            if (alloc_shift[best] < cap_shift) {
                alloc_doubled[best] = min(alloc_counts[best], left >> alloc_shift[best]);
                left -= alloc_doubled[best] << alloc_shift[best];
            }
        }
    }
    // The parts: PART samples each, or the least power of two above that keeps the items
    // within the capacity.
    var part = 16u;
    var items = 0u;
    loop {
        items = 0u;
        for (var k = 0u; k < levels_n; k++) {
            items += level_items(alloc_counts[k], alloc_doubled[k], 1u << alloc_shift[k], part);
        }
        if (items <= adapt.capacity || part >= 0x7fffffffu) {
            break;
        }
        part *= 2u;
    }
    var first_item = 0u;
    var first_rank = 0u;
    for (var k = 0u; k < levels_n; k++) {
        let at = CONTROL_LEVELS + 4u * k;
        let samples = 1u << alloc_shift[k];
        set_control(at, samples);
        set_control(at + 1u, alloc_doubled[k]);
        set_control(at + 2u, first_item);
        set_control(at + 3u, first_rank);
        first_item += level_items(alloc_counts[k], alloc_doubled[k], samples, part);
        first_rank += alloc_counts[k];
    }
    set_control(CONTROL_SAMPLES, adapt.budget - left);
    set_control(CONTROL_PARTS, items);
    set_control(CONTROL_PART, part);
    set_groups(CONTROL_ARGS, items, true);
    set_groups(CONTROL_ARGS + 3u, n, false);
}

var<workgroup> scan_words: array<u32, 256>;
// `adaptive_list`: 1 where the workgroup's chunk has no shaded candidate (or the frame failed).
var<workgroup> chunk_empty: u32;

// The inclusive prefix sum of `value` over a workgroup of `size` (at most 256) invocations
// (Hillis and Steele).
// No Rust twin: GPU plumbing (the CPU builds the list in one loop,
// `render::adaptive::render_with`).
fn workgroup_scan(local: u32, value: u32, size: u32) -> u32 {
    scan_words[local] = value;
    workgroupBarrier();
    for (var d = 1u; d < size; d *= 2u) {
        var add = 0u;
        if (local >= d) {
            add = scan_words[local - d];
        }
        workgroupBarrier();
        scan_words[local] += add;
        workgroupBarrier();
    }
    return scan_words[local];
}

// Whether candidate `c` (in the plan's order: level by level, by block) is shaded.
// The blocks whose `render::adaptive::Action` is `Shade`: those `render::adaptive::render_with`
// lists.
fn shaded_candidate(c: u32) -> bool {
    let action = levels[tables[adapt.candidates + c]].z & 0xffu;
    return action == ACTION_SHADE || action == ACTION_RESCUED;
}

// Invocation `local`'s RUN of chunk `chunk`'s CHUNK candidates, as (first, end).
// No Rust twin: how `adaptive_list` splits the candidates among invocations.
fn run_range(chunk: u32, local: u32) -> vec2<u32> {
    let first = chunk * CHUNK + local * RUN;
    return vec2<u32>(first, min(first + RUN, candidates_total()));
}

// The shaded candidates among invocation `local`'s run of chunk `chunk`.
// No Rust twin: how `adaptive_list` splits the candidates among invocations.
fn run_count(chunk: u32, local: u32) -> u32 {
    let run = run_range(chunk, local);
    var sum = 0u;
    for (var c = run.x; c < run.y; c++) {
        sum += u32(shaded_candidate(c));
    }
    return sum;
}

// The list in the plan's order, step 1 of 2, one workgroup of 256: the shaded candidates before
// each chunk of CHUNK, in place of its own, which the plan counted (each invocation sums a
// stretch of chunks, a prefix sum over the stretches, then each goes through its stretch again).
// No Rust twin: a prefix sum, for `adaptive_list`.
@compute @workgroup_size(256)
fn adaptive_offsets(@builtin(local_invocation_index) local: u32) {
    let chunks = div_ceil(candidates_total(), CHUNK);
    let per = div_ceil(chunks, 256u);
    let first = min(local * per, chunks);
    let last = min(first + per, chunks);
    var sum = 0u;
    for (var i = first; i < last; i++) {
        sum += control_word(CONTROL_CHUNKS + i);
    }
    var before = workgroup_scan(local, sum, 256u) - sum;
    for (var i = first; i < last; i++) {
        let mine = control_word(CONTROL_CHUNKS + i);
        set_control(CONTROL_CHUNKS + i, before);
        before += mine;
    }
}

// Step 2, a workgroup of 64 a chunk and RUN candidates an invocation (few barriers: lavapipe
// runs them slowly; many invocations: a GPU hides its memory's latency with them): each shaded
// candidate's entry at its rank. Where the GPU allocates, also its samples (the first of its
// level that `adaptive_allocate` doubled get twice its level's) and its parts in
// `shade_blocks`' items, as `gpu::preview::adaptive::parts` lays them out. The CPU's list: the
// shaded blocks of `render::adaptive::render_with`, in the same order.
@compute @workgroup_size(64)
fn adaptive_list(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let chunk = workgroup_index(group, groups);
    // A chunk without shaded candidates (most, where the plan shades little) has nothing to
    // write: the whole workgroup leaves before the scan.
    if (local == 0u) {
        let total = candidates_total();
        var empty = chunk * CHUNK >= total || control_word(CONTROL_STATUS) != 0u;
        if (!empty) {
            var after = control_word(CONTROL_SHADED);
            if ((chunk + 1u) * CHUNK < total) {
                after = control_word(CONTROL_CHUNKS + chunk + 1u);
            }
            empty = after == control_word(CONTROL_CHUNKS + chunk);
        }
        chunk_empty = u32(empty);
    }
    if (workgroupUniformLoad(&chunk_empty) != 0u) {
        return;
    }
    let mine = run_count(chunk, local);
    let inclusive = workgroup_scan(local, mine, 64u);
    if (mine == 0u) {
        return;
    }
    var rank = control_word(CONTROL_CHUNKS + chunk) + inclusive - mine;
    let run = run_range(chunk, local);
    for (var c = run.x; c < run.y; c++) {
        if (shaded_candidate(c)) {
            list_entry(tables[adapt.candidates + c], rank);
            rank += 1u;
        }
    }
}

// Shaded block `block`'s entry in the list, at `rank`.
// The entry and items of `gpu::preview::adaptive::parts`.
fn list_entry(block: u32, rank: u32) {
    let k = level_of_block(block);
    let me = level_info(k);
    let b = block - me.z;
    let pixel = block_pixel(k, b % me.x, b / me.x);
    if (adapt.allocate == 0u) {
        list[rank] = vec4<u32>(k, b, levels[block].y, pixel);
        return;
    }
    let at = CONTROL_LEVELS + 4u * k;
    let samples = control_word(at);
    let doubled = control_word(at + 1u);
    let part = control_word(CONTROL_PART);
    let r = rank - control_word(at + 3u);
    let parts_doubled = div_ceil(2u * samples, part);
    var n = samples;
    var first = control_word(at + 2u) + r * parts_doubled;
    if (r >= doubled) {
        first = control_word(at + 2u) + doubled * parts_doubled + (r - doubled) * div_ceil(samples, part);
    } else {
        n = 2u * samples;
    }
    let count = div_ceil(n, part);
    for (var m = 0u; m < count; m++) {
        let start = m * part;
        accumulation[first + m] = bitcast<vec4<f32>>(vec4<u32>(pixel, n, start, min(part, n - start)));
    }
    list[rank] = vec4<u32>(block, first, count, n);
}

// The shaded blocks' estimates in place: the sum of each one's parts (`accumulation`, as
// `shade_blocks` leaves them; the list's entry `i` holds the block, its first part and their count).
// Dispatched for the list (`CONTROL_ARGS` + 3 where the GPU allocates).
// The shaded blocks' values in `render::adaptive::render_with` (the `Action::Shade` arm).
@compute @workgroup_size(64)
fn adaptive_scatter(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let i = adaptive_item(group, local, groups);
    if (i >= atomicLoad(&control[CONTROL_SHADED])) {
        return;
    }
    let entry = list[i];
    var estimate = vec3<f32>(0.0);
    for (var m = 0u; m < entry.z; m++) {
        estimate += accumulation[entry.y + m].xyz;
    }
    values[entry.x] = vec4<f32>(estimate, 0.0);
}

// Level `adapt.level`'s up-sampled blocks: the weighted means of their parents' values.
// The `Action::Upsample` arm of `render::adaptive::render_with`.
@compute @workgroup_size(64)
fn adaptive_upsample(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let b = candidate(adapt.level, adaptive_item(group, local, groups));
    if (b == NONE) {
        return;
    }
    let block = level_info(adapt.level).z + b;
    let action = levels[block].z;
    if ((action & 0xffu) != ACTION_UPSAMPLE) {
        return;
    }
    let first = level_info(adapt.level + 1u).z;
    let p = parents[block];
    let w = weights[block];
    var mean = vec3<f32>(0.0);
    for (var m = 0u; m < (action >> 8u); m++) {
        mean += w[m] * values[first + p[m]].xyz;
    }
    values[block] = vec4<f32>(mean, 0.0);
}

// The output image into `accumulation`: each output pixel the mean of its ss x ss render
// pixels (level 0's values, the environment (`backdrop`) where no triangle covers the pixel, black
// where one covers it without a shading frame), w = 1 where a triangle covers any of them.
// `render::adaptive::render_with`'s render pixels then `render::adaptive::frame::downsample`.
@compute @workgroup_size(64)
fn adaptive_output(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let o = adaptive_item(group, local, groups);
    if (o >= adapt.out_width * adapt.out_height) {
        return;
    }
    let ox = o % adapt.out_width;
    let oy = o / adapt.out_width;
    var sum = vec3<f32>(0.0);
    var covered = 0.0;
    for (var j = 0u; j < adapt.ss * adapt.ss; j++) {
        let x = ox * adapt.ss + j % adapt.ss;
        let y = oy * adapt.ss + j / adapt.ss;
        let p = y * adapt.width + x;
        // The depth alone tells the three apart: the rest of the record is not read.
        let depth = records_surface[p].x;
        if (depth < 0.0) {
            sum += backdrop[p].xyz;
        } else {
            covered = 1.0;
            if (depth > 0.0) {
                sum += values[p].xyz;
            }
        }
    }
    accumulation[o] = vec4<f32>(sum / f32(adapt.ss * adapt.ss), covered);
}
