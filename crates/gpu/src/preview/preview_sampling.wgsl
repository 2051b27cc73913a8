//! The estimators' sampling (the `render` crate's "Samples"): each pixel's Owen-scrambled Sobol'
//! points (`render::pixel_sequences`, `point`), the baked tables' directions and densities
//! (`importance::Slice`), the environment's lat-long distribution (`sampling::LatLong`) and the
//! balance heuristic.

// `render::pcg_hash`: Jarzynski and Olano 2020. WGSL's u32 arithmetic wraps like Rust's
// wrapping_*, so the words are the CPU's bit for bit.
fn pcg_hash(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// `render::sample_range`: (vector, first sample) of pixel `pixel` in frame `f`. The seed is hashed
// before it meets the frame, so that renders with small seeds do not share their frames' words.
fn sample_range(pixel: u32, f: u32, spp: u32) -> vec2<u32> {
    let per_vector = shade.n_samples / spp;
    let chunks = shade.n_vectors * per_vector;
    let h = pcg_hash(pixel ^ pcg_hash(shade.seed));
    let chunk = (h % chunks + f % chunks) % chunks;
    return vec2<u32>(chunk / per_vector, (chunk % per_vector) * spp);
}

// `render::pixel_sequences`' salt.
const SEQUENCE_SALT: u32 = 0x6a09e667u;

// `sampling::OwenSobol2D`'s nested uniform scrambling of the bits of `v` (pbrt-v4's
// FastOwenScrambler): u32 arithmetic that wraps as the CPU's does.
fn owen_scramble(value: u32, seed: u32) -> u32 {
    var v = reverseBits(value);
    v ^= v * 0x3d20adeau;
    v += seed;
    v *= (seed >> 16u) | 1u;
    v ^= v * 0x05526c56u;
    v ^= v * 0x53a22864u;
    return reverseBits(v);
}

// `sampling::OwenSobol2D`'s second Sobol' dimension.
fn sobol_dim1(i: u32) -> u32 {
    var index = i;
    var result = 0u;
    var v = 0x80000000u;
    while (index != 0u) {
        if ((index & 1u) != 0u) {
            result ^= v;
        }
        index >>= 1u;
        v ^= v >> 1u;
    }
    return result;
}

// `render::pixel_sequences`: the scrambling words of the pixel's two sequences, the BRDF's in
// xy, the light's in zw.
fn pixel_words(pixel: u32) -> vec4<u32> {
    let w0 = pcg_hash(pixel ^ pcg_hash(shade.seed ^ SEQUENCE_SALT));
    let w1 = pcg_hash(w0);
    let w2 = pcg_hash(w1);
    return vec4<u32>(w0, w1, w2, pcg_hash(w2));
}

// `render::point`: point `index` of the sequence scrambled by `words`, the top 24 bits of each
// coordinate (exact in f32).
fn sequence_point(words: vec2<u32>, index: u32) -> vec2<f32> {
    let x = owen_scramble(reverseBits(index), words.x);
    let y = owen_scramble(sobol_dim1(index), words.y);
    return vec2<f32>(f32(x >> 8u), f32(y >> 8u)) / 16777216.0;
}

// The largest f32 below 1 (`sampling::ONE_MINUS_EPSILON` in f32).
const ONE_BELOW: f32 = 0.99999994;

// The bin of the CDF table of `n` bins at `sampling_tables[first]` that `u` (in [0, 1)) falls in: the
// last edge at most `u`, as `sampling::Distribution1D::sample` finds it, so a bin of zero width
// is never taken.
fn cdf_bin(first: u32, n: u32, u: f32) -> u32 {
    var lo = 0u;
    var hi = n;
    while (hi - lo > 1u) {
        let mid = (lo + hi) / 2u;
        if (sampling_tables[first + mid] <= u) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    return lo;
}

// Where `u` lies within bin `i` of the CDF table at `sampling_tables[first]`, in [0, 1).
// The fraction `t` of `sampling::Distribution1D::sample`.
fn cdf_fraction(first: u32, i: u32, u: f32) -> f32 {
    let c0 = sampling_tables[first + i];
    return min((u - c0) / (sampling_tables[first + i + 1u] - c0), ONE_BELOW);
}

// The width of bin `i` of the CDF table at `sampling_tables[first]`: its probability.
// `sampling::distribution1d::Piecewise::bin_pdf` over the bin count.
fn cdf_width(first: u32, i: u32) -> f32 {
    return sampling_tables[first + i + 1u] - sampling_tables[first + i];
}

// A direction and its density per unit solid angle.
struct DirectionSample {
    wi: vec3<f32>,
    pdf: f32,
}

// The outgoing direction of slice `k` (`importance::Slice::wo`): theta_o = k / S pi / 2.
fn slice_wo(k: u32) -> vec3<f32> {
    let theta_o = f32(k) / f32(shade.n_slices) * HALF_PI;
    return vec3<f32>(sin(theta_o), 0.0, cos(theta_o));
}

// `importance::Slice::h_density` of cell (iu, iv) of slice `k`'s tables: the cell's probability
// over its solid angle of half vectors.
fn h_density(k: u32, iv: u32, iu: u32) -> f32 {
    let rows = shade.brdf_rows;
    let sectors = shade.brdf_sectors;
    let row_width = sampling_tables[shade.t_edges + iv + 1u] - sampling_tables[shade.t_edges + iv];
    let p_row = cdf_width(shade.brdf_marginal + k * (rows + 1u), iv);
    let p_cell = cdf_width(shade.brdf_conditional + (k * rows + iv) * (sectors + 1u), iu);
    return p_row * p_cell / (row_width * 2.0 * PI / f32(sectors));
}

// `importance::Slice::sample` of slice `k` at `u`.
fn brdf_sample(k: u32, u: vec2<f32>) -> DirectionSample {
    let rows = shade.brdf_rows;
    let sectors = shade.brdf_sectors;
    let marginal = shade.brdf_marginal + k * (rows + 1u);
    let iv = cdf_bin(marginal, rows, u.y);
    let fv = cdf_fraction(marginal, iv, u.y);
    let conditional = shade.brdf_conditional + (k * rows + iv) * (sectors + 1u);
    let iu = cdf_bin(conditional, sectors, u.x);
    let fu = cdf_fraction(conditional, iu, u.x);
    let t0 = sampling_tables[shade.t_edges + iv];
    let t = t0 + fv * (sampling_tables[shade.t_edges + iv + 1u] - t0);
    let phi = 2.0 * PI * (f32(iu) + fu) / f32(sectors);
    let h = vec3<f32>(sqrt(max(t * (2.0 - t), 0.0)) * vec2<f32>(cos(phi), sin(phi)), 1.0 - t);
    let wo = slice_wo(k);
    let wo_h = dot(wo, h);
    if (!(wo_h > 0.0)) {
        return DirectionSample(vec3<f32>(0.0), 0.0);
    }
    return DirectionSample(2.0 * wo_h * h - wo, h_density(k, iv, iu) / (4.0 * wo_h));
}

// `importance::Slice::pdf` of slice `k` at `wi` (tangent frame).
fn brdf_pdf(k: u32, wi: vec3<f32>) -> f32 {
    let wo = slice_wo(k);
    let sum = wi + wo;
    let len = length(sum);
    if (!(len > 0.0)) {
        return 0.0;
    }
    let h = sum / len;
    let wo_h = dot(wo, h);
    if (!(h.z > 0.0 && wo_h > 0.0)) {
        return 0.0;
    }
    let t = (h.x * h.x + h.y * h.y) / (1.0 + h.z);
    // `importance::HalfVectorRows::row_of`: the edges 1 ..= R at most t, counted, at most R - 1.
    var lo = 0u;
    var hi = shade.brdf_rows;
    while (lo < hi) {
        let mid = (lo + hi) / 2u;
        if (sampling_tables[shade.t_edges + 1u + mid] <= t) {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    let iv = min(lo, shade.brdf_rows - 1u);
    var phi = merl_atan2(h.y, h.x);
    if (phi < 0.0) {
        phi += 2.0 * PI;
    }
    let iu = min(u32(min(phi / (2.0 * PI), ONE_BELOW) * f32(shade.brdf_sectors)), shade.brdf_sectors - 1u);
    return h_density(k, iv, iu) / (4.0 * wo_h);
}

// A lat-long distribution over map 0's texels in `sampling_tables` (`sampling::LatLong`).
struct LatLong {
    marginal: u32,
    conditional: u32,
}

// A point of the map and its density per unit solid angle.
struct LightSample {
    uv: vec2<f32>,
    pdf: f32,
}

// `pdf_uv / (2 pi^2 sin(pi v))`, 0 where sin(pi v) is not positive.
// `sampling::latlong::solid_angle_density`.
fn solid_angle_density(pdf_uv: f32, v: f32) -> f32 {
    let sin_theta = sin(PI * v);
    if (!(sin_theta > 0.0 && pdf_uv > 0.0)) {
        return 0.0;
    }
    return pdf_uv / (2.0 * PI * PI * sin_theta);
}

// The density over (u, v) of texel (x, y): its row's probability times its own within the row,
// over the texel's area.
// `sampling::Distribution2D::pdf`.
fn latlong_texel_density(d: LatLong, x: u32, y: u32) -> f32 {
    let size = env_map(0);
    let p_row = cdf_width(d.marginal, y);
    let p_texel = cdf_width(d.conditional + y * (size.x + 1u), x);
    return p_row * p_texel * f32(size.x) * f32(size.y);
}

// `sampling::LatLong::sample` at `u`.
fn latlong_sample(d: LatLong, u: vec2<f32>) -> LightSample {
    let size = env_map(0);
    let y = cdf_bin(d.marginal, size.y, u.y);
    let fy = cdf_fraction(d.marginal, y, u.y);
    let row = d.conditional + y * (size.x + 1u);
    let x = cdf_bin(row, size.x, u.x);
    let fx = cdf_fraction(row, x, u.x);
    let uv = vec2<f32>((f32(x) + fx) / f32(size.x), (f32(y) + fy) / f32(size.y));
    return LightSample(uv, solid_angle_density(latlong_texel_density(d, x, y), uv.y));
}

// `sampling::LatLong::pdf` at `uv` (in [0, 1]^2).
fn latlong_pdf(d: LatLong, uv: vec2<f32>) -> f32 {
    let size = env_map(0);
    let x = min(u32(max(uv.x * f32(size.x), 0.0)), size.x - 1u);
    let y = min(u32(max(uv.y * f32(size.y), 0.0)), size.y - 1u);
    return solid_angle_density(latlong_texel_density(d, x, y), uv.y);
}

// `render::shade::mis_weight`: the balance heuristic.
fn mis_weight(p: f32, q: f32) -> f32 {
    return p / (p + q);
}
