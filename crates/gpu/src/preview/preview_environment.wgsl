//! The environment's lookups (`envmap`, `render::shade`): directions and map coordinates,
//! bilinear and trilinear reads, and the Phong layers a view blends.

// `envmap::direction`: the unit direction at map coordinates (u, v).
fn env_direction(uv: vec2<f32>) -> vec3<f32> {
    let phi = 2.0 * PI * uv.x;
    let theta = PI * uv.y;
    return vec3<f32>(sin(theta) * cos(phi), sin(theta) * sin(phi), cos(theta));
}

// `render::shade::slice_of`: the slice nearest theta_o = atan2(wo_local.x, wo_local.z).
fn slice_of(frame: ShadingFrame) -> u32 {
    let theta_o = merl_atan2(frame.wo_local.x, frame.wo_local.z);
    let k = max(floor(theta_o / HALF_PI * f32(shade.n_slices) + 0.5), 0.0);
    return min(u32(k), shade.n_slices - 1u);
}

// `envmap::geometry::uv`: map coordinates of a direction (need not be normalized); u in [0, 1),
// 0 on the poles.
fn env_uv(w: vec3<f32>) -> vec2<f32> {
    // atan2 of the two legs rather than acos(z), as on the CPU (precision near the poles).
    let theta = merl_atan2(length(w.xy), w.z);
    var u = merl_atan2(w.y, w.x) / (2.0 * PI);
    if (u < 0.0) {
        u += 1.0;
        // A tiny negative phi rounds to exactly 1, the same meridian as 0.
        if (u >= 1.0) {
            u = 0.0;
        }
    }
    return vec2<f32>(u, theta / PI);
}

// `envmap::EnvMap::texel` of the map whose texels start at `base`, at index `index`.
fn env_texel(base: u32, index: u32) -> vec3<f32> {
    let i = base + 3u * index;
    return vec3<f32>(env_texels[i], env_texels[i + 1u], env_texels[i + 2u]);
}

// `envmap::EnvMap::lookup_uv` of map `m`: bilinear with texel centres at (x + 1/2) / width, u
// wrapping, v clamped to the centres of the first and last rows.
fn env_bilinear(m: u32, uv: vec2<f32>) -> vec3<f32> {
    let map = env_map(m);
    let w = map.x;
    let h = map.y;
    let s = uv.x * f32(w) - 0.5;
    let t = clamp(uv.y * f32(h) - 0.5, 0.0, f32(h - 1u));
    let s0 = floor(s);
    let fx = s - s0;
    let fy = t - floor(t);
    // rem_euclid: WGSL's % truncates towards zero like Rust's, so add w once more.
    let x0 = u32((i32(s0) % i32(w) + i32(w)) % i32(w));
    let x1 = select(x0 + 1u, 0u, x0 + 1u == w);
    let y0 = min(u32(t), h - 1u);
    let y1 = min(y0 + 1u, h - 1u);
    let a = env_texel(map.z, y0 * w + x0);
    let b = env_texel(map.z, y0 * w + x1);
    let c = env_texel(map.z, y1 * w + x0);
    let d = env_texel(map.z, y1 * w + x1);
    let top = a * (1.0 - fx) + b * fx;
    let bottom = c * (1.0 - fx) + d * fx;
    return top * (1.0 - fy) + bottom * fy;
}

// `render::FIS_LOD_BIAS`.
const FIS_LOD_BIAS: f32 = -1.0;

// `render::PREFILTERED_FOOTPRINT_LAYERS`.
const PREFILTERED_FOOTPRINT_LAYERS: f32 = 1.0;

// `envmap::MipChain::lod_solid_angle` for one of `filter_samples` samples (the picture's, over
// its frames) of density `pdf` per unit solid angle, plus `FIS_LOD_BIAS` (`render::shade::shade`):
// max(log4(width height / (filter_samples pdf 2 pi^2)) + FIS_LOD_BIAS, 0), as a difference of
// logarithms (the quotient overflows f32 for tiny densities, where the CPU's f64 does not). A
// density that is not positive stands for the CPU's infinite level: the last.
fn mip_lod(pdf: f32) -> f32 {
    if (!(pdf > 0.0)) {
        return f32(shade.n_levels - 1u);
    }
    let level0 = env_map(shade.mips_first);
    let texels = f32(level0.x) * f32(level0.y);
    return max(0.5 * (log2(texels) - log2(f32(shade.filter_samples)) - log2(pdf * 2.0 * PI * PI)) + FIS_LOD_BIAS, 0.0);
}

// `envmap::MipChain::lookup_uv` in the chain from `shade.mips_first`: bilinear in the two levels
// around `lod` (clamped to the chain), then linear between them.
fn mip_trilinear(uv: vec2<f32>, lod: f32) -> vec3<f32> {
    let last = f32(shade.n_levels - 1u);
    var l = 0.0;
    if (lod > 0.0) {
        l = min(lod, last);
    }
    let l0 = floor(l);
    let t = l - l0;
    let a = env_bilinear(shade.mips_first + u32(l0), uv);
    if (t == 0.0) {
        return a;
    }
    let b = env_bilinear(shade.mips_first + u32(l0) + 1u, uv);
    return a * (1.0 - t) + b * t;
}

// `render::view_layer`: the pixel's Phong layer coordinate, between the view rows' centres.
fn view_layer_coordinate(frame: ShadingFrame) -> f32 {
    let rows = shade.n_view_rows;
    let s = clamp((1.0 - frame.cos_o) * f32(rows) - 0.5, 0.0, f32(rows - 1u));
    let r = min(u32(floor(s)), rows - 1u);
    let t = s - f32(r);
    let a = sampling_tables[shade.view_layers + r];
    if (t > 0.0) {
        return a + (sampling_tables[shade.view_layers + r + 1u] - a) * t;
    }
    return a;
}

// The prefiltered mode's layer coordinate at this pixel in `render::shade::shade`:
// `shade.layer_shift` layers sharper than the view's, at most the one past the sharpest (the
// smooth map itself).
fn pixel_layer(frame: ShadingFrame) -> f32 {
    return min(view_layer_coordinate(frame) + f32(shade.layer_shift), f32(shade.n_layers));
}

// The exponent of layer `k` (`shade.n_layers` past the sharpest), after the view rows.
// No Rust twin: the CPU reads `render::Lighting::exponents` and `render::past_exponent`.
fn layer_exponent_at(k: u32) -> f32 {
    return sampling_tables[shade.view_layers + shade.n_view_rows + k];
}

// `render::exponent_layer`: the layer coordinate of exponent `n`.
fn exponent_layer(n: f32) -> f32 {
    if (!(n > layer_exponent_at(0u))) {
        return 0.0;
    }
    if (n >= layer_exponent_at(shade.n_layers)) {
        return f32(shade.n_layers);
    }
    var k = 0u;
    while (k + 1u < shade.n_layers && layer_exponent_at(k + 1u) <= n) {
        k++;
    }
    let a = log(layer_exponent_at(k));
    return f32(k) + (log(n) - a) / (log(layer_exponent_at(k + 1u)) - a);
}

// `render::shade::footprint_layer`: the layer coordinate of the footprint of one of `n`
// samples of density `pdf`, PREFILTERED_FOOTPRINT_LAYERS sharper.
fn footprint_layer(n: u32, pdf: f32) -> f32 {
    return exponent_layer(2.0 * PI * f32(n) * pdf - 1.0) + PREFILTERED_FOOTPRINT_LAYERS;
}

// The map of layer `k` in `render::shade::layers_lookup`: the Phong layer, or past the sharpest
// the smooth part's level 0 (the first map of the chain fis reads).
fn layer_map(k: u32) -> u32 {
    if (k < shade.n_layers) {
        return shade.layers_first + k;
    }
    return shade.mips_first;
}

// `render::shade::layers_lookup`: the layers at coordinate `x` (the view's, or a sample's
// footprint's where that is broader), blended.
fn layers_bilinear(x_view: f32, x_sample: f32, uv: vec2<f32>) -> vec3<f32> {
    let x = clamp(min(x_view, x_sample), 0.0, f32(shade.n_layers));
    let k = u32(floor(x));
    let t = x - f32(k);
    let a = env_bilinear(layer_map(k), uv);
    if (t > 0.0) {
        let b = env_bilinear(layer_map(k + 1u), uv);
        return a * (1.0 - t) + b * t;
    }
    return a;
}

// What a debug mode shows at a pixel with a shading frame: (index, 1, 0): the sample slice, or
// the prefiltered layer coordinate (-1 without a table).
// No Rust twin: the CPU renderer has no debug views.
fn debug_index(frame: ShadingFrame) -> vec3<f32> {
    if (shade.mode == MODE_DEBUG_SLICE) {
        return vec3<f32>(f32(slice_of(frame)), 1.0, 0.0);
    }
    if (shade.n_view_rows == 0u) {
        return vec3<f32>(-1.0, 1.0, 0.0);
    }
    return vec3<f32>(pixel_layer(frame), 1.0, 0.0);
}
