//! The previewer's shading pass: one frame of the estimators of the `render` crate (its crate
//! documentation is the specification), per pixel of the triangle-index G-buffer that
//! `preview_raster.wgsl` drew, added into an accumulation buffer. Compiled after
//! `merl_lookup.wgsl` and `brdf_wavelet.wgsl`, whose `material_brdf` (group 0: the MERL table's
//! nearest lookup, or the wavelet reconstruction) is the BRDF.
//!
//! Every step is a function named after the CPU's (`render::raster`, `render::shade`, `envmap`),
//! in the same order and with the same branches, so that the two images differ by f32 rounding
//! only: the CPU works in f64. Group 1 is what the scene, material and lighting upload once,
//! group 2 the render.

const PI: f32 = 3.14159265358979;
const HALF_PI: f32 = 1.5707963267948966;

// The host rounds the image up to whole workgroups of this size (`SHADE_WORKGROUP` in Rust; a
// test there checks the two agree).
const SHADE_WORKGROUP: u32 = 8u;

const MODE_REFERENCE: u32 = 0u;
const MODE_FIS: u32 = 1u;
const MODE_PREFILTERED: u32 = 2u;
// Not estimators: write the G-buffer's interpolated (position, triangle) or (normal, covered) of
// each pixel in place of the sum, so that tests can hold visibility to `render::raster` alone.
const MODE_GBUFFER_POSITION: u32 = 3u;
const MODE_GBUFFER_NORMAL: u32 = 4u;
// Debug views, accumulated like the estimators (so that their average is the value) and with the
// environment behind the mesh as in every mode: per covered pixel the interpolated normal; or
// (index, 1, 0) with the prefiltered layer the view-layer table picks (-1 without a table) or
// the sample slice, and (0, 0, 0) where the pixel has no shading frame (black in the picture).
const MODE_DEBUG_NORMAL: u32 = 5u;
const MODE_DEBUG_LAYER: u32 = 6u;
const MODE_DEBUG_SLICE: u32 = 7u;

// `render::raster::GUARD_BAND`: triangles reaching beyond it are clipped on the CPU. (A test in
// Rust checks both constants against `render::raster`.)
const GUARD_BAND: f32 = 4.0;
// 2^`render::raster::SUBPIXEL_BITS`: viewport coordinates snap to 1/256 pixel.
const SUBPIXELS: f32 = 256.0;

// Group 1: the samples, every environment map, the view-layer table and the mesh.

// `render::SampleSet::texels`: (wi_local.xyz, pdf), slice-major, then vector, then sample.
@group(1) @binding(0) var<storage, read> samples: array<vec4<f32>>;
// One lat-long map per entry: (width, height, offset of its first value in `env_texels`, unused).
// Entries 0 .. n_levels are the mip chain (level 0 first), then one per prefiltered layer.
@group(1) @binding(1) var<storage, read> env_maps: array<vec4<u32>>;
// Every map's texels, RGB interleaved and row-major like `envmap::EnvMap::rgb`. Storage rather
// than textures: float32 textures need not be filterable, and doing the bilinear weights by hand
// makes them the CPU's arithmetic.
@group(1) @binding(2) var<storage, read> env_texels: array<f32>;
// `render::Material::view_layers`: each view row's Phong layer coordinate.
@group(1) @binding(3) var<storage, read> view_layers: array<f32>;
// The mesh, as `preview_raster.wgsl` reads it: twelve values per vertex, three indices per
// triangle. Per vertex: the clip-space position with the current camera and the snapped viewport
// x and y in 1/256 pixels (integers, exact in f32 within the guard band; 0 outside the clip
// volume), both as `render::raster` computes them on the CPU, then the position and the normal.
// The CPU's rather than the GPU's own: a GPU may fuse multiply-adds and divide to 2.5 ULP
// (Vulkan allows both), which moves a vertex whose coordinate lies near a rounding tie by a
// sub-pixel step, and a small triangle's interpolation with it.
@group(1) @binding(4) var<storage, read> mesh_vertices: array<f32>;
@group(1) @binding(5) var<storage, read> mesh_indices: array<u32>;
// The CDF tables the estimators sample, f32 as the CPU samples them (`render::SampleSet::tables`,
// `render::Lighting::environment` and the peaks' `sampling`), where `Shade` says they start.
@group(1) @binding(6) var<storage, read> sampling_tables: array<f32>;

// Group 2: the render.

struct Shade {
    // The camera: the eye, and the pixel ray's basis as `render::Camera::ray` builds it,
    // `forward`, `right tan(fov_y / 2) aspect` and `up tan(fov_y / 2)`.
    eye: vec4<f32>,
    ray_forward: vec4<f32>,
    ray_right: vec4<f32>,
    ray_up: vec4<f32>,
    width: u32,
    height: u32,
    seed: u32,
    mode: u32,
    spp: u32,
    n_slices: u32,
    n_vectors: u32,
    n_samples: u32,
    // Mip levels (of `mips_first`'s chain).
    n_levels: u32,
    n_view_rows: u32,
    // Prefiltered layers; the prefiltered estimator reads the layers `layer_shift` layers sharper
    // than the view's (an adaptive frame's shaded blocks: `render::adaptive::Settings`).
    n_layers: u32,
    layer_shift: u32,
    // Maps in `env_maps` (map 0 is level 0 of the environment, whole): the first level of the mip
    // chain the fis estimator reads and the first Phong layer (`render::Lighting::smooth_mips` and
    // `smooth_layers`), and the peaks' level 0 (`NO_MAP` where the environment has none).
    mips_first: u32,
    layers_first: u32,
    peak_map: u32,
    // In `sampling_tables`: the BRDF tables' rows (of half vectors) and sectors (of phi_h); where the row
    // edges `t = 1 - cos theta_h` (R + 1), the slices' marginal CDFs (R + 1 each) and their
    // conditional CDFs (R rows of C + 1 each) start.
    brdf_rows: u32,
    brdf_sectors: u32,
    t_edges: u32,
    brdf_marginal: u32,
    brdf_conditional: u32,
    // Level 0's distribution and the peaks': marginal (H + 1) and conditional (H rows of W + 1)
    // CDFs over map 0's texels.
    env_marginal: u32,
    env_conditional: u32,
    peak_marginal: u32,
    peak_conditional: u32,
}

// `Shade::peak_map` where the environment has no peaks.
const NO_MAP: u32 = 0xffffffffu;

// Its own uniform, at a dynamic offset: one command buffer holds many frames.
struct Frame {
    index: u32,
}

@group(2) @binding(0) var<uniform> shade: Shade;
@group(2) @binding(1) var<uniform> frame: Frame;
// The index plus one of the triangle that covers the pixel centre, 0 where none does.
@group(2) @binding(2) var gbuffer_triangle: texture_2d<u32>;
// Per pixel: the sum of the frames' radiance, and in w whether a triangle covers it.
@group(2) @binding(3) var<storage, read_write> accumulation: array<vec4<f32>>;
// Per pixel: the environment seen along its camera ray, drawn where no triangle covers the pixel
// (`shade_backdrop`, once per camera with the G-buffer).
@group(2) @binding(4) var<storage, read_write> backdrop: array<vec4<f32>>;

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
fn cdf_fraction(first: u32, i: u32, u: f32) -> f32 {
    let c0 = sampling_tables[first + i];
    return min((u - c0) / (sampling_tables[first + i + 1u] - c0), ONE_BELOW);
}

// The width of bin `i` of the CDF table at `sampling_tables[first]`: its probability.
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
fn solid_angle_density(pdf_uv: f32, v: f32) -> f32 {
    let sin_theta = sin(PI * v);
    if (!(sin_theta > 0.0 && pdf_uv > 0.0)) {
        return 0.0;
    }
    return pdf_uv / (2.0 * PI * PI * sin_theta);
}

// The density over (u, v) of texel (x, y): its row's probability times its own within the row,
// over the texel's area.
fn latlong_texel_density(d: LatLong, x: u32, y: u32) -> f32 {
    let size = env_maps[0];
    let p_row = cdf_width(d.marginal, y);
    let p_texel = cdf_width(d.conditional + y * (size.x + 1u), x);
    return p_row * p_texel * f32(size.x) * f32(size.y);
}

// `sampling::LatLong::sample` at `u`.
fn latlong_sample(d: LatLong, u: vec2<f32>) -> LightSample {
    let size = env_maps[0];
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
    let size = env_maps[0];
    let x = min(u32(max(uv.x * f32(size.x), 0.0)), size.x - 1u);
    let y = min(u32(max(uv.y * f32(size.y), 0.0)), size.y - 1u);
    return solid_angle_density(latlong_texel_density(d, x, y), uv.y);
}

// `render::shade::mis_weight`: the balance heuristic.
fn mis_weight(p: f32, q: f32) -> f32 {
    return p / (p + q);
}

// What covers a pixel (`render::raster::Hit`): the world position and the normalized normal
// (zero where it interpolates to zero) at the pixel centre.
struct Hit {
    position: vec3<f32>,
    normal: vec3<f32>,
}

fn mesh_clip(v: u32) -> vec4<f32> {
    let i = 12u * v;
    return vec4<f32>(mesh_vertices[i], mesh_vertices[i + 1u], mesh_vertices[i + 2u], mesh_vertices[i + 3u]);
}

fn mesh_snapped(v: u32) -> vec2<i32> {
    let i = 12u * v + 4u;
    return vec2<i32>(i32(mesh_vertices[i]), i32(mesh_vertices[i + 1u]));
}

fn mesh_position(v: u32) -> vec3<f32> {
    let i = 12u * v + 6u;
    return vec3<f32>(mesh_vertices[i], mesh_vertices[i + 1u], mesh_vertices[i + 2u]);
}

fn mesh_normal(v: u32) -> vec3<f32> {
    let i = 12u * v + 9u;
    return vec3<f32>(mesh_vertices[i], mesh_vertices[i + 1u], mesh_vertices[i + 2u]);
}

// Whether a clip-space vertex lies in the volume `render::raster` clips to
// (`plane_distances` all >= 0): 0 <= z <= w, |x|, |y| <= G w.
fn inside_clip_volume(c: vec4<f32>) -> bool {
    let g = GUARD_BAND * c.w;
    return c.z >= 0.0 && c.w - c.z >= 0.0 && c.x + g >= 0.0 && g - c.x >= 0.0 && c.y + g >= 0.0 && g - c.y >= 0.0;
}

// A signed 64-bit integer, two's complement: the edge functions' exact values. Snapped
// coordinates relative to the pixel centre stay below 2^25 in magnitude (within the guard band of
// an image of up to 16384 pixels), so the products need 51 bits: f32 would round them, and a
// sliver's small edge function is the difference of two large products. (Also the adaptive
// frame's allocation's sums: `preview_adaptive.wgsl`.)
struct Wide {
    hi: u32,
    lo: u32,
}

fn wide_add(a: Wide, b: Wide) -> Wide {
    let lo = a.lo + b.lo;
    return Wide(a.hi + b.hi + select(0u, 1u, lo < a.lo), lo);
}

fn wide_negate(a: Wide) -> Wide {
    let lo = ~a.lo + 1u;
    return Wide(~a.hi + select(0u, 1u, lo == 0u), lo);
}

// a b exactly, for |a|, |b| < 2^31: the magnitude from 16-bit halves, then the sign.
fn wide_product(a: i32, b: i32) -> Wide {
    let ua = u32(abs(a));
    let ub = u32(abs(b));
    let a0 = ua & 0xffffu;
    let a1 = ua >> 16u;
    let b0 = ub & 0xffffu;
    let b1 = ub >> 16u;
    let low = a0 * b0;
    // Each term is below 2^31, so the sum does not wrap.
    let middle = a0 * b1 + a1 * b0;
    let lo = low + (middle << 16u);
    let magnitude = Wide(a1 * b1 + (middle >> 16u) + select(0u, 1u, lo < low), lo);
    if ((a < 0) != (b < 0)) {
        return wide_negate(magnitude);
    }
    return magnitude;
}

// The nearest f32, to within two roundings (relative error below 2^-23): the high word is exact
// (below 2^24), and when it is not zero the low word's rounding is 2^-25 of the value at most.
fn wide_to_f32(a: Wide) -> f32 {
    if ((a.hi & 0x80000000u) != 0u) {
        let m = wide_negate(a);
        return -(f32(m.hi) * 4294967296.0 + f32(m.lo));
    }
    return f32(a.hi) * 4294967296.0 + f32(a.lo);
}

// The edge function of `render::raster::for_each_covered` for the edge from `a` to `b`, both
// relative to the point it is evaluated at: their 2D cross product, exactly.
fn edge(a: vec2<i32>, b: vec2<i32>) -> Wide {
    return wide_add(wide_product(a.x, b.y), wide_negate(wide_product(a.y, b.x)));
}

// Steps 5 and 6 of `render::raster` at pixel (x, y) for a triangle drawn whole (no vertex outside
// the clip volume): screen-space barycentrics from the snapped vertices' edge functions at the
// pixel centre, exact as on the CPU and divided in f32, then perspective-correct weights
// (b_i / w_i) / sum_j (b_j / w_j).
fn snapped_weights(snapped: array<vec2<i32>, 3>, w: vec3<f32>, x: u32, y: u32) -> vec3<f32> {
    let centre = vec2<i32>(i32(SUBPIXELS) * i32(x), i32(SUBPIXELS) * i32(y)) + i32(SUBPIXELS) / 2;
    let a = snapped[0] - centre;
    let b = snapped[1] - centre;
    let c = snapped[2] - centre;
    // Edge k is opposite vertex k; its function is vertex k's weight.
    let e = array<Wide, 3>(edge(b, c), edge(c, a), edge(a, b));
    let area = wide_to_f32(wide_add(wide_add(e[0], e[1]), e[2]));
    let bary = vec3<f32>(wide_to_f32(e[0]), wide_to_f32(e[1]), wide_to_f32(e[2])) / area;
    let q = bary / w;
    return q / (q.x + q.y + q.z);
}

// The weights of a triangle the CPU clips (a vertex behind the near plane, beyond the far plane
// or the guard band): those of the point where the pixel ray meets the triangle's plane. The
// CPU interpolates the clipped polygon's snapped vertices, which comes to the same up to that
// snapping: such triangles are rare in a preview (the near plane is at 1% of the distance).
fn ray_weights(p: array<vec3<f32>, 3>, x: u32, y: u32) -> vec3<f32> {
    let eye = shade.eye.xyz;
    let dir = camera_ray(x, y);
    let normal = cross(p[1] - p[0], p[2] - p[0]);
    let hit = eye + dot(p[0] - eye, normal) / dot(dir, normal) * dir;
    let area = dot(normal, normal);
    return vec3<f32>(
        dot(cross(p[1] - hit, p[2] - hit), normal),
        dot(cross(p[2] - hit, p[0] - hit), normal),
        dot(cross(p[0] - hit, p[1] - hit), normal),
    ) / area;
}

// `render::raster`'s hit at pixel (x, y) on triangle `t`: position and normal interpolated with
// the weights above, the normal normalized unless it is zero (glam's normalize_or_zero).
fn interpolate_hit(t: u32, x: u32, y: u32) -> Hit {
    var p: array<vec3<f32>, 3>;
    var n: array<vec3<f32>, 3>;
    var snapped: array<vec2<i32>, 3>;
    var w: vec3<f32>;
    var whole = true;
    for (var k = 0u; k < 3u; k++) {
        let v = mesh_indices[3u * t + k];
        p[k] = mesh_position(v);
        n[k] = mesh_normal(v);
        snapped[k] = mesh_snapped(v);
        let clip = mesh_clip(v);
        w[k] = clip.w;
        whole = whole && inside_clip_volume(clip);
    }
    var weights: vec3<f32>;
    if (whole) {
        weights = snapped_weights(snapped, w, x, y);
    } else {
        weights = ray_weights(p, x, y);
    }
    let position = weights.x * p[0] + weights.y * p[1] + weights.z * p[2];
    let normal = weights.x * n[0] + weights.y * n[1] + weights.z * n[2];
    let length_squared = dot(normal, normal);
    if (!(length_squared > 0.0)) {
        return Hit(position, vec3<f32>(0.0));
    }
    return Hit(position, normal / sqrt(length_squared));
}

struct ShadingFrame {
    t: vec3<f32>,
    b: vec3<f32>,
    n: vec3<f32>,
    cos_o: f32,
    // (sin theta_o, 0, cos theta_o): the frame of the baked samples, phi_o = 0.
    wo_local: vec3<f32>,
}

// `render::shade::duff_tangent`: the first tangent of Duff et al. 2017's branchless basis. The
// sign is read from the bit so that n.z = -0 takes -1, as Rust's copysign does.
fn duff_tangent(n: vec3<f32>) -> vec3<f32> {
    let s = select(1.0, -1.0, (bitcast<u32>(n.z) & 0x80000000u) != 0u);
    let a = -1.0 / (s + n.z);
    return vec3<f32>(1.0 + s * n.x * n.x * a, s * n.x * n.y * a, -s * n.x);
}

// `render::shade::ShadingFrame::new`; `valid` is false where the pixel is black: the normal
// interpolated to zero or faces away from the eye (silhouettes).
struct MaybeFrame {
    valid: bool,
    frame: ShadingFrame,
}

fn shading_frame(hit: Hit) -> MaybeFrame {
    var none: MaybeFrame;
    none.valid = false;
    let n = hit.normal;
    if (all(n == vec3<f32>(0.0))) {
        return none;
    }
    let wo = normalize(shade.eye.xyz - hit.position);
    let cos_o = dot(n, wo);
    if (!(cos_o > 0.0)) {
        return none;
    }
    let tangent = wo - cos_o * n;
    let sin_o = length(tangent);
    var t: vec3<f32>;
    if (sin_o < 1e-6) {
        // wo along the normal: any tangent will do, as long as it is the CPU's.
        t = duff_tangent(n);
    } else {
        t = tangent / sin_o;
    }
    let b = cross(n, t);
    let wo_local = normalize(vec3<f32>(sin_o, 0.0, cos_o));
    return MaybeFrame(true, ShadingFrame(t, b, n, cos_o, wo_local));
}

// A pixel of the G-buffer (`render::adaptive::pixels`): its hit and shading frame where it is
// shadeable (inside the image, covered, with a frame).
struct Surface {
    found: bool,
    hit: Hit,
    frame: ShadingFrame,
}

fn surface_at(x: i32, y: i32) -> Surface {
    var none: Surface;
    none.found = false;
    if (x < 0 || y < 0 || x >= i32(shade.width) || y >= i32(shade.height)) {
        return none;
    }
    let t = textureLoad(gbuffer_triangle, vec2<i32>(x, y), 0).x;
    if (t == 0u) {
        return none;
    }
    let hit = interpolate_hit(t - 1u, u32(x), u32(y));
    let maybe = shading_frame(hit);
    if (!maybe.valid) {
        return none;
    }
    return Surface(true, hit, maybe.frame);
}

fn to_world(frame: ShadingFrame, local: vec3<f32>) -> vec3<f32> {
    return local.x * frame.t + local.y * frame.b + local.z * frame.n;
}

fn to_local(frame: ShadingFrame, world: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(dot(world, frame.t), dot(world, frame.b), dot(world, frame.n));
}

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

fn env_texel(base: u32, index: u32) -> vec3<f32> {
    let i = base + 3u * index;
    return vec3<f32>(env_texels[i], env_texels[i + 1u], env_texels[i + 2u]);
}

// `envmap::EnvMap::lookup_uv` of map `m`: bilinear with texel centres at (x + 1/2) / width, u
// wrapping, v clamped to the centres of the first and last rows.
fn env_bilinear(m: u32, uv: vec2<f32>) -> vec3<f32> {
    let map = env_maps[m];
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

// `envmap::MipChain::lod_solid_angle` for one of `spp` samples of density `pdf` per unit solid
// angle: max(log4(width height / (spp pdf 2 pi^2)), 0), as a difference of logarithms (the
// quotient overflows f32 for tiny densities, where the CPU's f64 does not). A density that is not
// positive stands for the CPU's infinite level: the last.
fn mip_lod(pdf: f32) -> f32 {
    if (!(pdf > 0.0)) {
        return f32(shade.n_levels - 1u);
    }
    let level0 = env_maps[shade.mips_first];
    let texels = f32(level0.x) * f32(level0.y);
    return max(0.5 * (log2(texels) - log2(f32(shade.spp)) - log2(pdf * 2.0 * PI * PI)), 0.0);
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
    let a = view_layers[r];
    if (t > 0.0) {
        return a + (view_layers[r + 1u] - a) * t;
    }
    return a;
}

// The Phong layers the prefiltered estimator blends at this pixel: `shade.layer_shift` layers
// sharper than the view's coordinate, the sharpest at most; (first layer, its weight's
// complement t) as `render::shade` blends them: (1 - t) layer k + t layer k + 1.
struct LayerBlend {
    k: u32,
    t: f32,
}

fn layer_blend(frame: ShadingFrame) -> LayerBlend {
    let x = min(view_layer_coordinate(frame) + f32(shade.layer_shift), f32(shade.n_layers - 1u));
    let k = u32(floor(x));
    return LayerBlend(k, x - f32(k));
}

// The blended layers at `uv`.
fn layers_bilinear(blend: LayerBlend, uv: vec2<f32>) -> vec3<f32> {
    let a = env_bilinear(shade.layers_first + blend.k, uv);
    if (blend.t > 0.0) {
        let b = env_bilinear(shade.layers_first + min(blend.k + 1u, shade.n_layers - 1u), uv);
        return a * (1.0 - blend.t) + b * blend.t;
    }
    return a;
}

// What a debug mode shows at a pixel with a shading frame: (index, 1, 0): the sample slice, or
// the prefiltered layer coordinate (-1 without a table).
fn debug_index(frame: ShadingFrame) -> vec3<f32> {
    if (shade.mode == MODE_DEBUG_SLICE) {
        return vec3<f32>(f32(slice_of(frame)), 1.0, 0.0);
    }
    if (shade.n_view_rows == 0u) {
        return vec3<f32>(-1.0, 1.0, 0.0);
    }
    let blend = layer_blend(frame);
    return vec3<f32>(f32(blend.k) + blend.t, 1.0, 0.0);
}

// One frame's estimate at a covered pixel: 1 / spp of `estimate_sum` over its spp terms.
fn estimate(frame: ShadingFrame, pixel: u32, f: u32, spp: u32) -> vec3<f32> {
    return estimate_sum(frame, pixel, f, spp, 0u, spp) / f32(spp);
}

// The light the two strategies of multiple importance sampling share in this mode
// (`render::shade`): level 0 whole in the reference mode, the peaks in the filtered modes;
// `valid` is false where a filtered mode's environment has no peaks.
struct SampledLight {
    valid: bool,
    map: u32,
    distribution: LatLong,
}

fn sampled_light() -> SampledLight {
    if (shade.mode == MODE_REFERENCE) {
        return SampledLight(true, 0u, LatLong(shade.env_marginal, shade.env_conditional));
    }
    return SampledLight(shade.peak_map != NO_MAP, shade.peak_map, LatLong(shade.peak_marginal, shade.peak_conditional));
}

// The sum of terms `first .. first + count` of the pixel's `spp` in frame `f`
// (`render::shade::shade`): term `j` is the BRDF's sample at point `base + j` of the pixel's
// BRDF sequence and, where the mode samples a light, the light's at the same point of its own.
fn estimate_sum(frame: ShadingFrame, pixel: u32, f: u32, spp: u32, first: u32, count: u32) -> vec3<f32> {
    let k = slice_of(frame);
    let range = sample_range(pixel, f, spp);
    let base = range.x * shade.n_samples + range.y;
    let words = pixel_words(pixel);
    let light = sampled_light();
    var blend = LayerBlend(0u, 0.0);
    if (shade.mode == MODE_PREFILTERED) {
        blend = layer_blend(frame);
    }
    var sum = vec3<f32>(0.0);
    for (var j = first; j < first + count; j++) {
        let index = base + j;
        let s = brdf_sample(k, sequence_point(words.xy, index));
        if (s.pdf > 0.0 && s.wi.z > 0.0) {
            let brdf = material_brdf(s.wi, frame.wo_local);
            // No data counts as 0; the CPU skips zeros too.
            if (any(brdf != vec3<f32>(0.0))) {
                let uv = env_uv(to_world(frame, s.wi));
                if (shade.mode == MODE_FIS) {
                    sum += brdf * mip_trilinear(uv, mip_lod(s.pdf)) * (s.wi.z / s.pdf);
                } else if (shade.mode == MODE_PREFILTERED) {
                    sum += brdf * layers_bilinear(blend, uv) * (s.wi.z / s.pdf);
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

// `render::Camera::ray`: the ray from the eye through the centre of pixel (x, y), row 0 at the
// top.
fn camera_ray(x: u32, y: u32) -> vec3<f32> {
    let x_ndc = 2.0 * (f32(x) + 0.5) / f32(shade.width) - 1.0;
    let y_ndc = 1.0 - 2.0 * (f32(y) + 0.5) / f32(shade.height);
    return normalize(shade.ray_forward.xyz + x_ndc * shade.ray_right.xyz + y_ndc * shade.ray_up.xyz);
}

// The environment along every pixel's camera ray (`render::render`'s background), for the frames
// of a camera: the same in each of them, so drawn once (`Renderer::rasterize`).
@compute @workgroup_size(SHADE_WORKGROUP, SHADE_WORKGROUP)
fn shade_backdrop(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= shade.width || gid.y >= shade.height) {
        return;
    }
    backdrop[gid.y * shade.width + gid.x] = vec4<f32>(env_bilinear(0u, env_uv(camera_ray(gid.x, gid.y))), 0.0);
}

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
        radiance = backdrop[pixel].xyz;
    }
    let sum = accumulation[pixel].xyz + radiance;
    accumulation[pixel] = vec4<f32>(sum, select(0.0, 1.0, covered));
}

// The item of invocation `local` of workgroup `group` in a list of items (`shade_blocks`,
// `predict_blocks`) dispatched as a power of two of workgroups (`Renderer::run_items`): the
// workgroups take their runs of 64 items in bit-reversed order. A driver that hands each thread
// a contiguous range of workgroups (lavapipe does) then gives every thread an even share of any
// contiguous run of items: an adaptive frame's shaded blocks come level by level, and a coarse
// level's get many times the samples of a fine level's.
fn item_index(group: vec3<u32>, local: u32, groups: vec3<u32>) -> u32 {
    let g = group.y * groups.x + group.x;
    let bits = countTrailingZeros(groups.x * groups.y);
    var run = 0u;
    if (bits > 0u) {
        run = reverseBits(g) >> (32u - bits);
    }
    return run * 64u + local;
}

// The shaded blocks of an adaptive frame (`render::adaptive`), in parts: item `i` of `shade.spp`
// items arrives in `accumulation[i]` as the bits of (pixel, samples, first, count) and leaves as
// terms `first .. first + count` of the pixel's estimate with that many samples
// (`render::adaptive`'s shading, the same estimator as `shade_frame`) over `samples`, w = 1: the
// parts of a block sum to its estimate. Up to a vector's `n_samples` the samples are frame 0's;
// a block of more reads `samples / n_samples` frames of `n_samples` (term `j` is term
// `j % n_samples` of frame `j / n_samples`), a part that spans frames taking each frame's terms
// in turn. A block's samples in several parts run side by side rather than one after another in
// one invocation. Each invocation reads and writes its own item only.
@compute @workgroup_size(64)
fn shade_blocks(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let i = item_index(group, local, groups);
    if (i >= shade.spp) {
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
            radiance += estimate_sum(surface.frame, pixel, j / per_frame, per_frame, first, count);
            j += count;
        }
        radiance /= f32(item.y);
    }
    accumulation[i] = vec4<f32>(radiance, 1.0);
}

// Group 3: what the prediction of an adaptive frame reads besides the bake (`render::adaptive`,
// "The bandwidth buffer"), set by `Renderer::set_bandwidths`.
struct Predict {
    // Incident directions per prediction (`n_b`), at most the samples per vector.
    n_b: u32,
    // The environment bandwidth's lat-long grid, first in `bandwidth_texels`.
    env_width: u32,
    env_height: u32,
    // The BRDF atlas after it: `lobes_y` rows of `lobes_x` tiles of `tile x tile` texels,
    // row-major like `brdf_atlas::Atlas::data`.
    lobes_x: u32,
    lobes_y: u32,
    tile: u32,
    // Of the render, at the centre: `fov_y / height` (eq. 6).
    radians_per_pixel: f32,
    _pad: u32,
}

@group(3) @binding(0) var<uniform> predict: Predict;
// The environment bandwidth (cycles per radian), then the atlas: one buffer, so that the pass
// stays within the storage buffers an adapter offers per stage.
@group(3) @binding(1) var<storage, read> bandwidth_texels: array<f32>;

// `merl::luminance` and `envmap::luminance` (Rec. 709).
fn luminance(rgb: vec3<f32>) -> f32 {
    return 0.2126 * rgb.x + 0.7152 * rgb.y + 0.0722 * rgb.z;
}

// `render::adaptive::EnvBandwidth::at_uv`: the nearest texel.
fn env_bandwidth(uv: vec2<f32>) -> f32 {
    let x = min(u32(max(uv.x * f32(predict.env_width), 0.0)), predict.env_width - 1u);
    let y = min(u32(max(uv.y * f32(predict.env_height), 0.0)), predict.env_height - 1u);
    return bandwidth_texels[y * predict.env_width + x];
}

// `brdf_atlas::Atlas::lookup`'s `column`: floor(x n) clamped to [0, n - 1].
fn atlas_column(x: f32, n: u32) -> u32 {
    return min(u32(max(floor(x * f32(n)), 0.0)), n - 1u);
}

// `brdf_atlas::Atlas::lookup`: the bandwidth of the lobe of `wi` towards `wo` (tangent frame),
// the nearest texel: the tile from `wi`'s azimuth and elevation, the texel from `wo` turned into
// the plane of incidence and projected by `brdf_atlas::LobeMap::uv`.
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

// `render::adaptive::predict_pixel` at the shadeable pixel (x, y) of G-buffer curvature
// `curvature` (the CPU's, a camera's: `render::adaptive::Geometry`): the image bandwidth (cycles
// per pixel, eq. 5-6) and the variance (eq. 9, or eq. 10 for the pre-convolved estimator) from
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
    let vector = pcg_hash(pixel ^ pcg_hash(shade.seed ^ 0x9e3779b9u)) % shade.n_vectors;
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
// (`render::adaptive::prediction_pixels`): item `i` of `shade.spp` items arrives in
// `accumulation[i]` as the bits of (pixel, its G-buffer curvature as f32, 0, 0) and leaves as
// (bandwidth, variance, 0, 1).
@compute @workgroup_size(64)
fn predict_blocks(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let i = item_index(group, local, groups);
    if (i >= shade.spp) {
        return;
    }
    let item = bitcast<vec4<u32>>(accumulation[i]);
    let pixel = item.x;
    let prediction = predict_pixel(pixel % shade.width, pixel / shade.width, bitcast<f32>(item.y));
    accumulation[i] = vec4<f32>(prediction, 0.0, 1.0);
}
