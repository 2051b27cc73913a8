//! The previewer's present pass: the running average of a `Renderer`'s accumulation buffer as a
//! picture, drawn by one full-screen triangle into any 8-bit RGBA or BGRA target (a window's
//! surface texture, or an offscreen texture for a screenshot). The image keeps its aspect and is
//! centred, scaled by nearest pixel; the margins show the background.
//!
//! Radiance is tone mapped exactly like `envmap::tonemap_rgb8`: exposure 2^EV, a non-positive or
//! NaN value to 0, Reinhard's x / (1 + x) per channel (infinity to 1), then the sRGB transfer
//! function; the target's conversion to 8 bits rounds. An sRGB target encodes by itself, so the
//! pass decodes first and the hardware encodes again. The debug views of the shading pass
//! (`MODE_DEBUG_*` of `preview_bindings.wgsl`) are shown at covered pixels as colours instead:
//! normals as (n + 1) / 2, layer and slice indices in viridis (index 0 dark blue, the last
//! yellow), pixels without a shading frame black, a layer index of -1 (no view-layer table)
//! grey.

const VIEW_SHADED: u32 = 0u;
const VIEW_NORMAL: u32 = 1u;
const VIEW_LAYER: u32 = 2u;
const VIEW_SLICE: u32 = 3u;

// Encoded sRGB: the margins around the image, and the layer view without a table.
const BACKGROUND: vec3<f32> = vec3<f32>(0.125, 0.125, 0.125);
const NO_TABLE: vec3<f32> = vec3<f32>(0.5, 0.5, 0.5);

struct PresentUniform {
    image_size: vec2<u32>,
    // The accumulation holds the sum of this many frames; 0: nothing to show.
    frames: u32,
    view: u32,
    // 2^EV.
    exposure: f32,
    // 1 where the target encodes sRGB itself.
    srgb_target: u32,
    // Layers (layer view) or slices (slice view): the palette spans 0 .. n_indices - 1.
    n_indices: u32,
    _pad: u32,
    // Where the image's top-left corner is in the target, and target pixels per image pixel.
    origin: vec2<f32>,
    scale: f32,
    _pad2: f32,
}

@group(0) @binding(0) var<uniform> present: PresentUniform;
// Viridis at 0, 1/255, ..., 1 (`picture::colormap::viridis`), encoded sRGB in [0, 1].
@group(0) @binding(1) var<uniform> palette: array<vec4<f32>, 256>;
// `Renderer`'s accumulation: per pixel the sum of the frames and, in w, whether a triangle covers it.
@group(0) @binding(2) var<storage, read> accumulation: array<vec4<f32>>;

// No Rust twin: the full-screen triangle of a draw.
@vertex
fn present_vertex(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    // (-1, -1), (3, -1), (-1, 3): one triangle that covers the target.
    let corner = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(corner * 2.0 - 1.0, 0.0, 1.0);
}

// `envmap::tonemap_rgb8` before the conversion to 8 bits.
fn tonemap(radiance: vec3<f32>) -> vec3<f32> {
    let x = radiance * present.exposure;
    // Rust's f64::max(NaN, 0) is 0: a comparison is false for NaN too.
    let positive = select(vec3<f32>(0.0), x, x > vec3<f32>(0.0));
    // Infinity maps to 1, as any value beyond 2^24 does in f32.
    let finite = min(positive, vec3<f32>(3.0e38));
    return srgb_encode(finite / (1.0 + finite));
}

// `envmap::write::srgb_encode`.
fn srgb_encode(x: vec3<f32>) -> vec3<f32> {
    return select(1.055 * pow(x, vec3<f32>(1.0 / 2.4)) - 0.055, 12.92 * x, x <= vec3<f32>(0.0031308));
}

// No Rust twin: undoes `envmap::write::srgb_encode` for a target that encodes by itself.
fn srgb_decode(c: vec3<f32>) -> vec3<f32> {
    return select(pow((c + 0.055) / 1.055, vec3<f32>(2.4)), c / 12.92, c <= vec3<f32>(0.04045));
}

// The encoded colour of one image pixel.
// The shaded view's is `envmap::tonemap_rgb8`'s; the debug views have no Rust twin.
fn pixel_colour(sum: vec4<f32>) -> vec3<f32> {
    let value = sum.xyz / f32(present.frames);
    let covered = sum.w > 0.0;
    if (!covered || present.view == VIEW_SHADED) {
        return tonemap(value);
    }
    if (present.view == VIEW_NORMAL) {
        return clamp(0.5 * value + 0.5, vec3<f32>(0.0), vec3<f32>(1.0));
    }
    // VIEW_LAYER, VIEW_SLICE: (index, has a shading frame, 0).
    if (!(value.y > 0.5)) {
        return vec3<f32>(0.0);
    }
    if (value.x < 0.0) {
        return NO_TABLE;
    }
    let last = max(f32(present.n_indices) - 1.0, 1.0);
    let t = clamp(round(value.x) / last, 0.0, 1.0);
    return palette[u32(round(t * 255.0))].rgb;
}

// No Rust twin: the image placed in the target; each pixel's colour is `pixel_colour`'s.
@fragment
fn present_fragment(@builtin(position) position: vec4<f32>) -> @location(0) vec4<f32> {
    // The fragment's position is its pixel centre: (x + 1/2, y + 1/2).
    let p = (position.xy - present.origin) / present.scale;
    let size = vec2<f32>(present.image_size);
    var colour = BACKGROUND;
    if (present.frames > 0u && all(p >= vec2<f32>(0.0)) && all(p < size)) {
        let pixel = min(vec2<u32>(p), present.image_size - 1u);
        colour = pixel_colour(accumulation[pixel.y * present.image_size.x + pixel.x]);
    }
    if (present.srgb_target != 0u) {
        colour = srgb_decode(colour);
    }
    return vec4<f32>(colour, 1.0);
}
