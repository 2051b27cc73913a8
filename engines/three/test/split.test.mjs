// The split estimator's inputs derived at load time (split.js; node --test), against analytic
// answers: the lobe mixture of a Lambertian table (its albedo exactly, nothing left once its
// diffuse part is taken) and of a Phong lobe table (its albedo, its weight on the layer of its
// exponent), the mixture's kernels, the peak lights' corrections (none where the mixture is the
// table, the layers' share taken below the horizon), the peak lights of a peaks image (their
// power as the sum of radiance times solid angle, a sun kept apart from a lamp, no power lost),
// and level 0 averaged down to the layers' size.
import assert from 'node:assert/strict';
import { test } from 'node:test';

import {
    AZIMUTH_STEPS,
    ANGLE_STEPS,
    MAX_PEAK_LIGHTS,
    NEAR_MIN_DEGREES,
    effectiveExponents,
    lightCorrections,
    lobeMixture,
    merlBrdf,
    mixtureKernels,
    mixtureRows,
    peakLights,
    splitLayers,
    texelSpread,
} from '../src/split.js';

// MERL's 90 x 90 x 180 grid (phi_d over pi, reciprocity's fold), each cell the BRDF `f(wi, wo)`
// at its centre: theta_h = ((h + 1/2) / 90)^2 pi / 2, theta_d and phi_d at their cells' middles,
// the half vector in the xz plane (the table is isotropic).
const SIZE = [180, 90, 90];
function table(f) {
    const [np, nd, nh] = SIZE;
    const data = new Float32Array(4 * np * nd * nh);
    for (let h = 0; h < nh; h++) {
        const thetaH = ((h + 0.5) / nh) ** 2 * (Math.PI / 2);
        const half = [Math.sin(thetaH), 0, Math.cos(thetaH)];
        for (let d = 0; d < nd; d++) {
            const thetaD = ((d + 0.5) / nd) * (Math.PI / 2);
            for (let p = 0; p < np; p++) {
                const phiD = ((p + 0.5) / np) * Math.PI;
                const diff = [Math.sin(thetaD) * Math.cos(phiD), Math.sin(thetaD) * Math.sin(phiD), Math.cos(thetaD)];
                // wi: the difference vector turned back by theta_h about y; wo its reflection about h.
                const wi = [diff[0] * Math.cos(thetaH) + diff[2] * Math.sin(thetaH), diff[1], -diff[0] * Math.sin(thetaH) + diff[2] * Math.cos(thetaH)];
                const k = 2 * (wi[0] * half[0] + wi[2] * half[2]);
                const wo = [k * half[0] - wi[0], -wi[1], k * half[2] - wi[2]];
                const v = wi[2] > 0 && wo[2] > 0 ? f(wi, wo) : 0;
                data.set([v, v, v, 1], 4 * ((h * nd + d) * np + p));
            }
        }
    }
    return data;
}

test('a cell centre reads back its own value (merlBrdf is the inverse of the table above)', () => {
    const data = table((wi, wo) => wi[2] + 2 * wo[2]);
    const [wi, wo] = [[0.3, 0.1, Math.sqrt(1 - 0.1)], [-0.2, 0.4, Math.sqrt(1 - 0.2)]];
    // The nearest cell of the pair: its value is the function at the cell's centre, close to the pair's.
    const v = merlBrdf(data, SIZE, Math.PI, wi, wo)[0];
    assert.ok(Math.abs(v - (wi[2] + 2 * wo[2])) < 0.05, `${v}`);
});

test("a Lambertian table's albedo is its reflectance, and nothing is left once its diffuse part is taken", () => {
    const rho = 0.5;
    const data = table(() => rho / Math.PI);
    const rows = 16;
    const exponents = [1, 4, 16, 64, 256];
    const all = lobeMixture(data, SIZE, Math.PI, [0, 0, 0], rows, exponents);
    const rest = lobeMixture(data, SIZE, Math.PI, [rho / Math.PI, rho / Math.PI, rho / Math.PI], rows, exponents);
    for (let r = 0; r < rows; r++) {
        // The quadrature over half vectors is within 1% of the hemisphere's integral of cos (pi)
        // except at the most grazing views (2%).
        assert.ok(Math.abs(all[4 * r] - rho) < (r < rows - 2 ? 0.01 : 0.02) * rho, `row ${r}: ${all[4 * r]}`);
        assert.ok(Math.abs(rest[4 * r]) < 1e-6, `row ${r}`);
    }
});

// A table whose f cos theta_i is A (n + 1) / (2 pi) cos^n alpha about the mirror direction.
function phongTable(albedo, n) {
    return table((wi, wo) => {
        const cosAlpha = wi[0] * -wo[0] + wi[1] * -wo[1] + wi[2] * wo[2];
        return cosAlpha > 0 ? (albedo * (n + 1) * cosAlpha ** n) / (2 * Math.PI * wi[2]) : 0;
    });
}

// Kernel q's weight in lobeMixture's output at view r.
const weight = (out, rows, r, q) => (q === 0 ? out[4 * r + 3] : out[4 * (rows * (1 + Math.floor((q - 1) / 4)) + r) + ((q - 1) % 4)]);

test("a Phong lobe's albedo comes back, its weight on the layer of its exponent", () => {
    const [albedo, n] = [0.3, 64];
    const exponents = [1, 4, 16, 64, 256, 1024];
    const rows = 8;
    const out = lobeMixture(phongTable(albedo, n), SIZE, Math.PI, [0, 0, 0], rows, exponents);
    assert.equal(out.length, 4 * rows * mixtureRows(exponents.length));
    // Row 1: 1 - cos theta_o = 3/16, theta_o 36 degrees; the lobe (half width 8 degrees at half
    // its height) lies above the horizon. The nearest-cell table misses a little of the peak.
    assert.ok(Math.abs(out[4] - albedo) < 0.03 * albedo, `${out[4]}`);
    const w = exponents.map((_, q) => weight(out, rows, 1, q));
    assert.ok(w.every((v) => v >= 0), `${w}`);
    assert.ok(Math.abs(w.reduce((a, b) => a + b, 0) - 1) < 0.01, `${w}`);
    // The lobe's own layer holds nearly all of it (the penalty holding the sum and the table's
    // cells leave a few percent to its neighbours).
    assert.ok(w[3] > 0.85, `${w}`);
});

test("the mixture's kernel is its weights' Phong kernels, and read through the bilinear texel", () => {
    const exponents = [1, 4, 16];
    const rows = 2;
    const out = new Float32Array(4 * rows * mixtureRows(exponents.length));
    // View 0: all on exponent 4; view 1: half on 1, half on 16.
    out[4 * rows + 0] = 1;
    out[4 * 1 + 3] = 0.5;
    out[4 * rows + 4 + 1] = 0.5;
    const kernels = mixtureKernels(out, rows, exponents);
    for (const j of [0, 5, 20, 40]) {
        const c = Math.cos(Math.PI * ((j + 0.5) / ANGLE_STEPS) ** 2);
        const phong = (n) => (c > 0 ? ((n + 1) / (2 * Math.PI)) * c ** n : 0);
        assert.ok(Math.abs(kernels[j] - phong(4)) < 1e-6, `view 0, texel ${j}`);
        assert.ok(Math.abs(kernels[ANGLE_STEPS + j] - (phong(1) + phong(16)) / 2) < 1e-6, `view 1, texel ${j}`);
    }
    // A tent one texel wide along each axis adds the spread (pi / H)^2 / 6; an exponent past any
    // texel's reach reads as the texel's own width.
    assert.ok(Math.abs(texelSpread(256) - (Math.PI / 256) ** 2 / 6) < 1e-15);
    const [sharp] = effectiveExponents([1e12], texelSpread(256));
    assert.ok(Math.abs(sharp - (6 * (256 / Math.PI) ** 2 - 2)) < 1e-3 * sharp, `${sharp}`);
    assert.ok(Math.abs(effectiveExponents([4], 0)[0] - 4) < 1e-5);
});

test("a peak light's correction is none where the mixture is the table, the layers' share below the horizon", () => {
    const [albedo, n] = [0.3, 4];
    const exponents = [1, 4, 16];
    const rows = 4;
    // The mixture of a broad Phong lobe: all on its own exponent (set by hand, the view's albedo).
    const out = new Float32Array(4 * rows * mixtureRows(exponents.length));
    for (let r = 0; r < rows; r++) {
        out.set([albedo, albedo, albedo], 4 * r);
        out[4 * rows + r * 4] = 1;
    }
    const kernels = mixtureKernels(out, rows, exponents);
    const corrections = lightCorrections(phongTable(albedo, n), SIZE, Math.PI, [0, 0, 0], rows, out, kernels);
    assert.equal(corrections.length, 4 * ANGLE_STEPS * AZIMUTH_STEPS * rows);
    const peak = (albedo * (n + 1)) / (2 * Math.PI);
    let [above, below, worst] = [0, 0, 0];
    for (let r = 0; r < rows; r++) {
        const cosO = 1 - (r + 0.5) / rows;
        const sinO = Math.sqrt(1 - cosO * cosO);
        for (let b = 0; b < AZIMUTH_STEPS; b++) {
            const cosB = (2 * (b + 0.5)) / AZIMUTH_STEPS - 1;
            for (let j = 0; j < ANGLE_STEPS; j++) {
                const alpha = Math.PI * ((j + 0.5) / ANGLE_STEPS) ** 2;
                // The light's height above the surface: its direction's z in the view's frame.
                const z = Math.cos(alpha) * cosO + Math.sin(alpha) * cosB * sinO;
                const v = corrections[4 * ((r * AZIMUTH_STEPS + b) * ANGLE_STEPS + j)];
                if (z > 0.2) {
                    worst = Math.max(worst, Math.abs(v) / peak);
                    above++;
                } else if (z < 0) {
                    assert.ok(Math.abs(v + albedo * kernels[r * ANGLE_STEPS + j]) < 1e-6, `view ${r}, azimuth ${b}, texel ${j}`);
                    below++;
                }
            }
        }
    }
    // The table's nearest cell lies up to half a cell from the direction, and f = A (n + 1)
    // cos^n alpha / (2 pi cos theta_i) changes fastest towards grazing: measured 4.4% of the
    // lobe's peak above 0.2 of the light's height (21% just above the horizon).
    assert.ok(worst < 0.05, `${worst} of the peak`);
    assert.ok(above > 1000 && below > 1000, `${above} above, ${below} below`);
});

// A peaks image of 64 x 32 texels (row 0 at the zenith) lit at `texels` ([x, y, radiance]).
function peaksImage(texels) {
    const data = new Float32Array(4 * 64 * 32);
    for (const [x, y, v] of texels) data.set([v, 2 * v, 3 * v, 1], 4 * (y * 64 + x));
    return data;
}
const solidAngle = (y) => ((2 * Math.PI) / 64) * (Math.PI / 32) * Math.sin((Math.PI * (y + 0.5)) / 32);
const direction = (u, v) => [Math.sin(Math.PI * v) * Math.cos(2 * Math.PI * u), Math.sin(Math.PI * v) * Math.sin(2 * Math.PI * u), Math.cos(Math.PI * v)];

test('one source is one light: its power the radiance times solid angle, its direction the middle, its near cone', () => {
    const image = peaksImage([[10, 8, 100], [11, 8, 100], [10, 9, 100], [11, 9, 100]]);
    const lights = peakLights(image, 64, 32);
    assert.equal(lights.count, 1);
    const block = 100 * (2 * solidAngle(8) + 2 * solidAngle(9));
    assert.ok(Math.abs(lights.powers[0] - block) < 1e-6 * block && Math.abs(lights.powers[2] - 3 * block) < 1e-5 * block);
    const cos = direction(11 / 64, 9 / 32).reduce((s, e, i) => s + e * lights.directions[i], 0);
    assert.ok(cos > 0.9995, `${cos}`);
    // Four texels about 0.1 radians apart: a radius of a few hundredths, under the near cone's
    // least width, so the cone is NEAR_MIN_DEGREES and twice it.
    const least = (NEAR_MIN_DEGREES * Math.PI) / 180;
    assert.ok(Math.abs(lights.near[0] - Math.cos(least)) < 1e-6 || lights.near[0] < Math.cos(least), `${lights.near[0]}`);
    assert.ok(lights.near[1] < lights.near[0], `${lights.near}`);
    assert.equal(lights.powers[3], 0);
});

test('a sun keeps its own light beside a larger dimmer source, and past the most lights no power is lost', () => {
    // A bright texel (the sun) and a dim 3 x 3 lamp half the sky away, then a third source.
    const lamp = [];
    for (let dx = 0; dx < 3; dx++) for (let dy = 0; dy < 3; dy++) lamp.push([40 + dx, 14 + dy, 5]);
    const two = peakLights(peaksImage([[8, 10, 1000], ...lamp]), 64, 32);
    assert.equal(MAX_PEAK_LIGHTS, 2);
    assert.equal(two.count, 2);
    const sun = 1000 * solidAngle(10);
    assert.ok(Math.abs(two.powers[0] - sun) < 1e-6 * sun, `${two.powers}`);
    const lampPower = lamp.reduce((s, [, y, v]) => s + v * solidAngle(y), 0);
    assert.ok(Math.abs(two.powers[3] - lampPower) < 1e-5 * lampPower, `${two.powers}`);
    const cos = direction(8.5 / 64, 10.5 / 32).reduce((s, e, i) => s + e * two.directions[i], 0);
    assert.ok(cos > 1 - 1e-9, `${cos}`);
    const three = peakLights(peaksImage([[8, 10, 1000], ...lamp, [60, 25, 20]]), 64, 32);
    assert.equal(three.count, MAX_PEAK_LIGHTS);
    const total = sun + lampPower + 20 * solidAngle(25);
    const kept = three.powers[0] + three.powers[3];
    assert.ok(Math.abs(kept - total) < 1e-5 * total, `${kept} of ${total}`);
});

test("the extra layer is level 0 averaged down to the layers' size", () => {
    const [w, h] = [4, 2];
    const layers = Float32Array.from({ length: 4 * w * h * 2 }, (_, i) => i);
    const env = new Float32Array(4 * 8 * 4 * 2);
    for (let i = 0; i < 8 * 4; i++) env.set([i, 1, 2, 1], 4 * i);
    // A peak at texel (1, 0): the whole environment's level 0 keeps it.
    env.set([5, 0, 0, 0], 4 * (8 * 4 + 1));
    const out = splitLayers(layers, w, h, 2, env, 8, 4);
    assert.deepEqual(Array.from(out.subarray(0, layers.length)), Array.from(layers));
    // Layer texel (0, 0) covers level-0 texels (0, 0), (1, 0), (0, 1), (1, 1): R 0, 1, 8, 9.
    const extra = out.subarray(layers.length);
    assert.deepEqual(Array.from(extra.subarray(0, 4)), [(0 + 1 + 8 + 9) / 4, 1, 2, 1]);
});
