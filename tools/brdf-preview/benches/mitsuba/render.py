#!/usr/bin/env python3
"""Mitsuba 3's image of a scene exported by the `mitsuba` benchmark (../mitsuba.rs): the outside
referee of the CPU renderer (crate `render`).

The scene file (JSON, written by the benchmark) names the project's own tessellated mesh (OBJ:
positions and the vertex normals the renderer interpolates), the environment map (EXR: level 0 of
the bake's mip chain, as the renderer reads it, in `envmap`'s lat-long convention), the MERL table,
the camera (eye, target, up, vertical field of view) and the image size. This script renders it
with Mitsuba's `path` integrator at `max_depth` 2 (direct light: the environment through the mesh's
BSDF; what the renderer computes), the environment through Mitsuba's own `envmap` emitter (its
bilinear lookup and its importance sampling), the MERL table through `MerlNearest` below, and
writes linear RGB radiance (EXR, channels R, G, B) and which pixels the mesh covers (EXR, channel
Y: 1 or 0).

Conventions matched, and how:

- Pixels: the renderer shades one point per pixel, the centre (row 0 at the top). Mitsuba's film
  integrates over the pixel's area, which would blur a mirror's reflection and the silhouette, so
  this script generates the rays itself, through Mitsuba's `perspective` sensor (vertical field of
  view, `look_at` with +z up) at film position ((x + 1/2) / W, (y + 1/2) / H), and hands them to
  the integrator's `sample`, `spp` times each.
- The map: the project's lat-long convention is +z up, row 0 at the +z pole, u = 0 towards +x, u
  growing towards +y: direction (sin v pi cos 2 pi u, sin v pi sin 2 pi u, cos v pi). Mitsuba's
  envmap looks a local direction l up at u = atan2(l.x, -l.z) / 2 pi, v = acos(l.y) / pi. With
  l = (w.y, w.z, -w.x) for a world direction w both give the same (u, v); the emitter's to_world
  is the inverse of that rotation, ENV_TO_WORLD. Both put column x's centre at u = (x + 1/2) / W,
  but Mitsuba's rows sit at v = k / (H - 1) (the first and last on the poles) where ours sit at
  (y + 1/2) / H: the emitter is given `mitsuba_rows` of the map, with which its bilinear lookup
  is ours. The benchmark checks all of it on the background (an image of the map alone against
  the renderer's background).
- The BSDF: the table's nearest lookup exactly as BRDFRead.cpp (and crate `merl`) does it, in the
  local shading frame of the interpolated normal: half vector and difference angles
  (Rusinkiewicz), theta_h index sqrt(theta_h / (pi / 2)) * 90, theta_d index theta_d / (pi / 2) *
  90, phi_d folded into [0, pi) and index phi_d / pi * 180, each truncated and clamped; the channel
  scales 1/1500, 1.15/1500, 1.66/1500; a cell with any negative value is 0; 0 below either
  horizon. Sampling is independent of the project's: one-sample mixture of the cosine density and
  a half-vector density built here from the table (theta_h cells in proportion to the table's mean
  luminance in the cell times the cell's solid angle, uniform in solid angle within a cell and in
  phi_h), evaluated exactly for every direction, so the integrator's MIS with the emitter's
  sampling is unbiased.

Variants: llvm_ad_rgb (vectorized; needs libLLVM MIN_LLVM or newer, found here or named by
DRJIT_LIBLLVM_PATH) and scalar_rgb (always available, one Python call per sample: slow). The
BSDF's lookup is checked against crate merl's by the benchmark (--check-lookup).

Usage: render.py SCENE.json --out OUT.exr [--coverage COVER.exr] [--spp N] [--seed S]
       [--variant auto|llvm_ad_rgb|scalar_rgb] [--no-mesh]
       render.py SCENE.json --check-lookup PAIRS (the BSDF against crate merl's lookup)
Prints one JSON line: the variant, the samples and the wall time (or the pairs that differ).
"""

import argparse
import glob
import json
import math
import os
import re
import sys
import time

import numpy as np

# The world-from-local rotation of Mitsuba's envmap that gives the project's lat-long
# convention (module docs): local (l.x, l.y, l.z) = (w.y, w.z, -w.x), so w = (-l.z, l.x, l.y).
ENV_TO_WORLD = [[0, 0, -1, 0], [1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 0, 1]]

# MERL's channel scales (BRDFRead.cpp): a stored value times its scale is the BRDF in 1/sr.
MERL_SCALE = (1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0)

# Samples per pixel in one pass of the vectorized loop (its memory grows with pixels x this).
SPP_PER_PASS = 64


def fail(message):
    print(f"error: {message}", file=sys.stderr)
    sys.exit(2)


def read_merl(path):
    """The table as (dims, values): values[cell] = (r, g, b) in 1/sr, 0 where it holds no data."""
    try:
        data = open(path, "rb").read()
    except OSError as e:
        fail(f"reading {path}: {e.strerror}")
    if len(data) < 12:
        fail(f"reading {path}: truncated header")
    dims = tuple(int(n) for n in np.frombuffer(data[:12], dtype="<i4"))
    if dims[0] != 90 or dims[1] != 90 or dims[2] not in (180, 360):
        fail(f"reading {path}: unsupported dimensions {dims}, expected 90 x 90 x 180 (or 360)")
    cells = dims[0] * dims[1] * dims[2]
    if len(data) != 12 + 3 * 8 * cells:
        fail(f"reading {path}: expected {12 + 24 * cells} bytes, found {len(data)}")
    raw = np.frombuffer(data[12:], dtype="<f8").reshape(3, cells)
    if not np.all(np.isfinite(raw)):
        fail(f"reading {path}: NaN or infinite values")
    no_data = np.any(raw < 0.0, axis=0)
    values = raw.T * np.array(MERL_SCALE)
    values[no_data] = 0.0
    return dims, values


def half_vector_weights(dims, values):
    """The probability of each theta_h cell for the half-vector strategy: the table's mean Rec. 709
    luminance over the cell's (theta_d, phi_d) times the cell's solid angle (of h), with a floor of
    1e-3 of the mean so that every cell keeps some density."""
    luminance = values @ np.array([0.2126, 0.7152, 0.0722])
    mean = luminance.reshape(dims[0], -1).mean(axis=1)
    edges = (np.arange(dims[0] + 1) / dims[0]) ** 2 * (math.pi / 2)
    solid_angle = 2 * math.pi * (np.cos(edges[:-1]) - np.cos(edges[1:]))
    weights = mean * solid_angle
    weights = np.maximum(weights, 1e-3 * weights.mean())
    return weights / weights.sum(), edges


def read_map(mi, path):
    """The lat-long map as an (H, W, 3) float64 array."""
    try:
        bitmap = mi.Bitmap(path).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, srgb_gamma=False)
    except Exception as e:
        fail(f"reading {path}: {e}")
    return np.array(bitmap, dtype=np.float64)


def mitsuba_rows(texels):
    """The map Mitsuba's envmap must be given to read, bilinearly, what `envmap::EnvMap::lookup`
    reads from `texels` (H rows).

    Both put the centre of column x at u = (x + 1/2) / W and wrap in u. They differ in v: ours
    puts the centre of row y at v = (y + 1/2) / H and clamps to the first and last rows' centres;
    Mitsuba's envmap puts its row k at v = k / (H' - 1), the first and last rows on the poles.
    With H' = 2 H + 1 Mitsuba's rows fall on ours (odd k = 2 y + 1) and halfway between them (even
    k), where the mean of the two rows is the value of our linear interpolation; at the poles (k = 0
    and 2 H) our lookup holds the edge row's value. Mitsuba's bilinear interpolation of these rows
    is therefore ours, exactly (up to f32 rounding); in u the two lookups already agree."""
    h = texels.shape[0]
    rows = np.empty((2 * h + 1,) + texels.shape[1:])
    rows[1::2] = texels
    rows[2:-1:2] = 0.5 * (texels[:-1] + texels[1:])
    rows[0], rows[-1] = texels[0], texels[-1]
    return rows.astype(np.float32)


# The oldest libLLVM the llvm variant is known to work with here: Dr.Jit 1.5 (Mitsuba 3.9) finds
# no usable backend in LLVM 14 (Debian 12's default) and LLVM 15 and 16 abort in code generation
# on this script's kernels; LLVM 19 (Debian 12's libllvm19) works.
MIN_LLVM = 19


def find_libllvm():
    """The newest libLLVM of at least MIN_LLVM on the system, or None."""
    found = []
    for path in glob.glob("/usr/lib/*/libLLVM*.so*") + glob.glob("/usr/lib/llvm-*/lib/libLLVM*.so*"):
        m = re.match(r"libLLVM(?:-|\.so\.)(\d+)", os.path.basename(path))
        if m and int(m.group(1)) >= MIN_LLVM:
            found.append((int(m.group(1)), path))
    return max(found)[1] if found else None


def pick_variant(wanted):
    """llvm_ad_rgb when asked for, or for auto when DRJIT_LIBLLVM_PATH is set or a libLLVM of at
    least MIN_LLVM is found (then named by DRJIT_LIBLLVM_PATH); else scalar_rgb."""
    if wanted == "auto":
        if "DRJIT_LIBLLVM_PATH" not in os.environ:
            lib = find_libllvm()
            if lib is None:
                print(f"no libLLVM {MIN_LLVM} or newer (make setup-mitsuba installs it): scalar_rgb, one Python call "
                      "per sample (slow)", file=sys.stderr)
                wanted = "scalar_rgb"
            else:
                os.environ["DRJIT_LIBLLVM_PATH"] = lib
        if wanted == "auto":
            wanted = "llvm_ad_rgb"
    elif wanted == "llvm_ad_rgb" and "DRJIT_LIBLLVM_PATH" not in os.environ and (lib := find_libllvm()):
        os.environ["DRJIT_LIBLLVM_PATH"] = lib
    try:
        import mitsuba as mi
    except ImportError as e:
        fail(f"mitsuba is not installed ({e}): make setup-mitsuba")
    try:
        mi.set_variant(wanted)
    except Exception as e:
        fail(f"mitsuba variant {wanted}: {e}")
    return mi, wanted


def define_bsdf(mi, dr, dims, values, weights, edges):
    n_h, n_d, n_p = dims
    phi_range = 2 * math.pi if n_p == 360 else math.pi
    if dr.is_jit_v(mi.Float):
        array = lambda a: mi.Float(a.astype(np.float32))  # noqa: E731
        gather = lambda t, i: dr.gather(mi.Float, t, i)  # noqa: E731
    else:  # scalar_rgb: one direction at a time
        array = lambda a: a.astype(np.float32)  # noqa: E731
        gather = lambda t, i: float(t[int(i)])  # noqa: E731
    table = array(values.ravel())
    cell_pdf = array(weights / (2 * math.pi * (np.cos(edges[:-1]) - np.cos(edges[1:]))))
    cos_lo, cos_hi = array(np.cos(edges[1:])), array(np.cos(edges[:-1]))
    distribution = mi.DiscreteDistribution(weights.astype(np.float32))
    # Probability of the cosine strategy in the mixture.
    p_cos = 0.5

    def theta_of(v):
        return dr.atan2(dr.sqrt(dr.square(v.x) + dr.square(v.y)), v.z)

    def lookup(wi, wo):
        """f(wi, wo) in 1/sr: crate merl's nearest lookup (BRDFRead.cpp's indexing)."""
        h = dr.normalize(wi + wo)
        theta_h = theta_of(h)
        phi_h = dr.atan2(h.y, h.x)
        s, c = dr.sincos(-phi_h)
        x, y, z = wi.x * c - wi.y * s, wi.x * s + wi.y * c, wi.z
        s, c = dr.sincos(-theta_h)
        d = mi.Vector3f(x * c + z * s, y, -x * s + z * c)
        theta_d = theta_of(d)
        phi_d = dr.atan2(d.y, d.x)
        phi_d = dr.select(phi_d < 0, phi_d + phi_range, phi_d)

        def index(x, n):
            return dr.minimum(mi.UInt32(dr.maximum(x, 0.0)), n - 1)

        i_h = index(dr.sqrt(dr.maximum(theta_h, 0.0) / (math.pi / 2)) * n_h, n_h)
        i_d = index(theta_d / (math.pi / 2) * n_d, n_d)
        i_p = index(phi_d / phi_range * n_p, n_p)
        cell = (i_h * n_d + i_d) * n_p + i_p
        return mi.Color3f(*(gather(table, 3 * cell + k) for k in range(3)))

    def pdf_half(wi, wo):
        """The half-vector strategy's density over the solid angle of wi."""
        h = dr.normalize(wi + wo)
        wo_h = dr.dot(wo, h)
        theta_h = theta_of(h)
        i_h = dr.minimum(mi.UInt32(dr.sqrt(dr.maximum(theta_h, 0.0) / (math.pi / 2)) * n_h), n_h - 1)
        p_h = gather(cell_pdf, i_h)
        return dr.select((h.z > 0) & (wo_h > 0), p_h / (4 * wo_h), 0.0)

    def mixture_pdf(wi, wo):
        return p_cos * dr.maximum(wi.z, 0.0) / math.pi + (1 - p_cos) * pdf_half(wi, wo)

    class MerlNearest(mi.BSDF):
        """The MERL table's nearest lookup (module docs); `wi` is the light's direction (Mitsuba's
        `wo`), `wo` the viewer's (Mitsuba's `si.wi`), both in the local shading frame."""

        def __init__(self, props):
            mi.BSDF.__init__(self, props)
            flags = mi.BSDFFlags.DiffuseReflection | mi.BSDFFlags.GlossyReflection | mi.BSDFFlags.FrontSide
            self.m_flags = flags
            self.m_components = [flags]

        def eval(self, ctx, si, wo, active=True):
            view, light = si.wi, wo
            valid = active & (view.z > 0) & (light.z > 0)
            f = lookup(light, view) * light.z
            return dr.select(valid, f, 0.0)

        def pdf(self, ctx, si, wo, active=True):
            view, light = si.wi, wo
            valid = active & (view.z > 0) & (light.z > 0)
            return dr.select(valid, mixture_pdf(light, view), 0.0)

        def eval_pdf(self, ctx, si, wo, active=True):
            return self.eval(ctx, si, wo, active), self.pdf(ctx, si, wo, active)

        def sample(self, ctx, si, sample1, sample2, active=True):
            view = si.wi
            use_cos = sample1 < p_cos
            # Cosine.
            wi_cos = mi.warp.square_to_cosine_hemisphere(sample2)
            # Half vector: the theta_h cell from sample1 (reused), cos theta_h uniform within it
            # (uniform solid angle), phi_h uniform.
            cell, _ = distribution.sample_reuse(dr.clip((sample1 - p_cos) / (1 - p_cos), 0.0, 0.99999994))
            cos_h = dr.lerp(gather(cos_lo, cell), gather(cos_hi, cell), sample2.x)
            sin_h = dr.safe_sqrt(1 - dr.square(cos_h))
            s, c = dr.sincos(2 * math.pi * sample2.y)
            h = mi.Vector3f(sin_h * c, sin_h * s, cos_h)
            wi_half = 2 * dr.dot(view, h) * h - view
            wi = dr.select(use_cos, wi_cos, wi_half)
            pdf = mixture_pdf(wi, view)
            valid = active & (view.z > 0) & (wi.z > 0) & (pdf > 0)
            bs = mi.BSDFSample3f()
            bs.wo = wi
            bs.pdf = dr.select(valid, pdf, 0.0)
            bs.eta = 1.0
            bs.sampled_type = mi.UInt32(+mi.BSDFFlags.GlossyReflection)
            bs.sampled_component = mi.UInt32(0)
            value = lookup(wi, view) * (wi.z / dr.select(valid, pdf, 1.0))
            return bs, dr.select(valid, value, 0.0)

        def to_string(self):
            return "MerlNearest[]"

    mi.register_bsdf("merl_nearest", lambda props: MerlNearest(props))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scene", help="the scene file (JSON) the benchmark wrote")
    parser.add_argument("--out", help="radiance, linear RGB (EXR)")
    parser.add_argument("--coverage", help="which pixels the mesh covers (EXR, channel Y)")
    parser.add_argument("--spp", type=int, default=4096)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--variant", default="auto", choices=["auto", "llvm_ad_rgb", "scalar_rgb"])
    parser.add_argument("--no-mesh", action="store_true", help="the environment alone (the map's check)")
    parser.add_argument("--check-lookup", metavar="PAIRS",
                        help="instead of rendering, evaluate the BSDF at the direction pairs of PAIRS (nine "
                             "little-endian f64 each: wi, wo and crate merl's f) and count where it differs")
    args = parser.parse_args()
    if args.out is None and args.check_lookup is None:
        fail("--out OUT.exr (or --check-lookup PAIRS) is required")
    if args.spp < 1:
        fail(f"--spp {args.spp}: at least 1")
    try:
        scene_file = json.load(open(args.scene))
    except (OSError, ValueError) as e:
        fail(f"reading {args.scene}: {e}")
    base = os.path.dirname(os.path.abspath(args.scene))
    path = lambda key: os.path.join(base, scene_file[key])  # noqa: E731

    mi, variant = pick_variant(args.variant)
    import drjit as dr

    dims, values = read_merl(path("material"))
    weights, edges = half_vector_weights(dims, values)
    define_bsdf(mi, dr, dims, values, weights, edges)
    if args.check_lookup:
        check_lookup(mi, dr, args.check_lookup, variant)
        return

    camera = scene_file["camera"]
    width, height = scene_file["width"], scene_file["height"]
    sensor = {
        "type": "perspective",
        "fov_axis": "y",
        "fov": camera["fov_y_deg"],
        "near_clip": camera["near"],
        "far_clip": camera["far"],
        "to_world": mi.ScalarTransform4f().look_at(origin=camera["eye"], target=camera["target"], up=camera["up"]),
        "film": {"type": "hdrfilm", "width": width, "height": height, "rfilter": {"type": "box"}},
    }
    description = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 2, "hide_emitters": False},
        "sensor": sensor,
        "environment": {
            "type": "envmap",
            "bitmap": mi.Bitmap(mitsuba_rows(read_map(mi, path("environment")))),
            "to_world": mi.ScalarTransform4f(ENV_TO_WORLD),
        },
    }
    if not args.no_mesh:
        description["mesh"] = {
            "type": "obj",
            "filename": path("mesh"),
            "face_normals": False,
            "bsdf": {"type": "merl_nearest"},
        }
    scene = mi.load_dict(description)
    sensor = scene.sensors()[0]
    integrator = scene.integrator()

    start = time.time()
    if variant == "scalar_rgb":
        rgb, covered = render_scalar(mi, scene, sensor, integrator, width, height, args.spp, args.seed)
    else:
        rgb, covered = render_vectorized(mi, dr, scene, sensor, integrator, width, height, args.spp, args.seed)
    seconds = time.time() - start

    if not np.all(np.isfinite(rgb)):
        fail(f"{args.out}: the render has {np.count_nonzero(~np.isfinite(rgb))} non-finite values")
    mi.Bitmap(rgb.astype(np.float32), pixel_format=mi.Bitmap.PixelFormat.RGB).write(args.out)
    if args.coverage:
        mi.Bitmap(covered.astype(np.float32)[:, :, None], pixel_format=mi.Bitmap.PixelFormat.Y).write(args.coverage)
    print(json.dumps({"variant": variant, "spp": args.spp, "seed": args.seed, "seconds": round(seconds, 2),
                      "mitsuba": mi.__version__}))


def check_lookup(mi, dr, pairs_path, variant):
    """Prints how many of the pairs' BSDF values (`eval` over the light's cosine) differ from crate
    merl's by more than 1e-3 relative in a channel: a different cell differs by far more, and
    with the directions given in f32 (as the benchmark writes them) only rounding at a cell's
    edge separates the two lookups."""
    try:
        pairs = np.fromfile(pairs_path, dtype="<f8").reshape(-1, 9)
    except (OSError, ValueError) as e:
        fail(f"reading {pairs_path}: {e}")
    bsdf = mi.load_dict({"type": "merl_nearest"})
    wi, wo, expected = pairs[:, 0:3], pairs[:, 3:6], pairs[:, 6:9]
    if dr.is_jit_v(mi.Float):
        si = dr.zeros(mi.SurfaceInteraction3f, len(pairs))
        si.wi = mi.Vector3f(*(mi.Float(wo[:, k].astype(np.float32)) for k in range(3)))
        light = mi.Vector3f(*(mi.Float(wi[:, k].astype(np.float32)) for k in range(3)))
        value = bsdf.eval(mi.BSDFContext(), si, light)
        got = np.stack([np.array(value[k], dtype=np.float64) for k in range(3)], axis=1)
    else:
        got = np.zeros_like(expected)
        for i in range(len(pairs)):
            si = mi.SurfaceInteraction3f()
            si.wi = mi.Vector3f(*wo[i])
            got[i] = np.array(bsdf.eval(mi.BSDFContext(), si, mi.Vector3f(*wi[i])))
    got /= wi[:, 2:3].astype(np.float32)
    differ = np.any(np.abs(got - expected) > 1e-3 * np.abs(expected), axis=1)
    print(json.dumps({"variant": variant, "pairs": len(pairs), "differ": int(differ.sum())}))


def pixel_centres(mi, dr, width, height, repeat):
    """Film positions of every pixel's centre, `repeat` times each (pixel-major), and the pixels."""
    index = dr.arange(mi.UInt32, width * height * repeat) // repeat
    x, y = index % width, index // width
    return mi.Point2f((mi.Float(x) + 0.5) / width, (mi.Float(y) + 0.5) / height), index


def render_vectorized(mi, dr, scene, sensor, integrator, width, height, spp, seed):
    pixels = width * height
    total = np.zeros((pixels, 3))
    done = 0
    pass_index = 0
    while done < spp:
        n = min(SPP_PER_PASS, spp - done)
        position, _ = pixel_centres(mi, dr, width, height, n)
        sampler = mi.load_dict({"type": "independent"})
        # Distinct, reproducible streams per seed and pass.
        sampler.seed(seed * 1_000_003 + pass_index, pixels * n)
        ray, weight = sensor.sample_ray(mi.Float(0.0), mi.Float(0.5), position, mi.Point2f(0.5, 0.5))
        radiance, _, _ = integrator.sample(scene, sampler, ray)
        radiance = radiance * weight
        sums = [dr.block_sum(radiance[k], n) for k in range(3)]
        total += np.stack([np.array(s, dtype=np.float64) for s in sums], axis=1)
        done += n
        pass_index += 1
    position, _ = pixel_centres(mi, dr, width, height, 1)
    ray, _ = sensor.sample_ray(mi.Float(0.0), mi.Float(0.5), position, mi.Point2f(0.5, 0.5))
    covered = np.array(scene.ray_intersect(ray).is_valid(), dtype=bool)
    return (total / spp).reshape(height, width, 3), covered.reshape(height, width)


def render_scalar(mi, scene, sensor, integrator, width, height, spp, seed):
    rgb = np.zeros((height, width, 3))
    covered = np.zeros((height, width), dtype=bool)
    sampler = mi.load_dict({"type": "independent"})
    for y in range(height):
        for x in range(width):
            sampler.seed(seed * 1_000_003 + y * width + x)
            position = mi.Point2f((x + 0.5) / width, (y + 0.5) / height)
            ray, weight = sensor.sample_ray(0.0, 0.5, position, mi.Point2f(0.5, 0.5))
            covered[y, x] = scene.ray_intersect(ray).is_valid()
            total = np.zeros(3)
            for _ in range(spp):
                radiance, _, _ = integrator.sample(scene, sampler, mi.RayDifferential3f(ray))
                total += np.array(radiance * weight)
                sampler.advance()
            rgb[y, x] = total / spp
    return rgb, covered


if __name__ == "__main__":
    main()
