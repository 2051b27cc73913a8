// The split estimator's inputs, derived at load time from the engine textures (as the peaks and
// the smooth part are: data-schema/engine-textures.md): the BRDF's lobes per view from
// engine-merl, the environment's peaks as a few directional lights from engine-environment, and
// the layers with the smooth part's level 0 as one more, for the GPU's filtering.
//
// The split estimator (mode 'split', the live mode's first frame) draws a pixel without samples,
// as three's own materials draw theirs: the diffuse part as the prefiltered estimator reads it
// (pi f_d times the cosine layer at the normal); the rest of the BRDF at the view, `f - f_d`, as
// two normalized Phong lobes around the mirror direction with the table's albedo and widths at
// that view, each read from the Phong layer of its width in the mirror direction (the split of a
// lobe into its albedo and a prefiltered lookup, with the table's own albedo where a split sum
// has a fitted BRDF's); each peak light through the diffuse part and the lobes widened by the
// light's spread, the brightest through the table itself in place of the broader lobe. It is
// biased where the lobes are not Phong lobes around the mirror direction (off-specular peaks
// towards grazing angles, Fresnel colour changing across a lobe) and where a peak is large or
// not round; the live mode averages unbiased frames in after it.

import { BakeError } from './loader.js';

/** The most peak lights the split estimator reads (the shader's array size). */
export const MAX_PEAK_LIGHTS = 4;

/**
 * The grid over the map (columns, rows) whose cells a peak light stays within: a lamp larger than
 * a cell becomes a light per cell it covers, a few Gaussians closer to its shape than one.
 */
export const PEAK_CELLS = [16, 8];

// merl::half_diff (the shader's merl_half_diff): (theta_h, theta_d, phi_d) of a direction pair.
function halfDiff(wi, wo) {
    let [hx, hy, hz] = [wi[0] + wo[0], wi[1] + wo[1], wi[2] + wo[2]];
    const len = Math.hypot(hx, hy, hz);
    [hx, hy, hz] = [hx / len, hy / len, hz / len];
    const thetaH = Math.atan2(Math.hypot(hx, hy), hz);
    const phiH = hx === 0 && hy === 0 ? 0 : Math.atan2(hy, hx);
    // wi turned by -phi_h about z, then by -theta_h about y.
    const [cz, sz] = [Math.cos(-phiH), Math.sin(-phiH)];
    const [x1, y1, z1] = [wi[0] * cz - wi[1] * sz, wi[0] * sz + wi[1] * cz, wi[2]];
    const [cy, sy] = [Math.cos(-thetaH), Math.sin(-thetaH)];
    const [dx, dy, dz] = [x1 * cy + z1 * sy, y1, -x1 * sy + z1 * cy];
    return [thetaH, Math.atan2(Math.hypot(dx, dy), dz), dx === 0 && dy === 0 ? 0 : Math.atan2(dy, dx)];
}

/**
 * The nearest-cell BRDF of engine-merl's `data` (RGBA, `[n_phi_d, n_theta_d, n_theta_h]` =
 * `size`) at a direction pair, RGB in 1/sr: the shader's material_brdf.
 */
export function merlBrdf(data, size, phiDRange, wi, wo) {
    const [np, nd, nh] = size;
    const [thetaH, thetaD, phiD0] = halfDiff(wi, wo);
    const phiD = phiD0 < 0 ? phiD0 + phiDRange : phiD0;
    const index = (x, n) => Math.min(Math.max(Math.floor(x), 0), n - 1);
    const h = index(Math.sqrt(Math.max(thetaH, 0) / (Math.PI / 2)) * nh, nh);
    const d = index((thetaD / (Math.PI / 2)) * nd, nd);
    const p = index((phiD / phiDRange) * np, np);
    const i = 4 * ((h * nd + d) * np + p);
    return [data[i], data[i + 1], data[i + 2]];
}

/**
 * Per view `r` of `rows` (`1 - cos theta_o = (r + 1/2) / rows`, the view layers' rows): the BRDF
 * less its diffuse part `diffuse` as two normalized Phong lobes around the mirror direction
 * (twoLobes, on the directions weighted by that part's luminance times cos theta_i), its albedo
 * (RGB, `integral of (f - f_d) cos theta_i`) shared between them. Two rows of RGBA texels: row 0
 * texel `r` the sharper lobe's albedo (RGB) and exponent (from 0 to 1e6); row 1 texel `r` the
 * broader lobe's albedo over the sharper's (the two have the same colour), its exponent, and the
 * two exponents' layer coordinates among `exponents` (layerCoordinate). The integral runs over
 * half vectors: theta_h on MERL's square-root spacing (dense at the peak), `phiSteps` azimuths
 * over the half plane the view's symmetry leaves, `dw_i = 4 (wo . h) dw_h`.
 */
export function lobeTable(merl, size, phiDRange, diffuse, rows, exponents, phiSteps = 64) {
    const out = new Float32Array(8 * rows);
    const thetaSteps = size[2];
    for (let r = 0; r < rows; r++) {
        const cosO = 1 - (r + 0.5) / rows;
        const sinO = Math.sqrt(Math.max(1 - cosO * cosO, 0));
        const wo = [sinO, 0, cosO];
        const mirror = [-sinO, 0, cosO];
        const albedo = [0, 0, 0];
        const spread = [];
        for (let i = 0; i < thetaSteps; i++) {
            // theta_h = (x / N)^2 pi / 2 at the cell's centre x = i + 1/2; d theta_h = pi x / N^2.
            const x = (i + 0.5) / thetaSteps;
            const thetaH = x * x * (Math.PI / 2);
            const dThetaH = (Math.PI * x) / thetaSteps;
            const [st, ct] = [Math.sin(thetaH), Math.cos(thetaH)];
            for (let j = 0; j < phiSteps; j++) {
                const phiH = (Math.PI * (j + 0.5)) / phiSteps;
                const h = [st * Math.cos(phiH), st * Math.sin(phiH), ct];
                const woH = wo[0] * h[0] + wo[2] * h[2];
                if (!(woH > 0)) continue;
                const wi = [2 * woH * h[0] - wo[0], 2 * woH * h[1], 2 * woH * h[2] - wo[2]];
                if (!(wi[2] > 0)) continue;
                // Both halves of the azimuth: the view lies in the xz plane.
                const dw = 2 * 4 * woH * st * dThetaH * (Math.PI / phiSteps);
                const f = merlBrdf(merl, size, phiDRange, wi, wo);
                const rest = f.map((v, c) => Math.max(v - diffuse[c], 0) * wi[2] * dw);
                for (let c = 0; c < 3; c++) albedo[c] += rest[c];
                const y = 0.2126 * rest[0] + 0.7152 * rest[1] + 0.0722 * rest[2];
                if (y > 0) spread.push([wi[0] * mirror[0] + wi[2] * mirror[2], y]);
            }
        }
        const [w, n1, n2] = twoLobes(spread);
        // The sharper lobe's share at least 1e-6, so that the broader's over it stays finite.
        const share = Math.max(w, 1e-6);
        out.set([...albedo.map((v) => share * v), n1], 4 * r);
        out.set([(1 - share) / share, n2, layerCoordinate(n1, exponents), layerCoordinate(n2, exponents)], 4 * (rows + r));
    }
    return out;
}

/**
 * render::exponent_layer: the layer coordinate `k + t` of Phong exponent `n` among the layers'
 * `exponents` followed by the exponent past the sharpest (uLayerExponents), from 0 to the
 * number of layers.
 */
export function layerCoordinate(n, exponents) {
    const layers = exponents.length - 1;
    if (!(n > exponents[0])) return 0;
    if (n >= exponents[layers]) return layers;
    let k = 0;
    while (k + 1 < layers && exponents[k + 1] <= n) k++;
    const a = Math.log(exponents[k]);
    return k + (Math.log(n) - a) / (Math.log(exponents[k + 1]) - a);
}

// The density of a normalized Phong lobe of exponent n where ln cos alpha = log, per unit solid
// angle.
const phong = (n, log) => ((n + 1) / (2 * Math.PI)) * Math.exp(n * log);

/**
 * A mixture of two normalized Phong lobes around the mirror direction that best explains the
 * weighted directions `spread` (`[cos alpha, weight]`): `[w, n1, n2]`, the first lobe's share and
 * the exponents, the sharper first. Maximum likelihood by expectation-maximization (given its
 * directions, a lobe's exponent is `n + 1 = -1 / E[ln cos alpha]`), from a sharp and a broad start
 * around the one-lobe estimate.
 */
function twoLobes(spread) {
    const points = spread.map(([c, y]) => {
        const clamped = Math.min(Math.max(c, 1e-6), 1 - 1e-9);
        return [clamped, y, Math.log(clamped)];
    });
    const total = points.reduce((sum, [, y]) => sum + y, 0);
    if (!(total > 0)) return [1, 0, 0];
    const meanLog = points.reduce((sum, [, y, log]) => sum + y * log, 0) / total;
    const one = Math.min(-1 / meanLog - 1, 1e6);
    let [w, n1, n2] = [0.5, Math.min(16 * one + 16, 1e6), Math.max(one / 4, 0)];
    for (let step = 0; step < 32; step++) {
        let [s1, l1, l2] = [0, 0, 0];
        for (const [, y, log] of points) {
            const p1 = w * phong(n1, log);
            const p2 = (1 - w) * phong(n2, log);
            const r = p1 + p2 > 0 ? p1 / (p1 + p2) : 0.5;
            s1 += y * r;
            l1 += y * r * log;
            l2 += y * (1 - r) * log;
        }
        w = s1 / total;
        n1 = l1 < 0 ? Math.min(Math.max(-s1 / l1 - 1, 0), 1e6) : 1e6;
        n2 = l2 < 0 ? Math.min(Math.max(-(total - s1) / l2 - 1, 0), 1e6) : 1e6;
    }
    return n1 >= n2 ? [w, n1, n2] : [1 - w, n2, n1];
}

/**
 * The environment's peaks (`peaks`: engine-environment's layer 1, RGBA rows of `width x height`,
 * row 0 at the zenith) as at most MAX_PEAK_LIGHTS directional lights: the peak texels joined where
 * they touch (8 neighbours) within a cell of PEAK_CELLS, each group's irradiance at normal incidence (RGB, the
 * sum of radiance times solid angle) and its direction (the luminance-weighted mean, +z up); the
 * brightest groups kept, each other group added to the kept one nearest in direction; and each
 * light's spread, the mean of `1 - cos` between its texels' directions and its own (luminance
 * weighted). Returns `{ count, directions: Float32Array(3 MAX), powers: Float32Array(3 MAX),
 * spreads: Float32Array(MAX) }`.
 */
export function peakLights(peaks, width, height) {
    const label = new Int32Array(width * height).fill(-1);
    const groups = [];
    // The cell of PEAK_CELLS a texel lies in (columns from u = 0, rows from the zenith).
    const cellOf = (k) =>
        Math.floor(((k % width) * PEAK_CELLS[0]) / width) + PEAK_CELLS[0] * Math.floor((Math.floor(k / width) * PEAK_CELLS[1]) / height);
    const lit = (k) => peaks[4 * k] > 0 || peaks[4 * k + 1] > 0 || peaks[4 * k + 2] > 0;
    for (let start = 0; start < width * height; start++) {
        if (label[start] >= 0 || !lit(start)) continue;
        const g = { power: [0, 0, 0], dir: [0, 0, 0], weight: 0 };
        label[start] = groups.length;
        const stack = [start];
        while (stack.length > 0) {
            const k = stack.pop();
            const [x, y] = [k % width, Math.floor(k / width)];
            const v = (y + 0.5) / height;
            const u = (x + 0.5) / width;
            const solid = ((2 * Math.PI) / width) * (Math.PI / height) * Math.sin(Math.PI * v);
            const rgb = [peaks[4 * k], peaks[4 * k + 1], peaks[4 * k + 2]].map((c) => c * solid);
            const lum = 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2];
            const s = Math.sin(Math.PI * v);
            const d = [s * Math.cos(2 * Math.PI * u), s * Math.sin(2 * Math.PI * u), Math.cos(Math.PI * v)];
            for (let c = 0; c < 3; c++) {
                g.power[c] += rgb[c];
                g.dir[c] += lum * d[c];
            }
            g.weight += lum;
            for (let dy = -1; dy <= 1; dy++) {
                const ny = y + dy;
                if (ny < 0 || ny >= height) continue;
                for (let dx = -1; dx <= 1; dx++) {
                    const n = ny * width + ((x + dx + width) % width);
                    if (label[n] < 0 && lit(n) && cellOf(n) === cellOf(start)) {
                        label[n] = groups.length;
                        stack.push(n);
                    }
                }
            }
        }
        groups.push(g);
    }
    const lum = (p) => 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
    const unit = (d) => {
        const len = Math.hypot(...d);
        return len > 0 ? d.map((c) => c / len) : [0, 0, 1];
    };
    groups.sort((a, b) => lum(b.power) - lum(a.power));
    const kept = groups.slice(0, MAX_PEAK_LIGHTS);
    const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    for (const g of groups.slice(MAX_PEAK_LIGHTS)) {
        const d = unit(g.dir);
        const near = kept.reduce((best, k) => (dot(unit(k.dir), d) > dot(unit(best.dir), d) ? k : best));
        for (let c = 0; c < 3; c++) {
            near.power[c] += g.power[c];
            near.dir[c] += g.dir[c];
        }
        near.weight += g.weight;
    }
    const directions = new Float32Array(3 * MAX_PEAK_LIGHTS);
    const powers = new Float32Array(3 * MAX_PEAK_LIGHTS);
    const spreads = new Float32Array(MAX_PEAK_LIGHTS);
    kept.forEach((k, i) => {
        directions.set(unit(k.dir), 3 * i);
        powers.set(k.power, 3 * i);
        // E[1 - cos] of the light's directions about their mean: 1 - |E[d]|.
        spreads[i] = k.weight > 0 ? Math.min(Math.max(1 - Math.hypot(...k.dir) / k.weight, 0), 1) : 0;
    });
    if (!kept.every((k) => k.power.every(Number.isFinite))) throw new BakeError('error: the peaks sum to a value that is not finite');
    return { count: kept.length, directions, powers, spreads };
}

/**
 * engine-layers' `depth` layers (RGBA rows of `width x height`) and one more: the smooth part's
 * level 0 (engine-environment's level 0 less its peaks, `envWidth x envHeight`, at least 0: what
 * layer_bilinear reads past the sharpest layer) averaged down to the layers' size, each layer
 * texel the mean of the level-0 texels whose centres it covers (the nearest one where none
 * does). The split estimator's uLayersLinear.
 */
export function splitLayers(layers, width, height, depth, environment, envWidth, envHeight) {
    const out = new Float32Array(4 * width * height * (depth + 1));
    out.set(layers.subarray(0, 4 * width * height * depth));
    const peaks = 4 * envWidth * envHeight;
    const base = 4 * width * height * depth;
    const sum = new Float64Array(4 * width * height);
    const count = new Uint32Array(width * height);
    for (let y = 0; y < envHeight; y++) {
        const ly = Math.min(Math.floor(((y + 0.5) / envHeight) * height), height - 1);
        for (let x = 0; x < envWidth; x++) {
            const lx = Math.min(Math.floor(((x + 0.5) / envWidth) * width), width - 1);
            const e = 4 * (y * envWidth + x);
            const l = ly * width + lx;
            for (let c = 0; c < 3; c++) sum[4 * l + c] += Math.max(environment[e + c] - environment[peaks + e + c], 0);
            count[l] += 1;
        }
    }
    for (let l = 0; l < width * height; l++) {
        let mean;
        if (count[l] > 0) {
            mean = [0, 1, 2].map((c) => sum[4 * l + c] / count[l]);
        } else {
            // The nearest level-0 texel to this texel's centre.
            const [lx, ly] = [l % width, Math.floor(l / width)];
            const ex = Math.min(Math.floor(((lx + 0.5) / width) * envWidth), envWidth - 1);
            const ey = Math.min(Math.floor(((ly + 0.5) / height) * envHeight), envHeight - 1);
            const e = 4 * (ey * envWidth + ex);
            mean = [0, 1, 2].map((c) => Math.max(environment[e + c] - environment[peaks + e + c], 0));
        }
        out.set([...mean, 1], base + 4 * l);
    }
    return out;
}
