//! The previewer's shading pass: one frame of the estimators of the `render` crate (its crate
//! documentation is the specification), per pixel of the triangle-index G-buffer that
//! `preview_raster.wgsl` drew, added into an accumulation buffer (entry points `shade_backdrop`,
//! `shade_frame`, and `shade_blocks` for an adaptive frame). `material_brdf` of
//! `wavelet_brdf.wgsl` (group 0: the MERL table's nearest lookup, or the wavelet reconstruction)
//! is the BRDF; `gpu::wgsl` lists the files this one needs.
//!
//! Every step is a function named after the CPU's (`render::raster`, `render::shade`, `envmap`),
//! in the same order and with the same branches, so that the two images differ by f32 rounding
//! only: the CPU works in f64. Group 1 is what the scene, material and lighting upload once,
//! group 2 the render.

// One frame's estimate at a covered pixel: 1 / spp of `estimate_sum` over its spp terms.
// One frame of the loop over frames in `render::shade::shade`.
fn estimate(frame: ShadingFrame, pixel: u32, f: u32, spp: u32) -> vec3<f32> {
    return estimate_sum(frame, pixel, f, spp, 0u, spp, shade.filter_samples) / f32(spp);
}

// The light the two strategies of multiple importance sampling share in this mode
// (`render::shade`): level 0 whole in the reference mode, the peaks in the filtered modes;
// `valid` is false where a filtered mode's environment has no peaks.
struct SampledLight {
    valid: bool,
    map: u32,
    distribution: LatLong,
}

// The `sampled` light of `render::shade::shade`.
fn sampled_light() -> SampledLight {
    if (shade.mode == MODE_REFERENCE) {
        return SampledLight(true, 0u, LatLong(shade.env_marginal, shade.env_conditional));
    }
    return SampledLight(shade.peak_map != NO_MAP, shade.peak_map, LatLong(shade.peak_marginal, shade.peak_conditional));
}

// The sum of terms `first .. first + count` of the pixel's `spp` in frame `f`
// (`render::shade::shade`): term `j` is the BRDF's sample at point `base + j` of the pixel's
// BRDF sequence and, where the mode samples a light, the light's at the same point of its own.
// `n_filter` is the pixel's samples over all its frames, whose footprints the prefiltered mode
// reads.
fn estimate_sum(frame: ShadingFrame, pixel: u32, f: u32, spp: u32, first: u32, count: u32, n_filter: u32) -> vec3<f32> {
    let k = slice_of(frame);
    let range = sample_range(pixel, f, spp);
    let base = range.x * shade.n_samples + range.y;
    let words = pixel_words(pixel);
    let light = sampled_light();
    var x_view = 0.0;
    var diffuse = vec3<f32>(0.0);
    var sum = vec3<f32>(0.0);
    if (shade.mode == MODE_PREFILTERED) {
        x_view = pixel_layer(frame);
    }
    // The filtered modes' diffuse part and its integral, once per term (the terms' sum is divided
    // by their count); never nonzero without a cosine layer to read.
    if (shade.mode != MODE_REFERENCE && any(shade.diffuse.xyz != vec3<f32>(0.0))) {
        diffuse = shade.diffuse.xyz;
        sum = (PI * diffuse * env_bilinear(shade.layers_first, env_uv(frame.n))) * f32(count);
    }
    for (var j = first; j < first + count; j++) {
        let index = base + j;
        let s = brdf_sample(k, sequence_point(words.xy, index));
        if (s.pdf > 0.0 && s.wi.z > 0.0) {
            let brdf = material_brdf(s.wi, frame.wo_local);
            let rest = brdf - diffuse;
            // No data counts as 0; the CPU skips zeros too.
            if (any(brdf != vec3<f32>(0.0)) || any(rest != vec3<f32>(0.0))) {
                let uv = env_uv(to_world(frame, s.wi));
                if (shade.mode == MODE_FIS) {
                    sum += rest * mip_trilinear(uv, mip_lod(s.pdf)) * (s.wi.z / s.pdf);
                } else if (shade.mode == MODE_PREFILTERED) {
                    sum += rest * layers_bilinear(x_view, footprint_layer(n_filter, s.pdf), uv) * (s.wi.z / s.pdf);
                }
                if (light.valid) {
                    let weight = mis_weight(s.pdf, latlong_pdf(light.distribution, uv));
                    sum += brdf * env_bilinear(light.map, uv) * (s.wi.z * weight / s.pdf);
                }
            }
        }
        if (!light.valid) {
            continue;
        }
        let drawn = latlong_sample(light.distribution, sequence_point(words.zw, index));
        let wi = to_local(frame, env_direction(drawn.uv));
        if (drawn.pdf > 0.0 && wi.z > 0.0) {
            let brdf = material_brdf(wi, frame.wo_local);
            if (any(brdf != vec3<f32>(0.0))) {
                let weight = mis_weight(drawn.pdf, brdf_pdf(k, wi));
                sum += brdf * env_bilinear(light.map, drawn.uv) * (wi.z * weight / drawn.pdf);
            }
        }
    }
    return sum;
}

// The environment along every pixel's camera ray (`render::render`'s background), for the frames
// of a camera: the same in each of them, so drawn once (`Renderer::rasterize`).
@compute @workgroup_size(SHADE_WORKGROUP, SHADE_WORKGROUP)
fn shade_backdrop(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= shade.width || gid.y >= shade.height) {
        return;
    }
    accumulation[backdrop_index(gid.y * shade.width + gid.x)] = vec4<f32>(env_bilinear(0u, env_uv(camera_ray(gid.x, gid.y))), 0.0);
}

// One frame of every pixel: `render::shade::shade_rows` with `render::shade::shade` (the G-buffer
// and debug modes have no Rust twin).
@compute @workgroup_size(SHADE_WORKGROUP, SHADE_WORKGROUP)
fn shade_frame(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= shade.width || gid.y >= shade.height) {
        return;
    }
    let pixel = gid.y * shade.width + gid.x;
    let triangle = textureLoad(gbuffer_triangle, vec2<i32>(gid.xy), 0).x;
    let covered = triangle > 0u;
    var hit: Hit;
    if (covered) {
        hit = interpolate_hit(triangle - 1u, gid.x, gid.y);
    }
    if (shade.mode == MODE_GBUFFER_POSITION) {
        accumulation[pixel] = vec4<f32>(hit.position, f32(triangle));
        return;
    }
    if (shade.mode == MODE_GBUFFER_NORMAL) {
        accumulation[pixel] = vec4<f32>(hit.normal, select(0.0, 1.0, covered));
        return;
    }
    var radiance = vec3<f32>(0.0);
    if (covered && shade.mode == MODE_DEBUG_NORMAL) {
        radiance = hit.normal;
    } else if (covered) {
        let maybe = shading_frame(hit);
        if (maybe.valid) {
            if (shade.mode == MODE_DEBUG_LAYER || shade.mode == MODE_DEBUG_SLICE) {
                radiance = debug_index(maybe.frame);
            } else {
                radiance = estimate(maybe.frame, pixel, frame.index, shade.spp);
            }
        }
    } else {
        // The environment behind the mesh in every mode, so that its orientation can be checked.
        radiance = accumulation[backdrop_index(pixel)].xyz;
    }
    let sum = accumulation[pixel].xyz + radiance;
    accumulation[pixel] = vec4<f32>(sum, select(0.0, 1.0, covered));
}

// The shaded blocks of an adaptive frame (`render::adaptive`), in parts: item `i` of `shade.items`
// items arrives in `accumulation[i]` as the bits of (pixel, samples, first, count) and leaves as
// terms `first .. first + count` of the pixel's estimate with that many samples
// (`render::adaptive::frame::shade_blocks`, the same estimator as `shade_frame`) over `samples`, w = 1: the
// parts of a block sum to its estimate. Up to a vector's `n_samples` the samples are frame 0's;
// a block of more reads `samples / n_samples` frames of `n_samples` (term `j` is term
// `j % n_samples` of frame `j / n_samples`), a part that spans frames taking each frame's terms
// in turn. A block's samples in several parts run side by side rather than one after another in
// one invocation. Each invocation reads and writes its own item only. The footprints are sized for
// the block's samples times the frames the picture averages (`shade.filter_samples` here).
@compute @workgroup_size(64)
fn shade_blocks(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let i = item_index(group, local, groups);
    if (i >= shade.items) {
        return;
    }
    let item = bitcast<vec4<u32>>(accumulation[i]);
    let pixel = item.x;
    let surface = surface_at(i32(pixel % shade.width), i32(pixel / shade.width));
    var radiance = vec3<f32>(0.0);
    if (surface.found) {
        let per_frame = min(item.y, shade.n_samples);
        var j = item.z;
        let end = item.z + item.w;
        while (j < end) {
            let first = j % per_frame;
            let count = min(end - j, per_frame - first);
            radiance += estimate_sum(surface.frame, pixel, j / per_frame, per_frame, first, count, item.y * shade.filter_samples);
            j += count;
        }
        radiance /= f32(item.y);
    }
    accumulation[i] = vec4<f32>(radiance, 1.0);
}
