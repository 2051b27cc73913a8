// The split estimator's inputs derived at load time (split.js; node --test), against analytic
// answers: the lobe table's albedo of a Lambertian table (its albedo exactly) and of a Phong lobe
// table (its albedo, its exponent), the layer coordinate of an exponent, the peak lights of a
// peaks image (their power as the sum of radiance times solid angle), and the smooth part's
// level 0 averaged down to the layers' size.
import assert from 'node:assert/strict';
import { test } from 'node:test';

import { MAX_PEAK_LIGHTS, layerCoordinate, lobeTable, merlBrdf, peakLights, splitLayers } from '../src/split.js';

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
    const all = lobeTable(data, SIZE, Math.PI, [0, 0, 0], rows, exponents);
    const rest = lobeTable(data, SIZE, Math.PI, [rho / Math.PI, rho / Math.PI, rho / Math.PI], rows, exponents);
    for (let r = 0; r < rows; r++) {
        // The two lobes share the albedo (the broader's is the sharper's times row 1's first
        // value); the quadrature over half vectors is within 1% of the hemisphere's integral of
        // cos (pi) except at the most grazing views (2%).
        const albedo = all[4 * r] * (1 + all[4 * (rows + r)]);
        assert.ok(Math.abs(albedo - rho) < (r < rows - 2 ? 0.01 : 0.02) * rho, `row ${r}: ${albedo}`);
        assert.ok(Math.abs(rest[4 * r] * (1 + rest[4 * (rows + r)])) < 1e-6, `row ${r}`);
    }
});

test("a Phong lobe's albedo and exponent come back at a view where it lies above the horizon", () => {
    // f cos theta_i = A (n + 1) / (2 pi) cos^n alpha around the mirror direction.
    const [albedo, n] = [0.3, 50];
    const data = table((wi, wo) => {
        const cosAlpha = wi[0] * -wo[0] + wi[1] * -wo[1] + wi[2] * wo[2];
        return cosAlpha > 0 ? (albedo * (n + 1) * cosAlpha ** n) / (2 * Math.PI * wi[2]) : 0;
    });
    const rows = 8;
    const out = lobeTable(data, SIZE, Math.PI, [0, 0, 0], rows, [1, 4, 16, 64, 256, 1024]);
    // Row 1: 1 - cos theta_o = 3/16, theta_o 36 degrees; the lobe (half width 14 degrees at
    // half its height) lies above the horizon. The nearest-cell table misses a little of the peak.
    const [w1, w2] = [out[4 * 1], out[4 * 1] * out[4 * (rows + 1)]];
    assert.ok(Math.abs(w1 + w2 - albedo) < 0.03 * albedo, `${w1 + w2}`);
    // Each lobe holding a tenth of the albedo or more has the exponent within 15%.
    for (const [w, exponent] of [[w1, out[4 * 1 + 3]], [w2, out[4 * (rows + 1) + 1]]]) {
        if (w > 0.1 * albedo) assert.ok(Math.abs(exponent - n) < 0.15 * n, `${exponent} holding ${w}`);
    }
    // The layer coordinates of the two lobes are their exponents' (row 1's last two values).
    const exponents = [1, 4, 16, 64, 256, 1024];
    assert.ok(Math.abs(out[4 * (rows + 1) + 2] - layerCoordinate(out[4 * 1 + 3], exponents)) < 1e-6);
    assert.ok(Math.abs(out[4 * (rows + 1) + 3] - layerCoordinate(out[4 * (rows + 1) + 1], exponents)) < 1e-6);
});

test('the layer coordinate of an exponent interpolates the layers logarithmically', () => {
    const exponents = [1, 4, 16, 64, 256];
    assert.equal(layerCoordinate(0.5, exponents), 0);
    assert.equal(layerCoordinate(1, exponents), 0);
    assert.equal(layerCoordinate(4, exponents), 1);
    assert.ok(Math.abs(layerCoordinate(8, exponents) - 1.5) < 1e-12);
    assert.equal(layerCoordinate(256, exponents), 4);
    assert.equal(layerCoordinate(1e6, exponents), 4);
});

// A peaks image of 64 x 32 texels (row 0 at the zenith) lit at `texels` ([x, y, radiance]).
function peaksImage(texels) {
    const data = new Float32Array(4 * 64 * 32);
    for (const [x, y, v] of texels) data.set([v, 2 * v, 3 * v, 1], 4 * (y * 64 + x));
    return data;
}
const solidAngle = (y) => ((2 * Math.PI) / 64) * (Math.PI / 32) * Math.sin((Math.PI * (y + 0.5)) / 32);

test('touching peak texels within a cell make one light, its power their radiance times solid angle', () => {
    // A 2 x 2 block at rows 8-9 (one cell of 4 x 4 texels: 64 / 16 by 32 / 8), two touching texels
    // in one cell at row 20, and two touching texels in two cells (x 7 and 8) at row 26.
    const image = peaksImage([[10, 8, 100], [11, 8, 100], [10, 9, 100], [11, 9, 100], [5, 20, 50], [6, 20, 50], [7, 26, 30], [8, 26, 30]]);
    const lights = peakLights(image, 64, 32);
    assert.equal(lights.count, 4);
    const block = 100 * (2 * solidAngle(8) + 2 * solidAngle(9));
    const pair = 50 * 2 * solidAngle(20);
    assert.ok(Math.abs(lights.powers[0] - block) < 1e-6 * block && Math.abs(lights.powers[1] - 2 * block) < 1e-5 * block);
    assert.ok(Math.abs(lights.powers[3] - pair) < 1e-6 * pair);
    for (const i of [2, 3]) assert.ok(Math.abs(lights.powers[3 * i] - 30 * solidAngle(26)) < 1e-6, `light ${i}`);
    // The block's direction: between its texels' centres, at u = 11/64, v = 9/32.
    const [u, v] = [11 / 64, 9 / 32];
    const expected = [Math.sin(Math.PI * v) * Math.cos(2 * Math.PI * u), Math.sin(Math.PI * v) * Math.sin(2 * Math.PI * u), Math.cos(Math.PI * v)];
    const cos = expected.reduce((s, e, i) => s + e * lights.directions[i], 0);
    assert.ok(cos > 0.9995, `${cos}`);
    // The pair's light lies between its texels, at u = 6/64, theta that of row 20 (within 1e-3:
    // the mean of two directions half a texel either side leans towards the pole); its spread is
    // that of two texels 1/64 turn apart.
    const [phi, theta] = [(2 * Math.PI * 6) / 64, (Math.PI * 20.5) / 32];
    const toward = [Math.sin(theta) * Math.cos(phi), Math.sin(theta) * Math.sin(phi), Math.cos(theta)];
    for (let c = 0; c < 3; c++) assert.ok(Math.abs(lights.directions[3 + c] - toward[c]) < 1e-3, `${lights.directions.slice(3, 6)}`);
    assert.ok(lights.spreads[1] > 0 && lights.spreads[1] < 1 - Math.cos(Math.PI / 64), `${lights.spreads[1]}`);
});

test('past the most lights, each group joins the nearest kept one and no power is lost', () => {
    // One texel in each of MAX + 3 cells (columns 4 texels wide; rows 16 and 28 in two rows of cells).
    const texels = Array.from({ length: MAX_PEAK_LIGHTS + 3 }, (_, i) => [4 * (i % 16), i < 16 ? 16 : 28, 10 + i]);
    const lights = peakLights(peaksImage(texels), 64, 32);
    assert.equal(lights.count, MAX_PEAK_LIGHTS);
    const total = texels.reduce((s, [, y, v]) => s + v * solidAngle(y), 0);
    let kept = 0;
    for (let i = 0; i < MAX_PEAK_LIGHTS; i++) kept += lights.powers[3 * i];
    assert.ok(Math.abs(kept - total) < 1e-5 * total, `${kept} of ${total}`);
});

test("the extra layer is the smooth part's level 0 averaged down to the layers' size", () => {
    const [w, h] = [4, 2];
    const layers = Float32Array.from({ length: 4 * w * h * 2 }, (_, i) => i);
    const env = new Float32Array(4 * 8 * 4 * 2);
    for (let i = 0; i < 8 * 4; i++) env.set([i, 1, 2, 1], 4 * i);
    // A peak at texel (1, 0): level 0 less it is 0 there.
    env.set([5, 0, 0, 0], 4 * (8 * 4 + 1));
    const out = splitLayers(layers, w, h, 2, env, 8, 4);
    assert.deepEqual(Array.from(out.subarray(0, layers.length)), Array.from(layers));
    // Layer texel (0, 0) covers level-0 texels (0, 0), (1, 0), (0, 1), (1, 1): R 0, max(1 - 5, 0), 8, 9.
    const extra = out.subarray(layers.length);
    assert.deepEqual(Array.from(extra.subarray(0, 4)), [(0 + 0 + 8 + 9) / 4, 1, 2, 1]);
});
