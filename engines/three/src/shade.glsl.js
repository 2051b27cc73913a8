// The estimators of the `render` crate (its crate documentation is the specification) in GLSL ES
// 3.0, for WebGL 2: a port of the shading module of `crates/gpu/src/preview` (`preview_shade.wgsl` and the WGSL files
// `gpu::wgsl` lists for it, `merl_lookup.wgsl` among them), function
// for function, each named after its WGSL and Rust twin, in the same order and with the same
// branches, so that a pixel differs from `brdf-preview`'s by f32 rounding only. The inputs are
// the engine textures of a bake (`data-schema/engine-textures.md`), read with texelFetch: no
// filtering by the hardware, the bilinear weights computed as the CPU computes them.
//
// Only the reference (mode 0) and prefiltered (mode 2) estimators; the debug and adaptive modes of
// the WGSL stay in the previewer. One estimator is this engine's own, with no twin: the split
// estimator (split_estimate, compiled where SPLIT is defined; split.js says what it draws), the
// live mode's first frame.

export const COMMON = /* glsl */ `
precision highp float;
precision highp int;
precision highp sampler2D;
precision highp sampler3D;
precision highp sampler2DArray;

// The output, under the name three's chunks write (it declares it only for GLSL ES 1.0 shaders).
layout(location = 0) out highp vec4 pc_fragColor;
#define gl_FragColor pc_fragColor

const float PI = 3.14159265358979;
const float HALF_PI = 1.5707963267948966;
// The largest f32 below 1 (sampling::ONE_MINUS_EPSILON in f32).
const float ONE_BELOW = 0.99999994;
// The most layers a bake's engine textures may hold (the loader's check on the exponents).
#define MAX_LAYERS 64
// render::PREFILTERED_FOOTPRINT_LAYERS.
const float PREFILTERED_FOOTPRINT_LAYERS = 1.0;

// engine-environment.ktx2: layer 0 the environment's level 0, layer 1 its peaks.
uniform sampler2DArray uEnvironment;
// The environment's frame (brdf-preview's: +z up, phi from +x towards +y) from the world's:
// identity in brdf-preview's orientation; in three's, the turn and mirror that make env_uv read
// the texel three's equirectUv reads, after the scene's environment (or background) rotation.
uniform mat3 uEnvFromWorld;
// 2^EV: brdf-preview's exposure (PREVIEW_OUTPUT), or a scale of the linear radiance.
uniform float uExposure;

// merl_lookup.wgsl's merl_atan2: atan2(0, 0) is 0, as Rust's.
float merl_atan2(float y, float x) {
    if (x == 0.0 && y == 0.0) {
        return 0.0;
    }
    return atan(y, x);
}

// envmap::geometry::uv (preview_environment.wgsl's env_uv): u in [0, 1), 0 on the poles.
vec2 env_uv(vec3 w) {
    float theta = merl_atan2(length(w.xy), w.z);
    float u = merl_atan2(w.y, w.x) / (2.0 * PI);
    if (u < 0.0) {
        u += 1.0;
        if (u >= 1.0) {
            u = 0.0;
        }
    }
    return vec2(u, theta / PI);
}

// envmap::EnvMap::lookup_uv (env_bilinear): bilinear with texel centres at (x + 1/2) / width, u
// wrapping, v clamped to the centres of the first and last rows; layer \`layer\` of \`map\`.
vec3 env_bilinear(sampler2DArray map, int layer, vec2 uv) {
    ivec3 size = textureSize(map, 0);
    int w = size.x;
    int h = size.y;
    float s = uv.x * float(w) - 0.5;
    float t = clamp(uv.y * float(h) - 0.5, 0.0, float(h - 1));
    float s0 = floor(s);
    float fx = s - s0;
    float fy = t - floor(t);
    // rem_euclid; GLSL's % is undefined for negative operands, and s0 >= -1 here.
    int xi = int(s0);
    int x0 = (xi < 0 ? xi + w * ((w - 1 - xi) / w) : xi) % w;
    int x1 = x0 + 1 == w ? 0 : x0 + 1;
    int y0 = min(int(t), h - 1);
    int y1 = min(y0 + 1, h - 1);
    vec3 a = texelFetch(map, ivec3(x0, y0, layer), 0).rgb;
    vec3 b = texelFetch(map, ivec3(x1, y0, layer), 0).rgb;
    vec3 c = texelFetch(map, ivec3(x0, y1, layer), 0).rgb;
    vec3 d = texelFetch(map, ivec3(x1, y1, layer), 0).rgb;
    vec3 top = a * (1.0 - fx) + b * fx;
    vec3 bottom = c * (1.0 - fx) + d * fx;
    return top * (1.0 - fy) + bottom * fy;
}

vec3 srgb_encode(vec3 x) {
    return mix(1.055 * pow(x, vec3(1.0 / 2.4)) - 0.055, 12.92 * x, lessThanEqual(x, vec3(0.0031308)));
}

// preview_present.wgsl's tonemap, envmap::tonemap_rgb8 before the 8 bits: exposure, a
// non-positive or NaN value to 0, Reinhard's x / (1 + x) per channel, the sRGB transfer function.
vec3 tonemap(vec3 radiance) {
    vec3 x = radiance * uExposure;
    vec3 positive = mix(vec3(0.0), x, greaterThan(x, vec3(0.0)));
    vec3 finite = min(positive, vec3(3.0e38));
    return srgb_encode(finite / (1.0 + finite));
}

// What a pixel writes to gl_FragColor: brdf-preview's exposure, Reinhard and sRGB
// (PREVIEW_OUTPUT), or the linear radiance times uExposure, which three's tone mapping and output
// colour space take next (OUTPUT below, after the write). No twin: the previewer presents with
// tonemap alone.
vec4 present(vec3 value) {
#ifdef PREVIEW_OUTPUT
    return vec4(tonemap(value), 1.0);
#else
    return vec4(value * uExposure, 1.0);
#endif
}

// The image size, and the pixel ray's basis as render::Camera::ray builds it: the ray through
// the image's centre, and its change across half the image to the right and up (for three's
// perspective camera without zoom or view offset: forward, right tan(fov_y / 2) aspect, up
// tan(fov_y / 2); for an orthographic camera: forward, and no change).
uniform uvec2 uResolution;
uniform vec3 uRayForward;
uniform vec3 uRayRight;
uniform vec3 uRayUp;

// camera_ray: the ray from the eye through the centre of pixel (x, y), row 0 at the top.
vec3 camera_ray(uint x, uint y) {
    float x_ndc = 2.0 * (float(x) + 0.5) / float(uResolution.x) - 1.0;
    float y_ndc = 1.0 - 2.0 * (float(y) + 0.5) / float(uResolution.y);
    return normalize(uRayForward + x_ndc * uRayRight + y_ndc * uRayUp);
}

// render::shade::background (shade_backdrop): level 0 along the pixel's ray.
vec3 background(uint x, uint y) {
    vec3 ray = camera_ray(x, y);
#ifdef TURNED
    ray = uEnvFromWorld * ray;
#endif
    return env_bilinear(uEnvironment, 0, env_uv(ray));
}
`;

// After the write of present(): three's tone mapping and output colour space (its shader chunks:
// the renderer's toneMapping where it draws to the canvas, its outputColorSpace there, nothing on
// a render target), unless PREVIEW_OUTPUT.
const OUTPUT = /* glsl */ `
#ifndef PREVIEW_OUTPUT
    #include <tonemapping_fragment>
    #include <colorspace_fragment>
#endif
`;

// The background: level 0 along each pixel's camera ray (render::Camera::ray).
export const BACKGROUND_VERTEX = /* glsl */ `
void main() {
    // A full-screen quad at the far plane.
    gl_Position = vec4(position.xy, 1.0, 1.0);
}
`;

export const BACKGROUND_FRAGMENT = /* glsl */ `
${COMMON}

void main() {
    uvec2 p = uvec2(gl_FragCoord.xy);
    uint y = uResolution.y - 1u - p.y;
    gl_FragColor = present(background(p.x, y));
    ${OUTPUT}
}
`;

// A mesh as three's own materials move it (its shader chunks: batching, instancing, morph
// targets, skinning, logarithmic depth, clipping planes), handing the fragment shader the world
// position and normal (the normal through three's normal matrix and back from view space).
export const SURFACE_VERTEX = /* glsl */ `
#include <common>
#include <batching_pars_vertex>
#include <morphtarget_pars_vertex>
#include <skinning_pars_vertex>
#include <logdepthbuf_pars_vertex>
#include <clipping_planes_pars_vertex>
out vec3 vPosition;
out vec3 vNormal;
void main() {
    #include <morphinstance_vertex>
    #include <batching_vertex>
    #include <beginnormal_vertex>
    #include <morphnormal_vertex>
    #include <skinbase_vertex>
    #include <skinnormal_vertex>
    #include <defaultnormal_vertex>
    #include <begin_vertex>
    #include <morphtarget_vertex>
    #include <skinning_vertex>
    #include <project_vertex>
    #include <logdepthbuf_vertex>
    #include <clipping_planes_vertex>
    // worldpos_vertex's steps, which three takes only for its own lights and maps.
    vec4 world = vec4(transformed, 1.0);
#ifdef USE_BATCHING
    world = batchingMatrix * world;
#endif
#ifdef USE_INSTANCING
    world = instanceMatrix * world;
#endif
    world = modelMatrix * world;
    vPosition = world.xyz;
    // World-space normals, normalized per pixel.
    vNormal = transformNormalByInverseViewMatrix(transformedNormal, viewMatrix);
}
`;

// exactCoverage's G-buffer pass (a RawShaderMaterial: it writes two targets): the geometry's
// positions and normals as they are, in world space.
export const GBUFFER_VERTEX = /* glsl */ `
in vec3 position;
in vec3 normal;
uniform mat4 viewMatrix;
uniform mat4 projectionMatrix;
out vec3 vPosition;
out vec3 vNormal;
void main() {
    vPosition = position;
    vNormal = normal;
    gl_Position = projectionMatrix * viewMatrix * vec4(position, 1.0);
}
`;

export const SURFACE_FRAGMENT = /* glsl */ `
${COMMON}
const uint MODE_REFERENCE = 0u;
const uint MODE_PREFILTERED = 2u;
// split.js's MAX_PEAK_LIGHTS.
#define MAX_PEAK_LIGHTS 2

// engine-merl.ktx2: texel (phi_d, theta_d, theta_h) of the MERL grid, RGB in 1/sr, 0 without data.
uniform sampler3D uMerl;
// merl::Dims::phi_d_range: pi, or 2 pi for 360 cells.
uniform float uPhiDRange;
// engine-brdf-tables.ktx2: layer k slice k; row 0 the row edges in t = 1 - cos theta_h, row 1
// the marginal CDF over rows, row 2 + i the conditional CDF of row i over sectors.
uniform sampler2DArray uBrdfTables;
// engine-light-tables.ktx2: layer 0 level 0's distribution, layer 1 the peaks'; row 0 the
// marginal CDF over rows, row 1 + y the conditional CDF of row y.
uniform sampler2DArray uLightTables;
// engine-view-layers.ktx2: the view rows' Phong layer coordinates.
uniform sampler2D uViewLayers;
// engine-layers.ktx2: the smooth part's Phong layers.
uniform sampler2DArray uLayers;
// The layers' exponents (the manifest's), then render::past_exponent (the smooth map past the
// sharpest layer); the rest unused.
uniform float uLayerExponents[MAX_LAYERS + 1];
// render::Settings::filter_samples: the samples of the picture (spp times its frames), whose
// footprints the prefiltered estimator reads.
uniform uint uFilterSamples;

uniform uint uMode;
uniform uint uSeed;
uniform uint uSpp;
uniform uint uSlices;
uniform uint uVectors;
uniform uint uSamples;
uniform uint uRows;
uniform uint uSectors;
uniform bool uPeaks;
// render::diffuse_split (the manifest's diffuse): the BRDF's diffuse part f_d, which the
// prefiltered estimator reads from the cosine layer (the first) at the normal.
uniform vec3 uDiffuse;
#ifdef SPLIT
// The split estimator's inputs (split.js). uLobes: lobeMixture's rows of texels per view (the
// albedo and the layers' weights); uCorrections: what a peak light adds past the layers' share
// of it, per view, angle from the mirror direction and azimuth about it (lightCorrections); uLayersLinear: engine-full-layers and, as
// one more layer, level 0 at the layers' size (splitLayers), filtered linearly (u repeating, v
// clamped): what env_bilinear computes, in one read. MIX_LAYERS, defined with SPLIT, is the
// number of exponents (the layers and level 0). The peaks as directional lights: their
// directions in the environment's frame, their irradiance at normal incidence, and the cosines
// of their near cones (peakLights' near).
uniform sampler2D uLobes;
uniform sampler2DArray uLayersLinear;
uniform sampler3D uCorrections;
uniform int uPeakCount;
uniform vec3 uPeakDirections[MAX_PEAK_LIGHTS];
uniform vec3 uPeakPowers[MAX_PEAK_LIGHTS];
uniform vec2 uPeakNear[MAX_PEAK_LIGHTS];
#endif
// The frames this draw sums (first, count), and what the sum is divided by.
uniform uint uFirstFrame;
uniform uint uFrameCount;
uniform float uDivisor;
// The eye: cameraPosition, which three.js declares and sets from the camera.

#ifdef DEFERRED
// The G-buffer of exactCoverage (index.js): the interpolated position, and the interpolated
// normal with w = 1 where a triangle covers the sample, read at texel (S x + S / 2, S y + S / 2)
// for pixel (x, y) (rows from the bottom in both).
uniform sampler2D uGPosition;
uniform sampler2D uGNormal;
uniform int uGScale;
#else
in vec3 vPosition;
in vec3 vNormal;
#include <logdepthbuf_pars_fragment>
#include <clipping_planes_pars_fragment>
#endif

// ---- merl_lookup.wgsl: merl::half_diff, merl::Dims::nearest_cell, merl::MerlTable::cell_value.

float merl_theta_of(vec3 v) {
    return merl_atan2(length(v.xy), v.z);
}

vec3 merl_rotate_z(vec3 v, float angle) {
    float s = sin(angle);
    float c = cos(angle);
    return vec3(v.x * c - v.y * s, v.x * s + v.y * c, v.z);
}

vec3 merl_rotate_y(vec3 v, float angle) {
    float s = sin(angle);
    float c = cos(angle);
    return vec3(v.x * c + v.z * s, v.y, -v.x * s + v.z * c);
}

// (theta_h, phi_h, theta_d, phi_d).
vec4 merl_half_diff(vec3 wi, vec3 wo) {
    vec3 h = normalize(wi + wo);
    float theta_h = merl_theta_of(h);
    float phi_h = merl_atan2(h.y, h.x);
    vec3 d = merl_rotate_y(merl_rotate_z(wi, -phi_h), -theta_h);
    return vec4(theta_h, phi_h, merl_theta_of(d), merl_atan2(d.y, d.x));
}

int merl_axis_index(float x, int n) {
    return int(clamp(floor(x), 0.0, float(n - 1)));
}

// merl_lookup_nearest and wavelet_brdf.wgsl's material_brdf for a table: the nearest cell.
vec3 material_brdf(vec3 wi, vec3 wo) {
    ivec3 dims = textureSize(uMerl, 0);
    vec4 hd = merl_half_diff(wi, wo);
    float x_h = sqrt(max(hd.x, 0.0) / HALF_PI) * float(dims.z);
    float x_d = hd.z / HALF_PI * float(dims.y);
    float phi_d = hd.w;
    if (phi_d < 0.0) {
        phi_d += uPhiDRange;
    }
    float x_p = phi_d / uPhiDRange * float(dims.x);
    ivec3 cell = ivec3(merl_axis_index(x_p, dims.x), merl_axis_index(x_d, dims.y), merl_axis_index(x_h, dims.z));
    return texelFetch(uMerl, cell, 0).rgb;
}

// ---- preview_sampling, preview_geometry, preview_environment and preview_shade.wgsl.

// render::pcg_hash: GLSL's uint arithmetic wraps as Rust's wrapping_* does.
uint pcg_hash(uint v) {
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// render::sample_range: (vector, first sample) of pixel \`pixel\` in frame \`f\`.
uvec2 sample_range(uint pixel, uint f, uint spp) {
    uint per_vector = uSamples / spp;
    uint chunks = uVectors * per_vector;
    uint h = pcg_hash(pixel ^ pcg_hash(uSeed));
    uint chunk = (h % chunks + f % chunks) % chunks;
    return uvec2(chunk / per_vector, (chunk % per_vector) * spp);
}

// render::SEQUENCE_SALT.
const uint SEQUENCE_SALT = 0x6a09e667u;

// No twin: WGSL's builtin reverseBits (GLSL ES 3.0 has no bitfieldReverse).
uint reverse_bits(uint value) {
    uint v = value;
    v = ((v >> 1u) & 0x55555555u) | ((v & 0x55555555u) << 1u);
    v = ((v >> 2u) & 0x33333333u) | ((v & 0x33333333u) << 2u);
    v = ((v >> 4u) & 0x0f0f0f0fu) | ((v & 0x0f0f0f0fu) << 4u);
    v = ((v >> 8u) & 0x00ff00ffu) | ((v & 0x00ff00ffu) << 8u);
    return (v >> 16u) | (v << 16u);
}

// sampling::OwenSobol2D's nested uniform scrambling (owen_scramble).
uint owen_scramble(uint value, uint seed) {
    uint v = reverse_bits(value);
    v ^= v * 0x3d20adeau;
    v += seed;
    v *= (seed >> 16u) | 1u;
    v ^= v * 0x05526c56u;
    v ^= v * 0x53a22864u;
    return reverse_bits(v);
}

// sampling::OwenSobol2D's second Sobol' dimension (sobol_dim1).
uint sobol_dim1(uint i) {
    uint index = i;
    uint result = 0u;
    uint v = 0x80000000u;
    while (index != 0u) {
        if ((index & 1u) != 0u) {
            result ^= v;
        }
        index >>= 1u;
        v ^= v >> 1u;
    }
    return result;
}

// render::pixel_sequences (pixel_words): the BRDF's words in xy, the light's in zw.
uvec4 pixel_words(uint pixel) {
    uint w0 = pcg_hash(pixel ^ pcg_hash(uSeed ^ SEQUENCE_SALT));
    uint w1 = pcg_hash(w0);
    uint w2 = pcg_hash(w1);
    return uvec4(w0, w1, w2, pcg_hash(w2));
}

// render::point (sequence_point): the top 24 bits of each coordinate.
vec2 sequence_point(uvec2 words, uint index) {
    uint x = owen_scramble(reverse_bits(index), words.x);
    uint y = owen_scramble(sobol_dim1(index), words.y);
    return vec2(float(x >> 8u), float(y >> 8u)) / 16777216.0;
}

// A CDF table is a row of one layer of a table texture. No twin: the WGSL indexes its storage
// buffer (sampling_tables) where this fetches a texel.
float table_value(sampler2DArray tables, int layer, int row, uint i) {
    return texelFetch(tables, ivec3(int(i), row, layer), 0).r;
}

// cdf_bin: the last edge at most u (sampling::Distribution1D::sample).
uint cdf_bin(sampler2DArray tables, int layer, int row, uint n, float u) {
    uint lo = 0u;
    uint hi = n;
    while (hi - lo > 1u) {
        uint mid = (lo + hi) / 2u;
        if (table_value(tables, layer, row, mid) <= u) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    return lo;
}

// cdf_fraction: where u lies within bin i, in [0, 1).
float cdf_fraction(sampler2DArray tables, int layer, int row, uint i, float u) {
    float c0 = table_value(tables, layer, row, i);
    return min((u - c0) / (table_value(tables, layer, row, i + 1u) - c0), ONE_BELOW);
}

// cdf_width: the probability of bin i.
float cdf_width(sampler2DArray tables, int layer, int row, uint i) {
    return table_value(tables, layer, row, i + 1u) - table_value(tables, layer, row, i);
}

// A direction and its density per unit solid angle (DirectionSample).
struct DirectionSample {
    vec3 wi;
    float pdf;
};

// importance::Slice::wo (slice_wo).
vec3 slice_wo(uint k) {
    float theta_o = float(k) / float(uSlices) * HALF_PI;
    return vec3(sin(theta_o), 0.0, cos(theta_o));
}

// Row edge i (t = 1 - cos theta_h) of slice k's table, render::SampleSet::tables' t_edges. No
// twin: the WGSL reads it from sampling_tables inline.
float t_edge(uint k, uint i) {
    return table_value(uBrdfTables, int(k), 0, i);
}

// importance::Slice::h_density (h_density).
float h_density(uint k, uint iv, uint iu) {
    float row_width = t_edge(k, iv + 1u) - t_edge(k, iv);
    float p_row = cdf_width(uBrdfTables, int(k), 1, iv);
    float p_cell = cdf_width(uBrdfTables, int(k), 2 + int(iv), iu);
    return p_row * p_cell / (row_width * 2.0 * PI / float(uSectors));
}

// importance::Slice::sample (brdf_sample).
DirectionSample brdf_sample(uint k, vec2 u) {
    uint iv = cdf_bin(uBrdfTables, int(k), 1, uRows, u.y);
    float fv = cdf_fraction(uBrdfTables, int(k), 1, iv, u.y);
    uint iu = cdf_bin(uBrdfTables, int(k), 2 + int(iv), uSectors, u.x);
    float fu = cdf_fraction(uBrdfTables, int(k), 2 + int(iv), iu, u.x);
    float t0 = t_edge(k, iv);
    float t = t0 + fv * (t_edge(k, iv + 1u) - t0);
    float phi = 2.0 * PI * (float(iu) + fu) / float(uSectors);
    vec3 h = vec3(sqrt(max(t * (2.0 - t), 0.0)) * vec2(cos(phi), sin(phi)), 1.0 - t);
    vec3 wo = slice_wo(k);
    float wo_h = dot(wo, h);
    if (!(wo_h > 0.0)) {
        return DirectionSample(vec3(0.0), 0.0);
    }
    return DirectionSample(2.0 * wo_h * h - wo, h_density(k, iv, iu) / (4.0 * wo_h));
}

// importance::Slice::pdf (brdf_pdf).
float brdf_pdf(uint k, vec3 wi) {
    vec3 wo = slice_wo(k);
    vec3 sum = wi + wo;
    float len = length(sum);
    if (!(len > 0.0)) {
        return 0.0;
    }
    vec3 h = sum / len;
    float wo_h = dot(wo, h);
    if (!(h.z > 0.0 && wo_h > 0.0)) {
        return 0.0;
    }
    float t = (h.x * h.x + h.y * h.y) / (1.0 + h.z);
    // importance::HalfVectorRows::row_of: the edges 1 ..= R at most t, counted, at most R - 1.
    uint lo = 0u;
    uint hi = uRows;
    while (lo < hi) {
        uint mid = (lo + hi) / 2u;
        if (t_edge(k, 1u + mid) <= t) {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    uint iv = min(lo, uRows - 1u);
    float phi = merl_atan2(h.y, h.x);
    if (phi < 0.0) {
        phi += 2.0 * PI;
    }
    uint iu = min(uint(min(phi / (2.0 * PI), ONE_BELOW) * float(uSectors)), uSectors - 1u);
    return h_density(k, iv, iu) / (4.0 * wo_h);
}

// A point of the map and its density per unit solid angle (LightSample).
struct LightSample {
    vec2 uv;
    float pdf;
};

// solid_angle_density: pdf_uv / (2 pi^2 sin(pi v)).
float solid_angle_density(float pdf_uv, float v) {
    float sin_theta = sin(PI * v);
    if (!(sin_theta > 0.0 && pdf_uv > 0.0)) {
        return 0.0;
    }
    return pdf_uv / (2.0 * PI * PI * sin_theta);
}

// latlong_texel_density of distribution \`d\` (a layer of uLightTables).
float latlong_texel_density(int d, uint x, uint y) {
    ivec3 size = textureSize(uEnvironment, 0);
    float p_row = cdf_width(uLightTables, d, 0, y);
    float p_texel = cdf_width(uLightTables, d, 1 + int(y), x);
    return p_row * p_texel * float(size.x) * float(size.y);
}

// sampling::LatLong::sample (latlong_sample).
LightSample latlong_sample(int d, vec2 u) {
    ivec3 size = textureSize(uEnvironment, 0);
    uint y = cdf_bin(uLightTables, d, 0, uint(size.y), u.y);
    float fy = cdf_fraction(uLightTables, d, 0, y, u.y);
    uint x = cdf_bin(uLightTables, d, 1 + int(y), uint(size.x), u.x);
    float fx = cdf_fraction(uLightTables, d, 1 + int(y), x, u.x);
    vec2 uv = vec2((float(x) + fx) / float(size.x), (float(y) + fy) / float(size.y));
    return LightSample(uv, solid_angle_density(latlong_texel_density(d, x, y), uv.y));
}

// sampling::LatLong::pdf (latlong_pdf).
float latlong_pdf(int d, vec2 uv) {
    ivec3 size = textureSize(uEnvironment, 0);
    uint x = min(uint(max(uv.x * float(size.x), 0.0)), uint(size.x) - 1u);
    uint y = min(uint(max(uv.y * float(size.y), 0.0)), uint(size.y) - 1u);
    return solid_angle_density(latlong_texel_density(d, x, y), uv.y);
}

// render::shade::mis_weight: the balance heuristic.
float mis_weight(float p, float q) {
    return p / (p + q);
}

struct ShadingFrame {
    vec3 t;
    vec3 b;
    vec3 n;
    float cos_o;
    vec3 wo_local;
};

// render::shade::duff_tangent; the sign from the bit, so that n.z = -0 takes -1.
vec3 duff_tangent(vec3 n) {
    float s = (floatBitsToUint(n.z) & 0x80000000u) != 0u ? -1.0 : 1.0;
    float a = -1.0 / (s + n.z);
    return vec3(1.0 + s * n.x * n.x * a, s * n.x * n.y * a, -s * n.x);
}

// render::COS_O_MIN (COS_O_MIN).
const float COS_O_MIN = 1e-4;

// render::shade::bend_towards (bend_towards): n rotated towards wo until n . wo = COS_O_MIN.
vec3 bend_towards(vec3 n, vec3 wo, float cos_o) {
    vec3 across = n - cos_o * wo;
    float len = length(across);
    vec3 p = len < 1e-6 ? duff_tangent(wo) : across / len;
    return COS_O_MIN * wo + sqrt(1.0 - COS_O_MIN * COS_O_MIN) * p;
}

// render::shade::ShadingFrame::new (shading_frame); false where the pixel is black (a normal
// interpolated to zero).
bool shading_frame(vec3 position, vec3 n, vec3 eye, out ShadingFrame frame) {
    if (all(equal(n, vec3(0.0)))) {
        return false;
    }
    vec3 wo = normalize(eye - position);
    float cos_o = dot(n, wo);
    if (isnan(cos_o)) {
        return false;
    }
    if (cos_o < COS_O_MIN) {
        n = bend_towards(n, wo, cos_o);
        cos_o = dot(n, wo);
    }
    vec3 tangent = wo - cos_o * n;
    float sin_o = length(tangent);
    vec3 t = sin_o < 1e-6 ? duff_tangent(n) : tangent / sin_o;
    frame = ShadingFrame(t, cross(n, t), n, cos_o, normalize(vec3(sin_o, 0.0, cos_o)));
    return true;
}

vec3 to_world(ShadingFrame frame, vec3 local) {
    return local.x * frame.t + local.y * frame.b + local.z * frame.n;
}

vec3 to_local(ShadingFrame frame, vec3 world) {
    return vec3(dot(world, frame.t), dot(world, frame.b), dot(world, frame.n));
}

// envmap::direction (env_direction).
vec3 env_direction(vec2 uv) {
    float phi = 2.0 * PI * uv.x;
    float theta = PI * uv.y;
    return vec3(sin(theta) * cos(phi), sin(theta) * sin(phi), cos(theta));
}

// render::shade::slice_of: the slice nearest theta_o.
uint slice_of(ShadingFrame frame) {
    float theta_o = merl_atan2(frame.wo_local.x, frame.wo_local.z);
    float k = max(floor(theta_o / HALF_PI * float(uSlices) + 0.5), 0.0);
    return min(uint(k), uSlices - 1u);
}

// render::view_layer (view_layer_coordinate).
float view_layer_coordinate(ShadingFrame frame) {
    int rows = textureSize(uViewLayers, 0).x;
    float s = clamp((1.0 - frame.cos_o) * float(rows) - 0.5, 0.0, float(rows - 1));
    int r = min(int(floor(s)), rows - 1);
    float t = s - float(r);
    float a = texelFetch(uViewLayers, ivec2(r, 0), 0).r;
    if (t > 0.0) {
        return a + (texelFetch(uViewLayers, ivec2(r + 1, 0), 0).r - a) * t;
    }
    return a;
}

// pixel_layer (layer_shift 0): the view's layer coordinate, at most the one past the sharpest.
float pixel_layer(ShadingFrame frame) {
    return min(view_layer_coordinate(frame), float(textureSize(uLayers, 0).z));
}

// render::exponent_layer: the layer coordinate of exponent n.
float exponent_layer(float n) {
    int n_layers = textureSize(uLayers, 0).z;
    if (!(n > uLayerExponents[0])) {
        return 0.0;
    }
    if (n >= uLayerExponents[n_layers]) {
        return float(n_layers);
    }
    int k = 0;
    while (k + 1 < n_layers && uLayerExponents[k + 1] <= n) {
        k++;
    }
    float a = log(uLayerExponents[k]);
    return float(k) + (log(n) - a) / (log(uLayerExponents[k + 1]) - a);
}

// render::shade::footprint_layer: the footprint of one of n samples of density pdf.
float footprint_layer(uint n, float pdf) {
    return exponent_layer(2.0 * PI * float(n) * pdf - 1.0) + PREFILTERED_FOOTPRINT_LAYERS;
}

// layer_map: layer k at uv, or past the sharpest the smooth part's level 0 (level 0 less its
// peaks, which are 0 where there are none).
vec3 layer_bilinear(int k, vec2 uv) {
    if (k < textureSize(uLayers, 0).z) {
        return env_bilinear(uLayers, k, uv);
    }
    return max(env_bilinear(uEnvironment, 0, uv) - env_bilinear(uEnvironment, 1, uv), vec3(0.0));
}

// render::shade::layers_lookup: the layers at the view's coordinate, or the sample's where that
// is broader, blended: (1 - t) layer k + t layer k + 1.
vec3 layers_bilinear(float x_view, float x_sample, vec2 uv) {
    float x = clamp(min(x_view, x_sample), 0.0, float(textureSize(uLayers, 0).z));
    int k = int(floor(x));
    float t = x - float(k);
    vec3 a = layer_bilinear(k, uv);
    if (t > 0.0) {
        vec3 b = layer_bilinear(k + 1, uv);
        return a * (1.0 - t) + b * t;
    }
    return a;
}

// render::shade::shade (estimate_sum) for one frame: the sum of the pixel's spp terms. The light
// both strategies share: level 0 in the reference mode, the peaks in the prefiltered one (none
// where the environment has no peaks).
vec3 estimate_sum(ShadingFrame frame, uint pixel, uint f, uint spp) {
    uint k = slice_of(frame);
    uvec2 range = sample_range(pixel, f, spp);
    uint base = range.x * uSamples + range.y;
    uvec4 words = pixel_words(pixel);
    bool reference = uMode == MODE_REFERENCE;
    bool light_valid = reference || uPeaks;
    int light = reference ? 0 : 1;
    float x_view = 0.0;
    vec3 diffuse = vec3(0.0);
    vec3 sum = vec3(0.0);
    if (uMode == MODE_PREFILTERED) {
        x_view = pixel_layer(frame);
        // The diffuse part's integral, once per term (the sum is divided by spp).
        diffuse = uDiffuse;
        sum = (PI * diffuse * env_bilinear(uLayers, 0, env_uv(frame.n))) * float(spp);
    }
    for (uint j = 0u; j < spp; j++) {
        uint index = base + j;
        DirectionSample s = brdf_sample(k, sequence_point(words.xy, index));
        if (s.pdf > 0.0 && s.wi.z > 0.0) {
            vec3 brdf = material_brdf(s.wi, frame.wo_local);
            vec3 rest = brdf - diffuse;
            if (any(notEqual(brdf, vec3(0.0))) || any(notEqual(rest, vec3(0.0)))) {
                vec2 uv = env_uv(to_world(frame, s.wi));
                if (uMode == MODE_PREFILTERED) {
                    sum += rest * layers_bilinear(x_view, footprint_layer(uFilterSamples, s.pdf), uv) * (s.wi.z / s.pdf);
                }
                if (light_valid) {
                    float weight = mis_weight(s.pdf, latlong_pdf(light, uv));
                    sum += brdf * env_bilinear(uEnvironment, light, uv) * (s.wi.z * weight / s.pdf);
                }
            }
        }
        if (!light_valid) {
            continue;
        }
        LightSample drawn = latlong_sample(light, sequence_point(words.zw, index));
        vec3 wi = to_local(frame, env_direction(drawn.uv));
        if (drawn.pdf > 0.0 && wi.z > 0.0) {
            vec3 brdf = material_brdf(wi, frame.wo_local);
            if (any(notEqual(brdf, vec3(0.0)))) {
                float weight = mis_weight(drawn.pdf, brdf_pdf(k, wi));
                sum += brdf * env_bilinear(uEnvironment, light, drawn.uv) * (wi.z * weight / drawn.pdf);
            }
        }
    }
    return sum;
}

#ifdef SPLIT
// env_uv with one inverse cosine for theta (the split estimator's: no twin to match to the bit).
vec2 split_uv(vec3 w) {
    float u = merl_atan2(w.y, w.x) / (2.0 * PI);
    return vec2(u < 0.0 ? u + 1.0 : u, acos(clamp(w.z, -1.0, 1.0)) / PI);
}

// The rows of uLobes (split.js's mixtureRows).
#define MIX_ROWS (1 + (MIX_LAYERS + 2) / 4)

// The split estimator (no twin; split.js says what it draws and where it is biased): the diffuse
// part as estimate_sum reads it, the rest as the view's mixture of the layers in the mirror
// direction, and each peak light away from its reflection through the table, in place of the
// mixture's share of it.
vec3 split_estimate(ShadingFrame frame) {
    // The view's albedo and weights, linear between the views' rows; past the last layer the
    // texture array's layer clamps, and its weights are 0.
    float u = 1.0 - frame.cos_o;
    vec4 head = texture(uLobes, vec2(u, 0.5 / float(MIX_ROWS)));
    vec3 mirror = to_world(frame, vec3(-frame.wo_local.x, 0.0, frame.wo_local.z));
    vec2 uv = split_uv(mirror);
    vec3 lobe = head.a * texture(uLayersLinear, vec3(uv, 0.0)).rgb;
    for (int r = 1; r < MIX_ROWS; r++) {
        vec4 t = texture(uLobes, vec2(u, (float(r) + 0.5) / float(MIX_ROWS)));
        float k = float(4 * r - 3);
        lobe += t.x * texture(uLayersLinear, vec3(uv, k)).rgb + t.y * texture(uLayersLinear, vec3(uv, k + 1.0)).rgb
            + t.z * texture(uLayersLinear, vec3(uv, k + 2.0)).rgb + t.w * texture(uLayersLinear, vec3(uv, k + 3.0)).rgb;
    }
    vec3 sum = PI * uDiffuse * texture(uLayersLinear, vec3(split_uv(frame.n), 0.0)).rgb + head.rgb * lobe;
    for (int i = 0; i < MAX_PEAK_LIGHTS; i++) {
        if (i >= uPeakCount) {
            break;
        }
        vec3 d = uPeakDirections[i];
        float c = clamp(dot(mirror, d), -1.0, 1.0);
        // 0 within the near cone, where the layers draw the light with its shape; 1 past twice it.
        float away = 1.0 - smoothstep(uPeakNear[i].y, uPeakNear[i].x, c);
        if (away > 0.0) {
            // The light's angle from the mirror direction and azimuth about it (lightCorrections).
            vec3 wl = to_local(frame, d);
            float sin_a = sqrt(max(1.0 - c * c, 0.0));
            vec3 e1 = vec3(frame.wo_local.z, 0.0, frame.wo_local.x);
            float cos_b = sin_a > 1e-6 ? clamp(dot(wl, e1) / sin_a, -1.0, 1.0) : 1.0;
            vec3 correction = texture(uCorrections, vec3(sqrt(acos(c) / PI), 0.5 + 0.5 * cos_b, u)).rgb;
            sum += away * uPeakPowers[i] * correction;
        }
    }
    // The table's value less the mixture's may take more than the layers gave.
    return max(sum, vec3(0.0));
}
#endif

// shade_frame at pixel p (render::shade::shade_rows): the radiance (rows from the bottom), or
// where the G-buffer has no triangle the environment behind.
vec3 shade_pixel(uvec2 p) {
    // Row 0 at the top, as render's pixel index counts.
    uint pixel = (uResolution.y - 1u - p.y) * uResolution.x + p.x;
#ifdef DEFERRED
    ivec2 g = ivec2(p) * uGScale + uGScale / 2;
    vec4 gn = texelFetch(uGNormal, g, 0);
    if (gn.w == 0.0) {
        // No triangle covers the pixel: the environment behind.
        return background(p.x, uResolution.y - 1u - p.y);
    }
    vec3 position = texelFetch(uGPosition, g, 0).xyz;
    vec3 normal = gn.xyz;
#else
    vec3 position = vPosition;
    vec3 normal = vNormal;
#endif
    // glam's normalize_or_zero.
    float length_squared = dot(normal, normal);
    vec3 n = length_squared > 0.0 ? normal / sqrt(length_squared) : vec3(0.0);
    // An orthographic camera looks along its axis everywhere: the eye a unit back along it (the
    // view matrix's third row).
    vec3 eye = isOrthographic ? position + vec3(viewMatrix[0][2], viewMatrix[1][2], viewMatrix[2][2]) : cameraPosition;
#ifdef TURNED
    // Shaded in the environment's frame: the normal and the eye ray turned by uEnvFromWorld
    // (left out in brdf-preview's orientation, where it is the identity).
    eye = position + uEnvFromWorld * (eye - position);
    n = uEnvFromWorld * n;
#endif
    ShadingFrame frame;
    vec3 radiance = vec3(0.0);
    if (shading_frame(position, n, eye, frame)) {
#ifdef SPLIT
        // A program of its own (the define, not uMode): a software GPU runs what a uniform
        // branch leaves in, and the sampled estimators' code would cost the split frame more than
        // the split itself (engines/three/bench/frontier.mjs).
        radiance = split_estimate(frame);
#else
        vec3 sum = vec3(0.0);
        for (uint f = uFirstFrame; f < uFirstFrame + uFrameCount; f++) {
            sum += estimate_sum(frame, pixel, f, uSpp) / float(uSpp);
        }
        radiance = sum / uDivisor;
#endif
    }
    return radiance;
}

void main() {
#ifndef DEFERRED
    #include <clipping_planes_fragment>
#endif
    gl_FragColor = present(shade_pixel(uvec2(gl_FragCoord.xy)));
    ${OUTPUT}
#ifndef DEFERRED
    #include <logdepthbuf_fragment>
#endif
}
`;

// exactCoverage's G-buffer pass (index.js): at S times the size, only the texel of each pixel's
// centre (S x + S / 2, S y + S / 2) is written: the interpolated position and normal (w = 1).
export const GBUFFER_FRAGMENT = /* glsl */ `
precision highp float;
precision highp int;
uniform int uGScale;
in vec3 vPosition;
in vec3 vNormal;
layout(location = 0) out vec4 gPosition;
layout(location = 1) out vec4 gNormal;
void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    if (p.x % uGScale != uGScale / 2 || p.y % uGScale != uGScale / 2) {
        discard;
    }
    gPosition = vec4(vPosition, 1.0);
    gNormal = vec4(vNormal, 1.0);
}
`;

// A full-screen quad: exactCoverage's shading pass and the live mode's sums (live.js).
export const QUAD_VERTEX = /* glsl */ `
void main() {
    gl_Position = vec4(position.xy, 0.0, 1.0);
}
`;
