// The frontier benchmark: what the bake's three.js material costs and gains against three.js's
// own materials, in headless Chromium (WebGL 2 on SwiftShader, the same software GPU on every
// machine: costs are ratios to MeshStandardMaterial's frame in the same run).
//
//   node bench/frontier.mjs [--size N] [--timing-size N] [--truth-frames N] [--chromium PATH]
//
// About a minute and a half per case on 2 cores.
//
// Cases: a plastic (gray-plastic), a metal (steel) and a felt-like diffuse (pink-fabric) of the
// shared real-derived tables, under quarry_01 (a sun) and studio_small_03 (indoor); each baked
// with `brdf-bake --engine-textures` (release build, into target/bench-frontier/) and drawn on a
// sphere in a y-up three.js scene lit by the bake's map (engines/three/bench/frontier-page.js):
// - the truth: the bake's reference estimator, 64 samples per strategy x --truth-frames frames;
// - MeshStandardMaterial and MeshPhysicalMaterial (scene.environment: three's PMREM of the same
//   map) at parameters fitted to the truth's picture (the page says how);
// - the glTF material brdf-fit fitted to the table (`brdf-bake --fit`: material.gltf), read by
//   three's GLTFLoader: what a glTF viewer shows of the fit, fitted to the BRDF, not the picture;
//   beside it the same glTF BRDF drawn exactly (the fit's fit.binary baked with its own engine
//   textures, drawn by the reference estimator as the truth is): the fit's own cost, and what
//   three's image-based lighting adds to it; and the factors three read against fit.json's;
// - the live mode's first frame, the split estimator (no samples; src/split.js);
// - the bake's prefiltered estimator, one frame of 1, 4 and 16 samples, and the live mode after
//   the time of 8 standard frames (the split frame, then 1-sample frames).
// PSNR over the sphere's pixels at --size (128), tone mapped as brdf-preview maps them (Reinhard
// at the bake's automatic exposure, sRGB); milliseconds per frame at --timing-size (512).
// Prints the report as markdown, with the goal the material is held to and which cases meet it.
// Needs target/merl (make test-data), Chromium and engines/three's packages (make setup).
import { join } from 'node:path';

import { launch } from '../test/serve.mjs';
import { SPLIT_WEIGHT } from '../src/live.js';
import { ROOT, bakeWithFit, fail, onBakePage, parseArgs, prepare, rendererName } from './common.mjs';

const MATERIALS = [['gray-plastic', 'a plastic'], ['steel', 'a metal'], ['pink-fabric', 'a felt-like diffuse']];
const MAPS = ['quarry_01_1k', 'studio_small_03_1k'];

const args = parseArgs({ size: 128, 'timing-size': 512, 'truth-frames': 16 });
const out = join(ROOT, 'target/bench-frontier');
prepare(out);
const bakes = MATERIALS.flatMap(([material, what]) => MAPS.map((map) => ({ ...bakeWithFit(material, map, out), what })));

const browser = await launch(args.chromium).catch((e) => fail(e.message));
const rows = [];
let renderer = '';
try {
    for (const bake of bakes) {
        console.error(`drawing ${bake.material} under ${bake.map}`);
        const r = await onBakePage(browser, bake, async (page, origin) => {
            renderer ||= await rendererName(page);
            return page.evaluate((o) => window.frontier(o), {
                bake: `${origin}/bake/`,
                fitBake: `${origin}/fit-bake/`,
                size: args.size,
                timingSize: args['timing-size'],
                truthFrames: args['truth-frames'],
                timingDraws: 3,
            });
        });
        rows.push({ ...bake, r });
    }
} finally {
    await browser.close();
}

const f = (v, d = 1) => v.toFixed(d);
console.log(`### The three.js material against three's own (Chromium, ${renderer})\n`);
console.log(
    `PSNR in dB over the sphere's pixels at ${args.size} x ${args.size} against the bake's reference estimator at 64 samples per ` +
        `strategy x ${args['truth-frames']} frames, tone mapped as brdf-preview maps them; cost: milliseconds per frame at ` +
        `${args['timing-size']} x ${args['timing-size']} over MeshStandardMaterial's (its ms in brackets). Three's materials are ` +
        `fitted to the truth's picture (engines/three/bench/frontier-page.js: metalness, roughness and for MeshPhysicalMaterial ` +
        `clearcoat on a grid, each channel's colour by a search on the tone-mapped error); glTF: brdf-fit's material (fitted to the table, not to this picture) as three's GLTFLoader reads the bake's material.gltf; split: the split estimator, the live mode's first frame; live: the split frame and the 1-sample frames drawn after it in the time of 8 standard frames, averaged as the live mode averages them (the split counted ${SPLIT_WEIGHT} times).\n`,
);
console.log('| material | map | standard dB (metalness, roughness) | physical dB (clearcoat, its roughness) | glTF dB (material type) | split dB | measured 1 / 4 / 16 spp dB | split cost | cost 1 / 4 / 16 spp | physical cost | glTF cost | live: sampled frames, dB |');
console.log('|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|');
for (const { material, what, map, r } of rows) {
    const s = r.ms.standard;
    console.log(
        `| ${material} (${what}) | ${map} | ${f(r.standard.psnr)} (${r.standard.params.metalness}, ${f(r.standard.params.roughness, 2)}) ` +
            `| ${f(r.physical.psnr)} (${r.physical.params.clearcoat}, ${r.physical.params.clearcoatRoughness}) ` +
            `| ${f(r.gltf.psnr)} (${r.gltf.type}) | ${f(r.split)} ` +
            `| ${f(r.measured[1])} / ${f(r.measured[4])} / ${f(r.measured[16])} | ${f(r.ms.split / s, 2)} ` +
            `| ${f(r.ms.measured[1] / s)} / ${f(r.ms.measured[4] / s)} / ${f(r.ms.measured[16] / s)} (${f(s)} ms) ` +
            `| ${f(r.ms.physical / s, 2)} | ${f(r.ms.gltf / s, 2)} | ${r.live.frames}, ${f(r.live.psnr)} |`,
    );
}

console.log(
    `\nThe glTF fit apart from three: brdf-fit's material drawn by three (GLTFLoader, PMREM) and the same glTF BRDF drawn ` +
        `exactly (the fit's fit.binary baked with its own engine textures, drawn by the reference estimator as the truth is), ` +
        `both against the truth; three's drawing against the exact one (what three's image-based lighting costs, not the fit); ` +
        `the largest difference between the factors three read and fit.json's.\n`,
);
console.log("| material | map | glTF by three dB | glTF exact dB | three against exact dB | factors read back |");
console.log('|---|---|---:|---:|---:|---:|');
for (const { material, map, r } of rows) {
    const g = r.gltf;
    console.log(`| ${material} | ${map} | ${f(g.psnr)} | ${f(g.exactPsnr)} | ${f(g.threeAgainstExact)} | ${g.readBack === 0 ? 'exact' : g.readBack.toExponential(1)} |`);
}

// The goal the measured material is held to: worth its cost beside three's own material.
const GOAL = { firstCost: 3, liveGainDb: 10, liveDb: 50 };
console.log(
    `\nThe goal: the live mode's first frame (the split estimator) at most ${GOAL.firstCost}x a standard frame and at least as close to the ` +
        `truth as the fitted standard material; after the time of 8 standard frames, the live mode at least ${GOAL.liveGainDb} dB ` +
        `closer than the standard material or above ${GOAL.liveDb} dB.\n`,
);
console.log('| material | map | first frame cost | first frame dB - standard dB | live dB - standard dB | met |');
console.log('|---|---|---:|---:|---:|---|');
let met = 0;
for (const { material, map, r } of rows) {
    const cost = r.ms.split / r.ms.standard;
    const first = r.split - r.standard.psnr;
    const live = r.live.psnr - r.standard.psnr;
    const checks = [
        [cost <= GOAL.firstCost, 'cost'],
        [first >= 0, 'first frame'],
        [live >= GOAL.liveGainDb || r.live.psnr > GOAL.liveDb, 'live'],
    ];
    const missed = checks.filter(([ok]) => !ok).map(([, what]) => what);
    if (missed.length === 0) met += 1;
    console.log(
        `| ${material} | ${map} | ${f(cost)}x | ${f(first)} | ${f(live)} | ${missed.length === 0 ? 'yes' : `no (${missed.join(', ')})`} |`,
    );
}
console.log(`\n${met} of ${rows.length} cases meet the goal.`);
