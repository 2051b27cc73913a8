//! What covers a pixel (`render::raster`, `render::shade`): the mesh's vertices, the exact edge
//! functions, the interpolated hit and its shading frame.

// What covers a pixel (`render::raster::Hit`): the world position and the normalized normal
// (zero where it interpolates to zero) at the pixel centre.
struct Hit {
    position: vec3<f32>,
    normal: vec3<f32>,
}

// Vertex `v`'s clip-space position, as the host computed it with `render::raster::project`.
fn mesh_clip(v: u32) -> vec4<f32> {
    let i = 12u * v;
    return vec4<f32>(mesh_vertices[i], mesh_vertices[i + 1u], mesh_vertices[i + 2u], mesh_vertices[i + 3u]);
}

// Vertex `v`'s snapped viewport coordinates, as the host computed them with
// `render::raster::snapped`.
fn mesh_snapped(v: u32) -> vec2<i32> {
    let i = 12u * v + 4u;
    return vec2<i32>(i32(mesh_vertices[i]), i32(mesh_vertices[i + 1u]));
}

// Vertex `v`'s world position (`render::Mesh`).
fn mesh_position(v: u32) -> vec3<f32> {
    let i = 12u * v + 6u;
    return vec3<f32>(mesh_vertices[i], mesh_vertices[i + 1u], mesh_vertices[i + 2u]);
}

// Vertex `v`'s normal (`render::Mesh`).
fn mesh_normal(v: u32) -> vec3<f32> {
    let i = 12u * v + 9u;
    return vec3<f32>(mesh_vertices[i], mesh_vertices[i + 1u], mesh_vertices[i + 2u]);
}

// Whether a clip-space vertex lies in the volume `render::raster` clips to
// (`render::raster::plane_distances` all >= 0): 0 <= z <= w, |x|, |y| <= G w.
fn inside_clip_volume(c: vec4<f32>) -> bool {
    let g = GUARD_BAND * c.w;
    return c.z >= 0.0 && c.w - c.z >= 0.0 && c.x + g >= 0.0 && g - c.x >= 0.0 && c.y + g >= 0.0 && g - c.y >= 0.0;
}

// A signed 64-bit integer, two's complement: the edge functions' exact values. Snapped
// coordinates relative to the pixel centre stay below 2^25 in magnitude (within the guard band of
// an image of up to 16384 pixels), so the products need 51 bits: f32 would round them, and a
// sliver's small edge function is the difference of two large products. (Also the adaptive
// frame's allocation's sums: `preview/adaptive/samples.wgsl`.)
struct Wide {
    hi: u32,
    lo: u32,
}

// No Rust twin: 64-bit integer emulation; the CPU uses i64 (`render::raster::for_each_covered`).
fn wide_add(a: Wide, b: Wide) -> Wide {
    let lo = a.lo + b.lo;
    return Wide(a.hi + b.hi + select(0u, 1u, lo < a.lo), lo);
}

// No Rust twin: 64-bit integer emulation; the CPU uses i64.
fn wide_negate(a: Wide) -> Wide {
    let lo = ~a.lo + 1u;
    return Wide(~a.hi + select(0u, 1u, lo == 0u), lo);
}

// a b exactly, for |a|, |b| < 2^31: the magnitude from 16-bit halves, then the sign.
// No Rust twin: 64-bit integer emulation; the CPU uses i64.
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
// No Rust twin: 64-bit integer emulation; the CPU converts its i64 with `as f64`.
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

// Steps 5 and 6 of `render::raster` (`render::raster::for_each_covered`,
// `render::raster::SubTriangle::hit`) at pixel (x, y) for a triangle drawn whole (no vertex outside
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
// No Rust twin: the CPU clips (`render::raster::clip_polygon`) instead.
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

// `render::raster::SubTriangle::hit` at pixel (x, y) on triangle `t`: position and normal interpolated with
// the weights above, the normal normalized unless it is zero (glam's normalize_or_zero).
fn interpolate_hit(t: u32, x: u32, y: u32) -> Hit {
    var p: array<vec3<f32>, 3>;
    var n: array<vec3<f32>, 3>;
    var snapped: array<vec2<i32>, 3>;
    var w: vec3<f32>;
    var whole = true;
    for (var k = 0u; k < 3u; k++) {
        let v = mesh_indices_and_maps[3u * t + k];
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

// `render::COS_O_MIN`.
const COS_O_MIN: f32 = 1e-4;

// `render::shade::bend_towards`: `n` rotated towards `wo` until `n . wo = COS_O_MIN`.
fn bend_towards(n: vec3<f32>, wo: vec3<f32>, cos_o: f32) -> vec3<f32> {
    let across = n - cos_o * wo;
    let len = length(across);
    var p: vec3<f32>;
    if (len < 1e-6) {
        p = duff_tangent(wo);
    } else {
        p = across / len;
    }
    return COS_O_MIN * wo + sqrt(1.0 - COS_O_MIN * COS_O_MIN) * p;
}

// `render::shade::ShadingFrame::new`; `valid` is false where the pixel is black: the normal
// interpolated to zero.
struct MaybeFrame {
    valid: bool,
    frame: ShadingFrame,
}

// `render::shade::ShadingFrame::new`.
fn shading_frame(hit: Hit) -> MaybeFrame {
    var none: MaybeFrame;
    none.valid = false;
    var n = hit.normal;
    if (all(n == vec3<f32>(0.0))) {
        return none;
    }
    let wo = normalize(shade.eye.xyz - hit.position);
    var cos_o = dot(n, wo);
    if (cos_o != cos_o) {
        return none;
    }
    if (cos_o < COS_O_MIN) {
        n = bend_towards(n, wo, cos_o);
        cos_o = dot(n, wo);
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

// `render::adaptive::geometry::shading_frame` where `render::adaptive::geometry::pixels` finds the
// pixel shadeable.
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

// `render::shade::ShadingFrame::to_world`.
fn to_world(frame: ShadingFrame, local: vec3<f32>) -> vec3<f32> {
    return local.x * frame.t + local.y * frame.b + local.z * frame.n;
}

// `render::shade::ShadingFrame::to_local`.
fn to_local(frame: ShadingFrame, world: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(dot(world, frame.t), dot(world, frame.b), dot(world, frame.n));
}

// `render::Camera::ray`: the ray from the eye through the centre of pixel (x, y), row 0 at the
// top.
fn camera_ray(x: u32, y: u32) -> vec3<f32> {
    let x_ndc = 2.0 * (f32(x) + 0.5) / f32(shade.width) - 1.0;
    let y_ndc = 1.0 - 2.0 * (f32(y) + 0.5) / f32(shade.height);
    return normalize(shade.ray_forward.xyz + x_ndc * shade.ray_right.xyz + y_ndc * shade.ray_up.xyz);
}
