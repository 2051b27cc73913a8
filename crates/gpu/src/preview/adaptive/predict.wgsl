//! The prediction of an adaptive frame (`render::adaptive`, "The bandwidth buffer"): group 3, the
//! environment bandwidth and the bandwidth atlas, and each prediction pixel's image bandwidth and
//! variance (entry point `predict_blocks`).

// Group 3: what the prediction of an adaptive frame reads besides the bake (`render::adaptive`,
// "The bandwidth buffer"), set by `Renderer::set_bandwidths`.
struct PredictUniform {
    // Incident directions per prediction (`n_b`), at most the samples per vector.
    n_b: u32,
    // The environment bandwidth's lat-long grid, first in `bandwidth_texels`.
    env_width: u32,
    env_height: u32,
    // The bandwidth atlas after it: `lobes_y` rows of `lobes_x` tiles of `tile x tile` texels,
    // row-major like `bandwidth_atlas::Atlas::data`.
    lobes_x: u32,
    lobes_y: u32,
    tile: u32,
    // Of the render, at the centre: `fov_y / height` (eq. 6).
    radians_per_pixel: f32,
    _pad: u32,
}

@group(3) @binding(0) var<uniform> predict: PredictUniform;

// `render::adaptive::PREDICTION_SALT`: mixed into the seed of the vector each prediction reads.
const PREDICTION_SALT: u32 = 0x9e3779b9u;
// The environment bandwidth (cycles per radian), then the atlas: one buffer, so that the pass
// stays within the storage buffers an adapter offers per stage.
@group(3) @binding(1) var<storage, read> bandwidth_texels: array<f32>;

// `color::luminance` (Rec. 709).
fn luminance(rgb: vec3<f32>) -> f32 {
    return 0.2126 * rgb.x + 0.7152 * rgb.y + 0.0722 * rgb.z;
}

// `render::adaptive::EnvBandwidth::at_uv`: the nearest texel.
fn env_bandwidth(uv: vec2<f32>) -> f32 {
    let x = min(u32(max(uv.x * f32(predict.env_width), 0.0)), predict.env_width - 1u);
    let y = min(u32(max(uv.y * f32(predict.env_height), 0.0)), predict.env_height - 1u);
    return bandwidth_texels[y * predict.env_width + x];
}

// `bandwidth_atlas::Atlas::lookup`'s `column`: floor(x n) clamped to [0, n - 1].
fn atlas_column(x: f32, n: u32) -> u32 {
    return min(u32(max(floor(x * f32(n)), 0.0)), n - 1u);
}

// `bandwidth_atlas::Atlas::lookup`: the bandwidth of the lobe of `wi` towards `wo` (tangent frame),
// the nearest texel: the tile from `wi`'s azimuth and elevation, the texel from `wo` turned into
// the plane of incidence and projected by `bandwidth_atlas::LobeMap::uv`.
fn atlas_lookup(wi: vec3<f32>, wo: vec3<f32>) -> f32 {
    let phi_i = merl_atan2(wi.y, wi.x);
    // rem_euclid(2 pi) of an angle in (-pi, pi].
    let phi = select(phi_i, phi_i + 2.0 * PI, phi_i < 0.0);
    let i = atlas_column(phi / (2.0 * PI), predict.lobes_x);
    let j = atlas_column(1.0 - clamp(wi.z, 0.0, 1.0), predict.lobes_y);
    let s = sin(phi_i);
    let c = cos(phi_i);
    let w = vec3<f32>(c * wo.x + s * wo.y, -s * wo.x + c * wo.y, wo.z);
    let r = min(merl_theta_of(w), HALF_PI) / HALF_PI;
    let rho = length(w.xy);
    var ab = vec2<f32>(0.0);
    if (rho != 0.0) {
        ab = r * w.xy / rho;
    }
    let tx = atlas_column((ab.x + 1.0) / 2.0, predict.tile);
    let ty = atlas_column((1.0 - ab.y) / 2.0, predict.tile);
    let width = predict.lobes_x * predict.tile;
    let base = predict.env_width * predict.env_height;
    return bandwidth_texels[base + (j * predict.tile + ty) * width + i * predict.tile + tx];
}

// `render::adaptive::bandwidth_at_eye`: a distant light's [0, nu_env] through C_c, B_{0, rho}, S,
// C_-c, P_x and T_d' (`001` Fig. 4), |nu_a| of the result.
fn bandwidth_at_eye(nu_env: f32, rho: f32, c: f32, depth: f32, cos_x: f32) -> f32 {
    var nu = vec2<f32>(0.0, nu_env);
    nu = vec2<f32>(nu.x + c * nu.y, nu.y);
    nu = vec2<f32>(nu.x, min(rho, nu.y));
    nu = vec2<f32>(nu.x, -nu.y);
    nu = vec2<f32>(nu.x - c * nu.y, nu.y);
    nu = vec2<f32>(nu.x / cos_x, nu.y);
    nu = vec2<f32>(nu.x, -depth * nu.x + nu.y);
    return abs(nu.y);
}

// `render::adaptive::predict::predict_pixel` at the shadeable pixel (x, y) of G-buffer curvature
// `curvature` (the CPU's, a camera's: `render::adaptive::Geometry`): the image bandwidth (cycles
// per pixel, eq. 5-6) and the variance (eq. 9, or eq. 10 for the prefiltered estimator) from
// the first `n_b` samples of the pixel's vector; (-1, -1) where the pixel is not shadeable.
fn predict_pixel(x: u32, y: u32, curvature: f32) -> vec2<f32> {
    let me = surface_at(i32(x), i32(y));
    if (!me.found) {
        return vec2<f32>(-1.0);
    }
    let hit = me.hit;
    let frame = me.frame;
    let depth = length(shade.eye.xyz - hit.position);
    let pixel = y * shade.width + x;
    let n_b = min(predict.n_b, shade.n_samples);
    let k = slice_of(frame);
    let vector = pcg_hash(pixel ^ pcg_hash(shade.seed ^ PREDICTION_SALT)) % shade.n_vectors;
    let start = (k * shade.n_vectors + vector) * shade.n_samples;
    var weight = 0.0;
    var weighted = 0.0;
    var variance = 0.0;
    for (var j = 0u; j < n_b; j++) {
        let texel = samples[start + j];
        let wi_local = texel.xyz;
        let pdf = texel.w;
        if (!(pdf > 0.0 && wi_local.z > 0.0)) {
            continue;
        }
        let f = luminance(material_brdf(wi_local, frame.wo_local));
        let uv = env_uv(to_world(frame, wi_local));
        let g = luminance(env_bilinear(0u, uv)) * f * wi_local.z;
        let nu_env = env_bandwidth(uv);
        let rho = atlas_lookup(wi_local, frame.wo_local);
        let at_eye = bandwidth_at_eye(nu_env, rho, curvature, depth, frame.cos_o);
        weight += g / pdf;
        weighted += g / pdf * at_eye;
        var spread = nu_env + rho;
        if (shade.mode == MODE_PREFILTERED) {
            spread = 2.0 * rho;
        }
        variance += spread * g * g / pdf;
    }
    var bandwidth = 0.0;
    if (weight > 0.0) {
        bandwidth = weighted / weight * predict.radians_per_pixel;
    }
    return vec2<f32>(bandwidth, variance / f32(n_b));
}

// The bandwidth buffer of an adaptive frame at its prediction pixels
// (`render::adaptive::prediction_pixels`): item `i` of `shade.items` items arrives in
// `accumulation[i]` as the bits of (pixel, its G-buffer curvature as f32, 0, 0) and leaves as
// (bandwidth, variance, 0, 1).
@compute @workgroup_size(64)
fn predict_blocks(
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
    let prediction = predict_pixel(pixel % shade.width, pixel / shade.width, bitcast<f32>(item.y));
    accumulation[i] = vec4<f32>(prediction, 0.0, 1.0);
}
