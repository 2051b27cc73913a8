#!/usr/bin/env python3
"""Independent reference values for the envmap loader tests (tests/real_maps.rs).

Radiance HDR: decoded by the small RGBE reader below (written from the Radiance file format
description, new and old run-length schemes), value = mantissa * 2^(exponent - 136) with no
+0.5 bias, the convention of the `image` crate and three.js (Radiance's own `colr_color` adds
0.5 to the mantissa; that would shift every value by up to half a quantisation step).
OpenEXR: decoded by the reference C++ library through its Python bindings (`pip install OpenEXR
numpy`, OpenEXR 3.5.3), full-resolution level.

Prints, per file: size, the max and its texel, the plain mean over all texels and channels, the
solid-angle-weighted mean per channel, and a few spot texels. Run from anywhere:
    python3 spot_values.py /path/to/shared/data/env
"""
import math
import sys
from pathlib import Path

import numpy as np


def read_hdr(path):
    data = Path(path).read_bytes()
    pos = 0

    def line():
        nonlocal pos
        end = data.index(b"\n", pos)
        out = data[pos:end]
        pos = end + 1
        return out

    assert line().startswith(b"#?")
    while line().strip():
        pass
    parts = line().split()
    assert parts[0] == b"-Y" and parts[2] == b"+X"
    height, width = int(parts[1]), int(parts[3])
    rgbe = np.zeros((height, width, 4), dtype=np.uint8)
    for y in range(height):
        row = rgbe[y]
        if width >= 8 and width < 32768 and data[pos] == 2 and data[pos + 1] == 2 and data[pos + 2] < 128:
            assert (data[pos + 2] << 8 | data[pos + 3]) == width
            pos += 4
            for c in range(4):
                x = 0
                while x < width:
                    n = data[pos]
                    pos += 1
                    if n > 128:
                        n -= 128
                        row[x:x + n, c] = data[pos]
                        pos += 1
                    else:
                        row[x:x + n, c] = list(data[pos:pos + n])
                        pos += n
                    x += n
        else:  # flat or old run-length scheme
            x = 0
            shift = 0
            while x < width:
                px = data[pos:pos + 4]
                pos += 4
                if px[0] == 1 and px[1] == 1 and px[2] == 1:
                    n = px[3] << shift
                    row[x:x + n] = row[x - 1]
                    x += n
                    shift += 8
                else:
                    row[x] = list(px)
                    x += 1
                    shift = 0
    e = rgbe[..., 3].astype(np.int32)
    scale = np.where(e == 0, 0.0, np.ldexp(1.0, e - 136))
    return rgbe[..., :3].astype(np.float64) * scale[..., None]


def read_exr(path):
    import OpenEXR

    with OpenEXR.File(str(path)) as f:
        channels = f.channels()
        if "RGB" in channels:
            rgb = channels["RGB"].pixels
        elif "RGBA" in channels:
            rgb = channels["RGBA"].pixels[..., :3]
        else:
            rgb = np.stack([channels[c].pixels for c in "RGB"], axis=-1)
    return rgb.astype(np.float64)


def weighted_mean(rgb):
    h, w, _ = rgb.shape
    theta0 = math.pi * np.arange(h) / h
    theta1 = math.pi * (np.arange(h) + 1) / h
    omega = (np.cos(theta0) - np.cos(theta1)) * 2 * math.pi / w
    return (rgb * omega[:, None, None]).sum(axis=(0, 1)) / (4 * math.pi)


def main():
    root = Path(sys.argv[1])
    names = ["quarry_01_1k.hdr", "potsdamer_platz_1k.hdr", "studio_small_03_1k.hdr", "piz_compressed.exr",
             "KernerEnvLatLong.exr", "decoder/imagers_old-rle.hdr", "decoder/imagers_scale.hdr",
             "decoder/imagers_rgbr4x4.hdr", "decoder/memorial.exr"]
    for name in names:
        path = root / name
        rgb = read_exr(path) if name.endswith(".exr") else read_hdr(path)
        h, w, _ = rgb.shape
        y, x, c = np.unravel_index(np.argmax(rgb), rgb.shape)
        print(f"{name}: {w} x {h}, max {rgb.max():.9g} at x {x} y {y} channel {c}, mean {rgb.mean():.9g}, "
              f"min {rgb.min():.9g}")
        if w == 2 * h:
            print("  weighted mean", [f"{m:.9g}" for m in weighted_mean(rgb)])
        for (sx, sy) in [(0, 0), (w // 3, h // 5), (w - 1, h // 2), (w // 2, h - 1)]:
            print(f"  texel x {sx} y {sy}:", [float(np.float32(v)) for v in rgb[sy, sx]])


if __name__ == "__main__":
    main()
