// An adaptive frame on the GPU after its prediction (`render::adaptive`, step for step; compiled
// after `preview_shade.wgsl`, whose background, camera ray and accumulation buffer it uses): the
// levels of the bandwidth buffer, the min and max pyramids, the plan, the shaded blocks' estimates
// put in place, the up-sampling from coarse to fine and the output image. `Renderer::render_adaptive`
// (`preview/adaptive.rs`) records the passes and allocates the samples between them.
//
// Group 3, bindings 2 and up (bindings 0 and 1 are the prediction's): one uniform slot per pass,
// then the frame's state, one buffer per kind so that each stays within the adapter's largest
// binding (128 MiB on lavapipe: a 2048 x 2048 render's records take 64 MiB each), and the count
// of shaded blocks.

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
    _pad: u32,
}

// The state, per render pixel or per block of every level (blocks of level k start at the level
// table's offset for k):
// - records, per render pixel: its depth (-1 where no triangle covers it), cos theta_o and the
//   screen-projected normal (x, y); and its mirror direction (x, y, z) with the index of its
//   prediction (`NONE` where it is not shadeable);
// - bandwidths, per render pixel: its image bandwidth (cycles per pixel);
// - levels, per block: the min pyramid (i32), the max pyramid of the variance, the action
//   (`ACTION_*`, with the parents' count in bits 8 and up), unused;
// - parents and weights, per block: the parents' block indices in the next level, their weights;
// - values, per block: its value (RGB) once shaded or up-sampled;
// - list, per block: the shaded blocks (level, block, max variance, pixel) in the order
//   `adaptive_plan` finds them; then, from the host, in the plan's order: the block, the first of
//   its parts in `shade_blocks`' items and their count;
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
@group(3) @binding(12) var<storage, read_write> shaded_count: array<atomic<u32>>;

const NONE: u32 = 0xffffffffu;
const ACTION_SKIP: u32 = 0u;
const ACTION_SHADE: u32 = 1u;
const ACTION_RESCUED: u32 = 2u;
const ACTION_UPSAMPLE: u32 = 3u;
// `render::adaptive::MIN_WEIGHT`: 2^-100.
const MIN_WEIGHT: f32 = 7.888609052210118e-31;

// The item of this invocation in a dispatch of `(x, y)` workgroups of 64.
fn adaptive_item(group: vec3<u32>, local: u32, groups: vec3<u32>) -> u32 {
    return (group.y * groups.x + group.x) * 64u + local;
}

struct Record {
    depth: f32,
    cos_o: f32,
    screen_normal: vec2<f32>,
    mirror: vec3<f32>,
    prediction: u32,
}

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
fn level_info(k: u32) -> vec3<u32> {
    let i = adapt.level_table + 4u * k;
    return vec3<u32>(tables[i], tables[i + 1u], tables[i + 2u]);
}

// Level k's first candidate and their count.
fn level_candidates(k: u32) -> vec2<u32> {
    let i = adapt.level_table + 4u * k + 3u;
    return vec2<u32>(tables[i], tables[i + 4u] - tables[i]);
}

// Candidate `i` of level k, as the index of the block within its level; NONE past the last.
fn candidate(k: u32, i: u32) -> u32 {
    let range = level_candidates(k);
    if (i >= range.y) {
        return NONE;
    }
    return tables[adapt.candidates + range.x + i] - level_info(k).z;
}

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
// the Nyquist rate, as `Renderer::predict_blocks` reads it.
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

fn sharpness(r: Record) -> f32 {
    let row = min(u32((1.0 - r.cos_o) * f32(adapt.n_rows)), adapt.n_rows - 1u);
    return bitcast<f32>(tables[adapt.sharpness + row]);
}

// A block's pixel centre along one axis: b 2^k + floor(2^k / 2) + 1/2.
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
    var chosen = array<u32, 4>(0u, 0u, 0u, 0u);
    var w = array<f32, 4>(0.0, 0.0, 0.0, 0.0);
    var count = 0u;
    var total = 0.0;
    for (var j = 0u; j < 4u; j++) {
        let dx = j % 2u;
        let dy = j / 2u;
        let alpha = select(1.0 - frac.x, frac.x, dx == 1u) * select(1.0 - frac.y, frac.y, dy == 1u);
        let px = min(first.x + dx, parent.x - 1u);
        let py = min(first.y + dy, parent.y - 1u);
        let b = py * parent.x + px;
        var seen = false;
        for (var m = 0u; m < count; m++) {
            seen = seen || chosen[m] == b;
        }
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
            chosen[count] = b;
            w[count] = weight;
            total += weight;
            count += 1u;
        }
    }
    if (count == 0u || !(total > adapt.rescue_below)) {
        return 0u;
    }
    parents[block] = vec4<u32>(chosen[0], chosen[1], chosen[2], chosen[3]);
    weights[block] = vec4<f32>(w[0], w[1], w[2], w[3]) / total;
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
    var k = 0u;
    while (k < adapt.top && block >= level_info(k + 1u).z) {
        k += 1u;
    }
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
            list[atomicAdd(&shaded_count[0], 1u)] = vec4<u32>(k, b, entry.y, block_pixel(k, bx, by));
        }
    }
    levels[block].z = action;
}

// The shaded blocks' estimates in place: the sum of each one's parts (`accumulation`, as
// `shade_blocks` leaves them; the list's entry `i` holds the block, its first part and their count).
@compute @workgroup_size(64)
fn adaptive_scatter(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let i = adaptive_item(group, local, groups);
    if (i >= adapt.count) {
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
// pixels (level 0's values, the environment where no triangle covers the pixel, black where one
// covers it without a shading frame), w = 1 where a triangle covers any of them.
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
        let r = record(p);
        if (r.depth < 0.0) {
            sum += env_bilinear(0u, env_uv(camera_ray(x, y)));
        } else {
            covered = 1.0;
            if (r.prediction != NONE) {
                sum += values[p].xyz;
            }
        }
    }
    accumulation[o] = vec4<f32>(sum / f32(adapt.ss * adapt.ss), covered);
}
