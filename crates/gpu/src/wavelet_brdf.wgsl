//! WGSL port of `wavelet_brdf::Decoded::eval` (Claustres et al. 2007, sections 5.3-5.4): the
//! BRDF reconstructed from its Haar coefficients at a level of detail, step for step in f32.
//! Compiled after `merl_lookup.wgsl` (for `merl_atan2`); group 0 bindings 2 and 3 hold the asset.
//! `material_brdf` is what the previewer's estimators call: the wavelet when one is bound
//! (`wavelet.enabled`), else the table's nearest lookup with no data as 0.

struct WaveletUniform {
    // `n`, cells per angle of the sphere grid, and `log2 n`.
    side: u32,
    levels: u32,
    // 1 when the estimators read the wavelet, 0 for the table.
    enabled: u32,
    // Level of detail in [0, levels].
    lod: f32,
    // `mu` per channel and `eps` of the log encoding.
    mean: vec3<f32>,
    epsilon: f32,
}

@group(0) @binding(2) var<uniform> wavelet: WaveletUniform;
// One buffer, one binding (`Renderer::new` packs it): the map, per coefficient position (n^2 of
// them) its slice, 0 the shared zero slice; then the zero slice and the stored slices as f32
// bits, each n^2 outgoing cells x 3 channels.
@group(0) @binding(3) var<storage, read> wavelet_words: array<u32>;

struct WaveletBilinear {
    cells: vec4<u32>,
    weights: vec4<f32>,
}

// `wavelet_brdf::Grid::bilinear` for a direction with z >= 0.
fn wavelet_bilinear(w: vec3<f32>) -> WaveletBilinear {
    let theta = merl_atan2(w.z, w.x);
    let phi = merl_atan2(sqrt(w.x * w.x + w.z * w.z), w.y);
    let n = wavelet.side;
    let last = f32(n - 1u);
    let x_row = clamp(phi / PI * f32(n) - 0.5, 0.0, last);
    let x_col = clamp(theta / PI * f32(n) - 0.5, 0.0, last);
    let r0 = min(u32(floor(x_row)), n - 2u);
    let c0 = min(u32(floor(x_col)), n - 2u);
    let tr = x_row - f32(r0);
    let tc = x_col - f32(c0);
    let cell = r0 * n + c0;
    return WaveletBilinear(
        vec4<u32>(cell, cell + 1u, cell + n, cell + n + 1u),
        vec4<f32>((1.0 - tr) * (1.0 - tc), (1.0 - tr) * tc, tr * (1.0 - tc), tr * tc),
    );
}

// Coefficient position `p` of outgoing cell `o` (`wavelet_brdf::Decoded::coefficient`).
fn wavelet_coefficient(p: u32, o: u32) -> vec3<f32> {
    let cells = wavelet.side * wavelet.side;
    let at = cells + (wavelet_words[p] * cells + o) * 3u;
    return bitcast<vec3<f32>>(vec3<u32>(wavelet_words[at], wavelet_words[at + 1u], wavelet_words[at + 2u]));
}

// `wavelet_brdf::Decoded::log_value`: Haar synthesis of incoming cell `i` of outgoing cell `o`
// at the integer level of detail `lod` (`wavelet_brdf::transform::synthesis`).
fn wavelet_log_value(o: u32, i: u32, lod: u32) -> vec3<f32> {
    let n = wavelet.side;
    let r = i / n;
    let c = i % n;
    var sum = wavelet_coefficient(0u, o) / f32(n);
    for (var j = wavelet.levels; j > lod; j--) {
        let block = 1u << j;
        let s = n >> j;
        let ky = r / block;
        let kx = c / block;
        let sr = select(-1.0, 1.0, r % block < block / 2u);
        let sc = select(-1.0, 1.0, c % block < block / 2u);
        let amplitude = 1.0 / f32(block);
        sum += amplitude * (sr * wavelet_coefficient((s + ky) * n + kx, o)
            + sc * wavelet_coefficient(ky * n + s + kx, o)
            + sr * sc * wavelet_coefficient((s + ky) * n + s + kx, o));
    }
    return sum;
}

// `wavelet_brdf::Decoded::eval`.
fn wavelet_eval(wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    if (!(wi.z >= 0.0 && wo.z >= 0.0)) {
        return vec3<f32>(0.0);
    }
    let outgoing = wavelet_bilinear(wo);
    let incoming = wavelet_bilinear(wi);
    let lod = clamp(wavelet.lod, 0.0, f32(wavelet.levels));
    let coarse = u32(floor(lod));
    let blend = lod - f32(coarse);
    var sum = vec3<f32>(0.0);
    for (var a = 0u; a < 4u; a++) {
        for (var b = 0u; b < 4u; b++) {
            let weight = outgoing.weights[a] * incoming.weights[b];
            let o = outgoing.cells[a];
            let i = incoming.cells[b];
            sum += weight * (1.0 - blend) * wavelet_log_value(o, i, coarse);
            if (blend > 0.0) {
                sum += weight * blend * wavelet_log_value(o, i, coarse + 1u);
            }
        }
    }
    return max(wavelet.mean * (exp(sum) - wavelet.epsilon), vec3<f32>(0.0));
}

// The BRDF the estimators read (`render::shade::brdf`), 0 where the table holds no data.
fn material_brdf(wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    if (wavelet.enabled != 0u) {
        return wavelet_eval(wi, wo);
    }
    let value = merl_lookup_nearest(wi, wo);
    return select(vec3<f32>(0.0), value, merl_has_data(value));
}
