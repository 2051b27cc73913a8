// The frame's samples shared among its shaded blocks (the area allocation) and the list of shaded
// blocks, on the GPU: `render::adaptive`'s `samples.rs`, step for step (the state and its
// helpers: `state.wgsl`).

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
// `render::adaptive::frame::shade_blocks`).
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
// The blocks whose `render::adaptive::Action` is `Shade`: those
// `render::adaptive::frame::shade_blocks` lists.
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
// shaded blocks of `render::adaptive::frame::shade_blocks`, in the same order.
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
