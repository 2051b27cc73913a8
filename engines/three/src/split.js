// The split estimator's inputs, derived at load time from the engine textures
// (data-schema/engine-textures.md): the BRDF's lobe per view from engine-merl, as weights of the
// Phong layers; the environment's peaks as a few directional lights from engine-environment; and
// the whole environment's layers (engine-full-layers) with its level 0 as one more layer, for the
// GPU's filtering.
//
// The split estimator (mode 'split', the live mode's first frame) draws a pixel without samples,
// as three's own materials draw theirs, from three parts:
// - the diffuse part `f_d` as the prefiltered estimator reads it: pi f_d times the cosine layer at
//   the normal, of the whole environment;
// - the rest of the BRDF at the view, `f - f_d`, as a weighted sum of the Phong layers (and level
//   0) read in the mirror direction: a lobe symmetric about the mirror direction, the table's own
//   albedo at that view times a mixture of the layers' kernels whose encircled energy (the share
//   of the lobe within each angle of the mirror direction) is the table's (lobeMixture). The layers
//   hold the whole environment, so a lamp or the sun reflects with its own shape;
// - each peak light (at most MAX_PEAK_LIGHTS, peakLights) through the table itself, away from its
//   mirror reflection: the table's value at the light's centre less the mixture's, times its
//   power. The mixture places the lobe's broad part around the mirror direction, where a measured
//   table's need not lie (a metal's haze at grazing views, a felt's sheen); near the reflection
//   (within NEAR_RADII of the light's radius, at least NEAR_MIN_DEGREES) the layers alone draw the
//   light, with its shape, and the correction fades in over the next as far again.
// It is biased where the table's lobe is not symmetric about the mirror direction and no peak
// light corrects it (the smooth part of the map), where a light's centre does not stand for it
// (a large lamp seen through a narrow lobe just past the near cone), and in colour across a lobe
// (the mixture's weights are the luminance's); the live mode averages unbiased frames in after it.

import { BakeError } from './loader.js';

/** The most peak lights the split estimator reads through the table (the shader's array size). */
export const MAX_PEAK_LIGHTS = 2;

/** The near cone of a peak light: this many times its radius... */
export const NEAR_RADII = 2;

/** ...and at least this wide, in degrees: the sharp lobes' and the layers' texels' extent. */
export const NEAR_MIN_DEGREES = 2;

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
 * The spread (mean `1 - cos`) a bilinear read of a lat-long layer `height` texels high adds to
 * its kernel: a tent one texel wide along each axis, `E[alpha^2] / 2 = 2 (pi / height)^2 / 6 / 2`.
 */
export function texelSpread(height) {
    return (Math.PI / height) ** 2 / 6;
}

/**
 * The Phong exponents of the layers as read through the GPU's bilinear filtering: spreads add
 * (`1 / (n + 2)`, a Phong lobe's mean `1 - cos`), so `1 / (n' + 2) = 1 / (n + 2) + spread`.
 */
export function effectiveExponents(exponents, spread) {
    return Float32Array.from(exponents, (n) => 1 / (1 / (n + 2) + spread) - 2);
}

// View `r` of `rows` (`1 - cos theta_o = (r + 1/2) / rows`) in the xz plane: wo, its mirror
// direction about the normal (+z), cos and sin theta_o.
function viewOf(r, rows) {
    const cosO = 1 - (r + 0.5) / rows;
    const sinO = Math.sqrt(Math.max(1 - cosO * cosO, 0));
    return { cosO, sinO, wo: [sinO, 0, cosO], mirror: [-sinO, 0, cosO] };
}

// Where lobeMixture's output holds kernel q's weight at view r: row 0's alpha for the first,
// then four to a texel in the rows after it.
function weightIndex(rows, r, q) {
    return q === 0 ? 4 * r + 3 : 4 * (rows * (1 + Math.floor((q - 1) / 4)) + r) + ((q - 1) % 4);
}

/** The angles (radians) at which lobeMixture matches encircled energy: 0.05 to 180 degrees, evenly in log. */
const RADII = Array.from({ length: 48 }, (_, j) => ((0.05 * Math.PI) / 180) * 3600 ** (j / 47));

/**
 * Per view `r` of `rows` (`1 - cos theta_o = (r + 1/2) / rows`, the view layers' rows): the BRDF
 * less its diffuse part `diffuse`, `f - f_d` (at least 0), as its albedo (RGB, the integral of
 * `(f - f_d) cos theta_i`) times a mixture of normalized Phong kernels about the mirror direction
 * of the `exponents` (the layers' and level 0's, as read: effectiveExponents), with weights at
 * least 0 summing to 1, fitted to the lobe's encircled energy: for each angle of RADII, the
 * share of the lobe's luminance within it of the mirror direction against the mixture's (for a
 * Phong kernel `1 - cos^(n + 1)`), in least squares. The integral runs over half vectors:
 * theta_h on MERL's square-root spacing (dense at the peak), `phiSteps` azimuths over the half
 * plane the view's symmetry leaves, `dw_i = 4 (wo . h) dw_h`.
 *
 * Returns `1 + ceil((K - 1) / 4)` rows of `rows` RGBA texels for K exponents: row 0 texel `r`
 * the albedo (RGB) and the first kernel's weight, row `1 + j` the weights of kernels `1 + 4 j`
 * to `4 + 4 j` (0 past the last).
 */
export function lobeMixture(merl, size, phiDRange, diffuse, rows, exponents, phiSteps = 64) {
    const k = exponents.length;
    const textureRows = mixtureRows(k);
    const out = new Float32Array(4 * rows * textureRows);
    const kernels = Array.from(exponents, (n) => RADII.map((a) => (a >= Math.PI / 2 ? 1 : 1 - Math.cos(a) ** (n + 1))));
    const thetaSteps = size[2];
    for (let r = 0; r < rows; r++) {
        const { wo, mirror } = viewOf(r, rows);
        const albedo = [0, 0, 0];
        // The lobe's luminance between consecutive radii (the last bin: past the widest).
        const within = new Float64Array(RADII.length + 1);
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
                if (!(y > 0)) continue;
                const alpha = Math.acos(Math.min(Math.max(wi[0] * mirror[0] + wi[2] * mirror[2], -1), 1));
                let bin = 0;
                while (bin < RADII.length && RADII[bin] < alpha) bin++;
                within[bin] += y;
            }
        }
        const total = within.reduce((a, b) => a + b, 0);
        let sum = 0;
        const encircled = RADII.map((_, j) => {
            sum += within[j];
            return total > 0 ? sum / total : 1;
        });
        const w = simplexLeastSquares(kernels, encircled);
        out.set(albedo, 4 * r);
        w.forEach((v, q) => {
            out[weightIndex(rows, r, q)] = v;
        });
    }
    return out;
}

/** The angles from the mirror direction at which mixtureKernels and lightCorrections tabulate. */
export const ANGLE_STEPS = 64;

/**
 * The mixture's kernel per view `r` of `rows` (lobeMixture's `table`, for the same
 * `exponents`): `sum over k of w_k (n_k + 1) / (2 pi) cos^n_k alpha` (0 past 90 degrees) at
 * `alpha = pi x^2`, `x = (j + 1/2) / ANGLE_STEPS` (dense near the mirror direction): one row of
 * ANGLE_STEPS values per view, the layers' share of a peak light at angle alpha from the mirror
 * direction that lightCorrections takes away.
 */
export function mixtureKernels(table, rows, exponents) {
    const out = new Float32Array(rows * ANGLE_STEPS);
    for (let r = 0; r < rows; r++) {
        const w = Array.from(exponents, (_, q) => table[weightIndex(rows, r, q)]);
        for (let j = 0; j < ANGLE_STEPS; j++) {
            const c = Math.cos(Math.PI * ((j + 0.5) / ANGLE_STEPS) ** 2);
            out[r * ANGLE_STEPS + j] = c > 0 ? w.reduce((sum, wk, q) => sum + (wk * (exponents[q] + 1) * c ** exponents[q]) / (2 * Math.PI), 0) : 0;
        }
    }
    return out;
}

/** The azimuths about the mirror direction at which lightCorrections tabulates. */
export const AZIMUTH_STEPS = 16;

/**
 * What a peak light of unit power at a direction adds to the split estimate beyond what the
 * layers gave of it, per view `r` of `rows`, angle `alpha` from the mirror direction (`pi x^2`,
 * `x = (j + 1/2) / ANGLE_STEPS`) and azimuth `beta` about it (`cos beta = 2 (b + 1/2) /
 * AZIMUTH_STEPS - 1`: 1 towards the normal in the plane of the normal and the view, -1 towards
 * the horizon; the table's symmetry across that plane leaves `|beta|`): the table's `(f - f_d) cos theta_i` at that
 * direction (0 below the horizon) less the mixture's kernel there times the view's albedo (the
 * layers hold the light too, horizon or not). RGBA texels, `ANGLE_STEPS x AZIMUTH_STEPS x
 * rows` (alpha fastest): the shader reads it once per light, filtered linearly, in place of the
 * table and the kernels. `table` is lobeMixture's, `kernels` mixtureKernels'.
 */
export function lightCorrections(merl, size, phiDRange, diffuse, rows, table, kernels) {
    const out = new Float32Array(4 * ANGLE_STEPS * AZIMUTH_STEPS * rows);
    for (let r = 0; r < rows; r++) {
        const { cosO, sinO, wo, mirror } = viewOf(r, rows);
        // About the mirror direction: e1 in the plane of the normal and the view, e2 across it.
        const e1 = [cosO, 0, sinO];
        const albedo = [table[4 * r], table[4 * r + 1], table[4 * r + 2]];
        for (let b = 0; b < AZIMUTH_STEPS; b++) {
            const cosB = (2 * (b + 0.5)) / AZIMUTH_STEPS - 1;
            const sinB = Math.sqrt(Math.max(1 - cosB * cosB, 0));
            for (let j = 0; j < ANGLE_STEPS; j++) {
                const alpha = Math.PI * ((j + 0.5) / ANGLE_STEPS) ** 2;
                const [ca, sa] = [Math.cos(alpha), Math.sin(alpha)];
                const wi = [0, 1, 2].map((c) => ca * mirror[c] + sa * cosB * e1[c] + (c === 1 ? sa * sinB : 0));
                const f = wi[2] > 0 ? merlBrdf(merl, size, phiDRange, wi, wo) : [0, 0, 0];
                const kernel = kernels[r * ANGLE_STEPS + j];
                const at = 4 * ((r * AZIMUTH_STEPS + b) * ANGLE_STEPS + j);
                for (let c = 0; c < 3; c++) out[at + c] = (wi[2] > 0 ? (f[c] - diffuse[c]) * wi[2] : 0) - albedo[c] * kernel;
                out[at + 3] = 1;
            }
        }
    }
    return out;
}

/** The rows of lobeMixture's texture for `k` kernels. */
export function mixtureRows(k) {
    return 1 + Math.ceil((k - 1) / 4);
}

/**
 * The weights `w` (at least 0, summing to 1) of the `columns` that best give `target` in least
 * squares: projected coordinate descent on the normal equations, the sum held by a penalty row
 * weighted as all of the target's rows together.
 */
function simplexLeastSquares(columns, target) {
    const [k, m] = [columns.length, target.length];
    const penalty = m;
    const gram = columns.map((a) => columns.map((b) => penalty + a.reduce((s, v, j) => s + v * b[j], 0)));
    const right = columns.map((a) => penalty + a.reduce((s, v, j) => s + v * target[j], 0));
    const w = new Float64Array(k).fill(1 / k);
    for (let step = 0; step < 500; step++) {
        for (let p = 0; p < k; p++) {
            let g = -right[p];
            for (let q = 0; q < k; q++) g += gram[p][q] * w[q];
            w[p] = Math.max(0, w[p] - g / gram[p][p]);
        }
    }
    return w;
}

/**
 * The environment's peaks (`peaks`: engine-environment's layer 1, RGBA rows of `width x height`,
 * row 0 at the zenith) as at most MAX_PEAK_LIGHTS directional lights: the peak texels clustered
 * about the lights' directions by luminance-weighted spherical k-means (the first centre the
 * brightest texel, each next the texel with the most luminance times `1 - cos` to the centres
 * so far among those more than 10 degrees from all of them, then 16 rounds of assigning each texel to its nearest centre and moving each centre to
 * its texels' luminance-weighted mean direction), so that a sun keeps a light of its own beside
 * the sky around it and a large lamp is one light. Each light's power is its texels' radiance
 * times solid angle summed (RGB, its irradiance at normal incidence), brightest first; its
 * `near` cone's cosines `[cos a, cos 2a]` with `a` NEAR_RADII times its radius
 * (`sqrt(2 spread)`, `spread` the texels' mean `1 - cos` about its direction) and at least
 * NEAR_MIN_DEGREES. Returns `{ count, directions: Float32Array(3 MAX), powers: Float32Array(3 MAX),
 * near: Float32Array(2 MAX) }`.
 */
export function peakLights(peaks, width, height) {
    const texels = [];
    for (let y = 0; y < height; y++) {
        const v = (y + 0.5) / height;
        const s = Math.sin(Math.PI * v);
        const solid = ((2 * Math.PI) / width) * (Math.PI / height) * s;
        for (let x = 0; x < width; x++) {
            const i = 4 * (y * width + x);
            if (!(peaks[i] > 0 || peaks[i + 1] > 0 || peaks[i + 2] > 0)) continue;
            const u = (x + 0.5) / width;
            const rgb = [peaks[i] * solid, peaks[i + 1] * solid, peaks[i + 2] * solid];
            const d = [s * Math.cos(2 * Math.PI * u), s * Math.sin(2 * Math.PI * u), Math.cos(Math.PI * v)];
            texels.push({ d, rgb, lum: luminance(rgb) });
        }
    }
    const centres = [];
    if (texels.length > 0) centres.push(texels.reduce((a, b) => (b.lum > a.lum ? b : a)).d);
    while (centres.length < MAX_PEAK_LIGHTS) {
        let best;
        let score = 0;
        for (const t of texels) {
            const near = Math.max(...centres.map((c) => dot(c, t.d)));
            const s = t.lum * (1 - near);
            if (near < SEPARATION_COS && s > score) [best, score] = [t, s];
        }
        if (!best) break;
        centres.push(best.d);
    }
    let groups = [];
    for (let round = 0; round < 16; round++) {
        groups = centres.map(() => ({ power: [0, 0, 0], dir: [0, 0, 0], weight: 0 }));
        for (const t of texels) {
            let near = 0;
            for (let c = 1; c < centres.length; c++) if (dot(centres[c], t.d) > dot(centres[near], t.d)) near = c;
            const g = groups[near];
            for (let c = 0; c < 3; c++) {
                g.power[c] += t.rgb[c];
                g.dir[c] += t.lum * t.d[c];
            }
            g.weight += t.lum;
        }
        groups.forEach((g, c) => {
            if (g.weight > 0) centres[c] = unit(g.dir);
        });
    }
    groups = groups.filter((g) => g.weight > 0).sort((a, b) => luminance(b.power) - luminance(a.power));
    if (!groups.every((g) => g.power.every(Number.isFinite))) throw new BakeError('error: the peaks sum to a value that is not finite');
    const directions = new Float32Array(3 * MAX_PEAK_LIGHTS);
    const powers = new Float32Array(3 * MAX_PEAK_LIGHTS);
    const near = new Float32Array(2 * MAX_PEAK_LIGHTS);
    groups.forEach((g, i) => {
        directions.set(unit(g.dir), 3 * i);
        powers.set(g.power, 3 * i);
        // E[1 - cos] of the light's directions about their mean: 1 - |E[d]|.
        const spread = Math.min(Math.max(1 - Math.hypot(...g.dir) / g.weight, 0), 1);
        const a = Math.max(NEAR_RADII * Math.sqrt(2 * spread), (NEAR_MIN_DEGREES * Math.PI) / 180);
        near.set([Math.cos(a), Math.cos(Math.min(2 * a, Math.PI))], 2 * i);
    });
    return { count: groups.length, directions, powers, near };
}

// A texel within 10 degrees of a centre starts no other: one source stays one light.
const SEPARATION_COS = Math.cos((10 * Math.PI) / 180);

const luminance = (p) => 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const unit = (d) => {
    const len = Math.hypot(...d);
    return len > 0 ? d.map((c) => c / len) : [0, 0, 1];
};

/**
 * engine-full-layers' `depth` layers (RGBA rows of `width x height`) and one more: the
 * environment's level 0 (engine-environment's layer 0, `envWidth x envHeight`: what
 * layer_bilinear reads past the sharpest layer) averaged down to the layers' size, each layer
 * texel the mean of the level-0 texels whose centres it covers (the nearest one where none
 * does). The split estimator's uLayersLinear.
 */
export function splitLayers(layers, width, height, depth, environment, envWidth, envHeight) {
    const out = new Float32Array(4 * width * height * (depth + 1));
    out.set(layers.subarray(0, 4 * width * height * depth));
    const base = 4 * width * height * depth;
    const sum = new Float64Array(4 * width * height);
    const count = new Uint32Array(width * height);
    for (let y = 0; y < envHeight; y++) {
        const ly = Math.min(Math.floor(((y + 0.5) / envHeight) * height), height - 1);
        for (let x = 0; x < envWidth; x++) {
            const lx = Math.min(Math.floor(((x + 0.5) / envWidth) * width), width - 1);
            const e = 4 * (y * envWidth + x);
            const l = ly * width + lx;
            for (let c = 0; c < 3; c++) sum[4 * l + c] += environment[e + c];
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
            mean = [environment[e], environment[e + 1], environment[e + 2]];
        }
        out.set([...mean, 1], base + 4 * l);
    }
    return out;
}
