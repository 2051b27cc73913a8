// brdf-fit's glTF materials in a glTF viewer: for each of the 20 shared real-derived tables, the
// material.gltf brdf-fit writes (`brdf-bake --fit`) checked by the Khronos glTF validator, read
// by three.js's GLTFLoader in headless Chromium (WebGL 2 on SwiftShader) and drawn on a sphere
// in a y-up scene lit by the bake's map (scene.environment: three's PMREM), beside the same
// glTF BRDF drawn exactly (the fit's fit.binary baked with its own engine textures and drawn by
// the bake material's reference estimator, 64 samples per strategy x --truth-frames frames).
// The PSNR between the two is what three's image-based lighting costs, not the fit (the fit
// against the measured table is the fits benchmark's).
//
//   node bench/gltf.mjs [--size N] [--truth-frames N] [--only NAME] [--chromium PATH]
//
// About 100 s per material (two maps, two bakes each with the fit) on 2 cores. Prints the report
// as markdown and writes the sheet of every material's pictures to docs/three-gltf.png. Needs
// target/merl (make test-data), Chromium, and the packages of engines/three and
// tests/gltf-validator (make setup).
import { execFileSync } from 'node:child_process';
import { readFileSync, writeFileSync } from 'node:fs';
import { join } from 'node:path';

import { launch } from '../test/serve.mjs';
import { ROOT, bakeWithFit, fail, onBakePage, parseArgs, prepare, rendererName } from './common.mjs';

const MATERIALS = [
    'alum-bronze', 'black-obsidian', 'blue-acrylic', 'blue-rubber', 'brass', 'cherry-235', 'chrome',
    'color-changing-paint3', 'gold-paint', 'gray-plastic', 'green-metallic-paint', 'nickel', 'pink-fabric',
    'red-metallic-paint', 'silver-metallic-paint', 'steel', 'teflon', 'white-marble', 'white-paint', 'yellow-paint',
];
const MAPS = ['quarry_01_1k', 'studio_small_03_1k'];

const args = parseArgs({ size: 128, 'truth-frames': 16, only: '' });
const materials = args.only ? MATERIALS.filter((m) => m === args.only) : MATERIALS;
if (materials.length === 0) fail(`--only ${args.only} is not one of the 20 materials`);
const out = join(ROOT, 'target/bench-gltf');
prepare(out);

// The Khronos validator's report of each material.gltf (tests/gltf-validator/check.mjs).
function validate(files) {
    const checker = join(ROOT, 'tests/gltf-validator/check.mjs');
    let stdout;
    try {
        stdout = execFileSync('node', [checker, ...files], { encoding: 'utf8', stdio: ['ignore', 'pipe', 'inherit'] });
    } catch (e) {
        fail(`the glTF validator did not run (make setup installs it): exit ${e.status}`);
    }
    return new Map(stdout.trim().split('\n').map((line) => JSON.parse(line)).map((r) => [r.path, r]));
}

const browser = await launch(args.chromium).catch((e) => fail(e.message));
const rows = [];
let renderer = '';
let lastBake = null;
try {
    for (const material of materials) {
        const row = { material, maps: {} };
        for (const map of MAPS) {
            const bake = bakeWithFit(material, map, out);
            lastBake = bake;
            console.error(`drawing ${material}'s glTF under ${bake.map}`);
            row.maps[bake.map] = await onBakePage(browser, bake, async (page, origin) => {
                renderer ||= await rendererName(page);
                return page.evaluate((o) => window.gltfViewer(o), {
                    bake: `${origin}/bake/`,
                    fitBake: `${origin}/fit-bake/`,
                    size: args.size,
                    truthFrames: args['truth-frames'],
                });
            });
            row.maps[bake.map].gltf = join(bake.dir, 'material.gltf');
            row.maps[bake.map].fit = JSON.parse(readFileSync(join(bake.dir, 'fit.json'), 'utf8'));
        }
        rows.push(row);
    }

    const maps = MAPS.map((m) => m.replace(/_1k$/, ''));
    const reports = validate(rows.flatMap((r) => maps.map((m) => r.maps[m].gltf)));
    const f = (v, d = 1) => (Number.isFinite(v) ? v.toFixed(d) : 'identical');
    console.log(`### brdf-fit's glTF material in three.js (Chromium, ${renderer})\n`);
    console.log(
        `Each material's material.gltf (brdf-bake --fit) under each map: the Khronos glTF validator's errors / warnings / infos ` +
            `(${[...reports.values()][0].validatorVersion}); the material three's GLTFLoader made of it and the largest difference ` +
            `between the factors it read and fit.json's; the PSNR in dB between three's drawing (PMREM of the map) and the same glTF ` +
            `BRDF drawn exactly (the fit's table, the reference estimator at 64 samples per strategy x ${args['truth-frames']} frames), ` +
            `over the sphere's pixels at ${args.size} x ${args.size}, tone mapped as brdf-preview maps them. The two maps give the same fit: ` +
            `the glTF files are compared byte for byte.\n`,
    );
    console.log(`| material | three's material | factors read back | validator ${maps.join(' / ')} | same file under both maps | ${maps.map((m) => `${m} dB`).join(' | ')} |`);
    console.log(`|---|---|---:|---|---|${maps.map(() => '---:').join('|')}|`);
    let clean = 0;
    for (const { material, maps: m } of rows) {
        const checks = maps.map((map) => reports.get(m[map].gltf));
        if (checks.every((c) => c.errors === 0)) clean += 1;
        const same = readFileSync(m[maps[0]].gltf).equals(readFileSync(m[maps[1]].gltf));
        const readBack = Math.max(...maps.map((map) => m[map].readBack));
        console.log(
            `| ${material} | ${m[maps[0]].type} (${m[maps[0]].fit.variant}) | ${readBack === 0 ? 'exact' : readBack.toExponential(1)} ` +
                `| ${checks.map((c) => `${c.errors} / ${c.warnings} / ${c.infos}`).join(', ')} | ${same ? 'yes' : 'no'} ` +
                `| ${maps.map((map) => f(m[map].threeAgainstExact)).join(' | ')} |`,
        );
    }
    console.log(`\n${clean} of ${rows.length} materials' glTF files pass the validator with no error under both maps.`);
    for (const map of maps) {
        const v = rows.map((r) => r.maps[map].threeAgainstExact).sort((a, b) => a - b);
        console.log(`${map}: three against exact: min ${f(v[0])} dB, median ${f(v[Math.floor((v.length - 1) / 2)])} dB, max ${f(v[v.length - 1])} dB.`);
    }

    // The sheet: every material's two pictures under each map, drawn by the page's 2D canvas.
    const sheet = await onBakePage(browser, lastBake, (page) =>
        page.evaluate((o) => window.gltfSheet(o), {
            rows: rows.map(({ material, maps: m }) => ({
                label: material,
                cells: maps.flatMap((map) => [
                    { rgb: m[map].three, caption: `${f(m[map].threeAgainstExact)} dB` },
                    { rgb: m[map].exact, caption: '' },
                ]),
            })),
            headings: maps.flatMap((map) => [`${map}\nthree.js`, `${map}\nexact`]),
            size: args.size,
            title: "brdf-fit's glTF material: three.js (GLTFLoader, PMREM) beside the same BRDF drawn exactly",
            legend: 'three: MeshStandard/PhysicalMaterial from material.gltf; exact: fit.binary by the reference estimator; dB: three against exact',
        }),
    );
    const sheetPath = join(ROOT, 'docs/three-gltf.png');
    writeFileSync(sheetPath, Buffer.from(sheet.replace(/^data:image\/png;base64,/, ''), 'base64'));
    console.error(`wrote ${sheetPath}`);
    console.log(`\n![brdf-fit's glTF material in three.js beside the exact drawing](three-gltf.png)`);
} finally {
    await browser.close();
}
