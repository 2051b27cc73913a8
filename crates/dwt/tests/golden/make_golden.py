#!/usr/bin/env python3
"""Golden vectors for the `dwt` crate, produced by PyWavelets.

Generated with PyWavelets 1.9.0 and numpy 2.4.6 (Python 3.11). To regenerate, from the
repository root:

    python3 -m pip install PyWavelets==1.9.0 numpy==2.4.6
    python3 crates/dwt/tests/golden/make_golden.py

The output is deterministic (fixed seeds) and is written next to this script as
`golden_1d.json` and `golden_2d.json`. Floats are written with Python's `repr` (shortest string
that round-trips to the same float64).

Layout of every case (2D arrays are flat, row-major, shape [height, width] = numpy's shape):

- `wavelet`: "db2" or "haar"; `shape`: [n] or [height, width]; `max_level`: J.
- Forward: `input` x; `approx[j-1]` = cA_j (the approximation after j levels); `details[j-1]` =
  cD_j (1D) or [cH_j, cV_j, cD_j] (2D) for level j = 1 (finest) .. J. For every L in 1..=J,
  `pywt.wavedec(x, w, mode="periodization", level=L)` equals
  [approx[L-1], details[L-1], ..., details[0]] exactly (asserted below), so the details are
  stored once instead of once per L.
- Inverse: random coefficients `inv_approx` (the level-J approximation) and `inv_details`
  (same layout as `details`), and `inv_recon[L]` for L = 0..J-1: for every L in 1..=J,
  `pywt.waverec([inv_recon[L], inv_details[L-1], ..., inv_details[0]], w, mode="periodization")`
  equals inv_recon[0], where inv_recon[J] would be inv_approx (asserted below).

Inputs and random coefficients are multiples of 0.001 in [-1, 1] so that they print short.
"""

import importlib.metadata
import json
import pathlib
import warnings

import numpy as np
import pywt

MODE = "periodization"
WAVELETS = ["db2", "haar"]
SIZES_1D = [8, 16, 64, 128, 24, 40]
# [height, width]. 24x40 and 24x8 are not powers of two (at most 3 levels). Haar gets smaller
# images to keep the files small: it runs through the same code as db2 with other filters.
SIZES_2D = {"db2": [[16, 16], [32, 32], [64, 32], [24, 40]], "haar": [[16, 16], [16, 32], [24, 8]]}

# Levels deeper than pywt.dwt_max_level are fine with periodization; silence pywt's warning.
warnings.filterwarnings("ignore", message="Level value of")


def max_level(n):
    """The crate's rule: a level needs an even length, so at most the number of factors 2."""
    return (n & -n).bit_length() - 1


def short_random(rng, shape):
    return rng.integers(-1000, 1001, size=shape) / 1000.0


def flat(a):
    return [float(v) for v in np.asarray(a, dtype=np.float64).ravel()]


def case_1d(rng, w, n):
    J = max_level(n)
    x = short_random(rng, n)
    full = pywt.wavedec(x, w, mode=MODE, level=J)
    details = full[1:][::-1]  # finest first
    approx = []
    a = x
    for _ in range(J):
        a, _d = pywt.dwt(a, w, mode=MODE)
        approx.append(a)
    for L in range(1, J + 1):
        got = pywt.wavedec(x, w, mode=MODE, level=L)
        want = [approx[L - 1]] + details[:L][::-1]
        assert all(np.array_equal(g, e) for g, e in zip(got, want, strict=True))

    inv_approx = short_random(rng, n >> J)
    inv_details = [short_random(rng, n >> j) for j in range(1, J + 1)]
    recon = [None] * (J + 1)
    recon[J] = inv_approx
    for j in range(J, 0, -1):
        recon[j - 1] = pywt.idwt(recon[j], inv_details[j - 1], w, mode=MODE)
    for L in range(1, J + 1):
        got = pywt.waverec([recon[L]] + inv_details[:L][::-1], w, mode=MODE)
        assert np.array_equal(got, recon[0])
    return {
        "wavelet": w,
        "shape": [n],
        "max_level": J,
        "input": flat(x),
        "approx": [flat(a) for a in approx],
        "details": [flat(d) for d in details],
        "inv_approx": flat(inv_approx),
        "inv_details": [flat(d) for d in inv_details],
        "inv_recon": [flat(r) for r in recon[:J]],
    }


def case_2d(rng, w, shape):
    h, wd = shape
    J = min(max_level(h), max_level(wd))
    x = short_random(rng, (h, wd))
    full = pywt.wavedec2(x, w, mode=MODE, level=J)
    details = full[1:][::-1]
    approx = []
    a = x
    for _ in range(J):
        a, _d = pywt.dwt2(a, w, mode=MODE)
        approx.append(a)
    for L in range(1, J + 1):
        got = pywt.wavedec2(x, w, mode=MODE, level=L)
        want = [approx[L - 1]] + details[:L][::-1]
        assert np.array_equal(got[0], want[0])
        for g, e in zip(got[1:], want[1:], strict=True):
            assert all(np.array_equal(gi, ei) for gi, ei in zip(g, e, strict=True))

    inv_approx = short_random(rng, (h >> J, wd >> J))
    inv_details = [tuple(short_random(rng, (h >> j, wd >> j)) for _ in range(3)) for j in range(1, J + 1)]
    recon = [None] * (J + 1)
    recon[J] = inv_approx
    for j in range(J, 0, -1):
        recon[j - 1] = pywt.idwt2((recon[j], inv_details[j - 1]), w, mode=MODE)
    for L in range(1, J + 1):
        got = pywt.waverec2([recon[L]] + inv_details[:L][::-1], w, mode=MODE)
        assert np.array_equal(got, recon[0])
    return {
        "wavelet": w,
        "shape": [h, wd],
        "max_level": J,
        "input": flat(x),
        "approx": [flat(a) for a in approx],
        "details": [[flat(o) for o in d] for d in details],
        "inv_approx": flat(inv_approx),
        "inv_details": [[flat(o) for o in d] for d in inv_details],
        "inv_recon": [flat(r) for r in recon[:J]],
    }


def main():
    out = pathlib.Path(__file__).resolve().parent
    # pywt.__version__ of the 1.9.0 wheel still says 1.8.0; the installed distribution is the truth.
    version = importlib.metadata.version("PyWavelets")
    provenance = f"PyWavelets {version}, numpy {np.__version__}, mode {MODE}; see make_golden.py"
    rng = np.random.default_rng(20240611)
    cases = [case_1d(rng, w, n) for w in WAVELETS for n in SIZES_1D]
    (out / "golden_1d.json").write_text(json.dumps({"provenance": provenance, "cases": cases}) + "\n")
    rng = np.random.default_rng(20240612)
    cases = [case_2d(rng, w, s) for w in WAVELETS for s in SIZES_2D[w]]
    (out / "golden_2d.json").write_text(json.dumps({"provenance": provenance, "cases": cases}) + "\n")


if __name__ == "__main__":
    main()
