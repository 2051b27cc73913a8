// The rest of an adaptive frame on the GPU: the shaded blocks' estimates put in place, the
// up-sampling from coarse to fine and the output image (`render::adaptive`'s `frame.rs`; the
// state and its helpers: `state.wgsl`).

// The shaded blocks' estimates in place: the sum of each one's parts (`accumulation`, as
// `shade_blocks` leaves them; the list's entry `i` holds the block, its first part and their count).
// Dispatched for the list (`CONTROL_ARGS` + 3 where the GPU allocates).
// The shaded blocks' values in `render::adaptive::frame::upsample` (the `Action::Shade` arm).
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
// The `Action::Upsample` arm of `render::adaptive::frame::upsample`.
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
// pixels (level 0's values, the environment (`backdrop_index`) where no triangle covers the pixel, black
// where one covers it without a shading frame), w = 1 where a triangle covers any of them.
// `render::adaptive::frame::compose`: its render pixels, then `render::adaptive::frame::downsample`.
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
        let depth = records_surface[p].depth;
        if (depth < 0.0) {
            sum += accumulation[backdrop_index(p)].xyz;
        } else {
            covered = 1.0;
            if (depth > 0.0) {
                sum += values[p].xyz;
            }
        }
    }
    accumulation[o] = vec4<f32>(sum / f32(adapt.ss * adapt.ss), covered);
}
