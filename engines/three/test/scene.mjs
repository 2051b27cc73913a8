// The material in a y-up three.js scene, beside three's own drawings of it (test/scene-page.js), in
// headless Chromium: prints one JSON line of figures and writes, for a person to look at, one PNG
// per check in OUT (three.js's drawing on the left, the bake's on the right, tone mapped as
// brdf-preview tone maps).
//
//   node test/scene.mjs --bake DIR --out-dir OUT [--size WxH] [--chromium PATH]
//
// Figures:
// - background_psnr_db: three's scene.background from the bake's map against the bake's
//   createBackground, per scene rotation (none, then a turn about every axis): the orientation;
// - mirror_horizon_rows: where the reflected horizon crosses the centre column of a mirror ball
//   seen from 30 degrees above (the row of the steepest change of log luminance), three's
//   MeshStandardMaterial lit by scene.environment and the bake's material;
// - scale_psnr_db: a sphere squashed by its mesh's scale against the same shape made in its
//   geometry, both drawn by the bake's material: the normal matrix;
// - instances_psnr_db, skinning_psnr_db: an InstancedMesh of 100 against 100 meshes, a sphere
//   skinned to a bone against a mesh moved as the bone (three's chunks in the vertex shader);
// - batched_psnr_db, logarithmic_depth_psnr_db: a BatchedMesh of 9 against 9 meshes; the bake's
//   sphere cutting through one of three's drawn with a logarithmic depth buffer against without;
// - orthographic_psnr_db: the material seen by an orthographic camera against a perspective one
//   4000 units away (rays parallel within 3e-4 radians);
// - environment_rotation_psnr_db: the material under scene.environmentRotation (a turn about +y)
//   against the unturned scene seen by a camera turned back by as much;
// - morph_psnr_db: a sphere morphed into a squashed one against the squashed shape in its geometry;
// - clipping_psnr_db: a sphere under a clipping plane through its centre against its lower half
//   made in its geometry;
// (a PSNR of identical pictures is infinite: null in the JSON);
// - live_largest_relative_difference, live_frames, live_frames_after_moving: the live mode
//   (Accumulator): the mean of 8 calls against one draw of the same 8 frames (linear values), the
//   frames it holds, and after the camera moved; live_split_largest_relative_difference,
//   live_split_frames, live_split_weight: with the split first frame, 9 calls against the split
//   frame and the 8 frames weighted as the accumulator weighs them (4 and 1 each), its frames and
//   total weight;
// - tone_mapping_levels: the material drawn to the canvas under ACES filmic (exposure 1.7) and no
//   tone mapping, against three's formulas applied to its linear radiance read back as floats:
//   the largest difference in 8-bit levels and how many values differ by more than one.
// Errors: one line `error: ...` on stderr, exit 2.
import { existsSync, mkdirSync, realpathSync, writeFileSync } from 'node:fs';
import { join, resolve } from 'node:path';

import { launch, openPage, png, serve } from './serve.mjs';
import { previewLevel } from './tonemap.js';

function fail(message) {
    console.error(`error: ${message}`);
    process.exit(2);
}

const args = { size: '128x128', chromium: process.env.CHROMIUM ?? '/usr/bin/chromium' };
for (let i = 2; i < process.argv.length; i += 2) args[process.argv[i].replace(/^--/, '')] = process.argv[i + 1];
if (!args.bake || !args['out-dir']) fail('usage: node test/scene.mjs --bake DIR --out-dir OUT [--size WxH]');
const size = /^(\d+)x(\d+)$/.exec(args.size);
if (!size) fail(`--size ${args.size}: expected WIDTHxHEIGHT`);
const [width, height] = [Number(size[1]), Number(size[2])];
if (!existsSync(resolve(args.bake, 'manifest.json'))) fail(`${args.bake}: not a bake folder (it has no manifest.json)`);

// envmap::tonemap_rgb8: exposure, Reinhard per channel, sRGB, rounded to 8 bits.
function tonemap(rgb, exposure) {
    return Uint8Array.from(rgb, (v) => previewLevel(v, exposure));
}

function psnrDb(a, b) {
    let sum = 0;
    for (let i = 0; i < a.length; i++) sum += (a[i] - b[i]) ** 2;
    const mse = sum / a.length;
    return mse === 0 ? Infinity : 10 * Math.log10((255 * 255) / mse);
}

// The row where log luminance changes most steeply down the centre column, within the rows the
// ball covers in both pictures (a pixel of the ball is not black).
function horizonRow(rgb) {
    const x = Math.floor(width / 2);
    const luminance = (y) => {
        const i = 3 * (y * width + x);
        return 0.2126 * rgb[i] + 0.7152 * rgb[i + 1] + 0.0722 * rgb[i + 2];
    };
    let best = { row: -1, step: 0 };
    for (let y = 1; y < height; y++) {
        const [a, b] = [luminance(y - 1), luminance(y)];
        if (a <= 0 || b <= 0) continue;
        const step = Math.abs(Math.log(b) - Math.log(a));
        if (step > best.step) best = { row: y, step };
    }
    return best.row;
}

// three's pipeline on linear RGB (its ShaderChunk tonemapping_pars_fragment and
// colorspace_pars_fragment, r187): ACES filmic (Narkowicz's fit as three writes it) or none, then
// the sRGB transfer function, clamped and rounded to 8 bits as the canvas stores them.
function threePipeline(rgb, toneMapping, exposure) {
    const out = new Uint8Array(rgb.length);
    const input = [[0.59719, 0.35458, 0.04823], [0.076, 0.90834, 0.01566], [0.0284, 0.13383, 0.83777]];
    const output = [[1.60475, -0.53108, -0.07367], [-0.10208, 1.10813, -0.00605], [-0.00327, -0.07276, 1.07602]];
    const times = (m, v) => m.map((row) => row[0] * v[0] + row[1] * v[1] + row[2] * v[2]);
    const fit = (v) => (v * (v + 0.0245786) - 0.000090537) / (v * (0.983729 * v + 0.432951) + 0.238081);
    for (let i = 0; i < rgb.length; i += 3) {
        let c = [rgb[i], rgb[i + 1], rgb[i + 2]];
        if (toneMapping === 'aces') {
            c = times(output, times(input, c.map((v) => (v * exposure) / 0.6)).map(fit));
        }
        for (let k = 0; k < 3; k++) {
            const v = Math.min(Math.max(c[k], 0), 1);
            const s = v <= 0.0031308 ? v * 12.92 : 1.055 * v ** 0.41666 - 0.055;
            out[i + k] = Math.round(Math.min(Math.max(s, 0), 1) * 255);
        }
    }
    return out;
}

// The largest difference in 8-bit levels and how many values differ by more than one.
function levels(a, b) {
    let [max, beyondOne] = [0, 0];
    for (let i = 0; i < a.length; i++) {
        const d = Math.abs(a[i] - b[i]);
        max = Math.max(max, d);
        if (d > 1) beyondOne++;
    }
    return { max, beyond_one: beyondOne };
}

// The largest |a - b| / max(|b|, 1e-6) over the linear values of two pictures.
function largestRelativeDifference(a, b) {
    let largest = 0;
    for (let i = 0; i < a.length; i++) largest = Math.max(largest, Math.abs(a[i] - b[i]) / Math.max(Math.abs(b[i]), 1e-6));
    return largest;
}

// Two pictures side by side with a 4-pixel grey gap.
function sideBySide(a, b) {
    const gap = 4;
    const w = 2 * width + gap;
    const out = new Uint8Array(3 * w * height).fill(96);
    for (let y = 0; y < height; y++) {
        out.set(a.subarray(3 * width * y, 3 * width * (y + 1)), 3 * w * y);
        out.set(b.subarray(3 * width * y, 3 * width * (y + 1)), 3 * (w * y + width + gap));
    }
    return { rgb: out, width: w };
}

const server = await serve(realpathSync(resolve(args.bake)));
const origin = `http://127.0.0.1:${server.address().port}`;
const browser = await launch(args.chromium).catch((e) => fail(e.message));
try {
    const { page, errors } = await openPage(browser, `${origin}/engines/three/test/page.html`).catch((e) => fail(e.message));
    const result = await page
        .evaluate((options) => window.renderScenes(options), { bake: `${origin}/bake/`, width, height })
        .catch((e) => fail(`rendering the scenes of ${args.bake}: ${e.message}; ${errors.join('; ')}`));
    if (errors.length > 0) fail(`the page reported errors: ${errors.join('; ')}`);
    const exposure = 2 ** result.exposureEv;
    const pictures = Object.fromEntries(Object.entries(result.pictures).map(([k, v]) => [k, tonemap(v, exposure)]));
    const outDir = args['out-dir'];
    mkdirSync(outDir, { recursive: true });
    const pair = (name, left, right) => {
        const sheet = sideBySide(pictures[left], pictures[right]);
        const file = join(outDir, `${name}.png`);
        writeFileSync(file, png(sheet.rgb, sheet.width, height));
        return file;
    };
    const files = [];
    const backgroundPsnr = [0, 1].map((i) => {
        files.push(pair(`background-${i}`, `background-${i}-three`, `background-${i}-bake`));
        return psnrDb(pictures[`background-${i}-three`], pictures[`background-${i}-bake`]);
    });
    files.push(pair('mirror', 'mirror-three', 'mirror-bake'));
    files.push(pair('scale', 'scale-mesh', 'scale-geometry'));
    files.push(pair('instances', 'instances-instanced', 'instances-separate'));
    files.push(pair('skinning', 'skinning-skinned', 'skinning-moved'));
    files.push(pair('batched', 'batched-batched', 'batched-separate'));
    files.push(pair('logarithmic-depth', 'logarithmic-depth-logarithmic', 'logarithmic-depth-linear'));
    files.push(pair('orthographic', 'orthographic-orthographic', 'orthographic-distant'));
    files.push(pair('environment-turned', 'environment-turned-scene', 'environment-turned-camera'));
    files.push(pair('morph', 'morph-morphed', 'morph-geometry'));
    files.push(pair('clipping', 'clipping-plane', 'clipping-geometry'));
    files.push(pair('live', 'live-accumulated', 'live-drawn'));
    files.push(pair('live-split', 'live-split-accumulated', 'live-split-expected'));
    const linear = result.pictures['mirror-bake'];
    const canvases = Object.fromEntries(
        ['aces', 'none'].map((t) => {
            const expected = threePipeline(linear, t, result.toneMappingExposure);
            const canvas = Uint8Array.from(result.canvases[t]);
            const sheet = sideBySide(canvas, expected);
            const file = join(outDir, `tone-mapping-${t}.png`);
            writeFileSync(file, png(sheet.rgb, sheet.width, height));
            files.push(file);
            return [t, levels(canvas, expected)];
        }),
    );
    console.log(JSON.stringify({
        renderer: result.renderer,
        width,
        height,
        background_psnr_db: backgroundPsnr,
        mirror_horizon_rows: { three: horizonRow(result.pictures['mirror-three']), bake: horizonRow(result.pictures['mirror-bake']) },
        scale_psnr_db: psnrDb(pictures['scale-mesh'], pictures['scale-geometry']),
        instances_psnr_db: psnrDb(pictures['instances-instanced'], pictures['instances-separate']),
        skinning_psnr_db: psnrDb(pictures['skinning-skinned'], pictures['skinning-moved']),
        batched_psnr_db: psnrDb(pictures['batched-batched'], pictures['batched-separate']),
        logarithmic_depth_psnr_db: psnrDb(pictures['logarithmic-depth-logarithmic'], pictures['logarithmic-depth-linear']),
        orthographic_psnr_db: psnrDb(pictures['orthographic-orthographic'], pictures['orthographic-distant']),
        environment_rotation_psnr_db: psnrDb(pictures['environment-turned-scene'], pictures['environment-turned-camera']),
        morph_psnr_db: psnrDb(pictures['morph-morphed'], pictures['morph-geometry']),
        clipping_psnr_db: psnrDb(pictures['clipping-plane'], pictures['clipping-geometry']),
        live_largest_relative_difference: largestRelativeDifference(result.pictures['live-accumulated'], result.pictures['live-drawn']),
        live_frames: result.live.frames,
        live_frames_after_moving: result.live.framesAfterMoving,
        live_split_largest_relative_difference: largestRelativeDifference(result.pictures['live-split-accumulated'], result.pictures['live-split-expected']),
        live_split_frames: result.live.splitFrames,
        live_split_weight: result.live.splitWeight,
        tone_mapping_levels: canvases,
        files,
    }));
} finally {
    await browser.close();
    server.close();
}
