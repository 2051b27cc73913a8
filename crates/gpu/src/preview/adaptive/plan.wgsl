// The levels of the bandwidth buffer, the min and max pyramids and the plan of every block, on
// the GPU: `render::adaptive`'s `plan.rs`, step for step (the state and its helpers:
// `state.wgsl`).

// Level 0 of the pyramids: each shadeable render pixel's level and variance from its prediction
// (in `accumulation`, as `predict_blocks` leaves it), or the oracle's bandwidth. A
// prediction whose pixel the GPU's raster does not find shadeable (-1) stands for the pixel
// grid's Nyquist limit, 1/2 cycle per pixel, as `Renderer::predict_blocks` reads it. Level 0
// of `render::adaptive::pyramid`, with the oracle as `render::adaptive::frame::apply_oracle` reads it.
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

// `render::adaptive::GRADE_RADIUS` and `GRADE_SLACK`.
const GRADE_RADIUS: i32 = 4;
const GRADE_SLACK: i32 = 1;

// Each shadeable render pixel's graded level (`render::adaptive::grade_levels`): at most
// GRADE_SLACK more than the least level of the shadeable pixels within GRADE_RADIUS, kept in
// the entry's third word until `adaptive_grade_apply` (the pixels read their neighbours' levels,
// which this pass must leave as they are). After `adaptive_levels`.
// `render::adaptive::grade_levels`.
@compute @workgroup_size(64)
fn adaptive_grade(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let p = candidate(0u, adaptive_item(group, local, groups));
    if (p == NONE) {
        return;
    }
    let size = level_info(0u);
    let x = i32(p % size.x);
    let y = i32(p / size.x);
    var least = min_level(p);
    for (var qy = max(y - GRADE_RADIUS, 0); qy <= min(y + GRADE_RADIUS, i32(size.y) - 1); qy++) {
        for (var qx = max(x - GRADE_RADIUS, 0); qx <= min(x + GRADE_RADIUS, i32(size.x) - 1); qx++) {
            let l = min_level(u32(qy) * size.x + u32(qx));
            if (l >= 0) {
                least = min(least, l);
            }
        }
    }
    levels[p].z = bitcast<u32>(min(min_level(p), least + GRADE_SLACK));
}

// The graded levels into the min pyramid's level 0, the third word cleared for the plan.
// No Rust twin: `render::adaptive::grade_levels` grades in place from a copy.
@compute @workgroup_size(64)
fn adaptive_grade_apply(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let p = candidate(0u, adaptive_item(group, local, groups));
    if (p == NONE) {
        return;
    }
    levels[p].x = levels[p].z;
    levels[p].z = 0u;
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
// parents and their weights into the block's plan entry and returns how many count (0: rescue:
// a bilinear parent not valid, the weights vanished or summed to at most the threshold).
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
        if (alpha <= 0.0 || seen) {
            continue;
        }
        if (min_level(parent.z + b) < i32(k + 1u)) {
            return 0u;
        }
        let them = record(block_pixel(k + 1u, px, py));
        if (them.prediction == NONE) {
            return 0u;
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

// The plan (`render::adaptive::plan::plan`, "Coarse to fine") of every candidate block of every level: skipped,
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
