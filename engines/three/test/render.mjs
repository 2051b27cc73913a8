// Renders a bake with the three.js material in headless Chromium (puppeteer-core driving the
// system's Chromium; no browser download) and writes the picture as an 8-bit RGB PNG: what
// `tests/three.rs` compares with brdf-preview's picture of the same bake and mode.
//
//   node test/render.mjs --bake DIR --mode reference|prefiltered --size WxH --out FILE.png
//        [--spp N] [--frames N] [--seed N] [--camera AZ,EL] [--coverage exact|forward] [--chromium PATH]
//   node test/render.mjs --bake DIR --mode reference|prefiltered --size WxH --timing N [--spp N]
//
// --coverage exact (the default) rasterizes the mesh at brdf-preview's sub-pixel precision
// (exactCoverage in src/index.js), forward draws it with the material as a scene does.
//
// Prints one JSON line: the renderer and the render's milliseconds; with --timing N (and no
// --out), the milliseconds per frame of N whole-image draws of one frame each to the canvas,
// after one untimed draw of a pixel (which compiles the shaders and uploads the textures). Chromium runs with WebGL 2 on
// SwiftShader (--use-angle=swiftshader --enable-unsafe-swiftshader): the same on every machine.
// Errors: one line `error: ...` on stderr, exit 2.
import { existsSync, realpathSync, writeFileSync } from 'node:fs';
import { resolve } from 'node:path';

import { launch, openPage, png, serve } from './serve.mjs';


function fail(message) {
    console.error(`error: ${message}`);
    process.exit(2);
}

function parseArgs(argv) {
    const args = { seed: 0, camera: '0,0', timing: 0, chromium: process.env.CHROMIUM ?? '/usr/bin/chromium' };
    for (let i = 0; i < argv.length; i += 2) {
        const key = argv[i]?.replace(/^--/, '');
        const value = argv[i + 1];
        if (!key || value === undefined) fail(`expected --option value pairs, found ${argv.slice(i).join(' ')}`);
        args[key] = value;
    }
    for (const required of ['bake', 'mode', 'size', ...(args.timing ? [] : ['out'])]) {
        if (args[required] === undefined) fail(`--${required} is required`);
    }
    const size = /^(\d+)x(\d+)$/.exec(args.size);
    if (!size) fail(`--size ${args.size}: expected WIDTHxHEIGHT`);
    args.width = Number(size[1]);
    args.height = Number(size[2]);
    const [azimuth, elevation] = args.camera.split(',').map(Number);
    if (!Number.isFinite(azimuth) || !Number.isFinite(elevation)) fail(`--camera ${args.camera}: expected AZ,EL`);
    Object.assign(args, { azimuth, elevation });
    for (const k of ['spp', 'frames', 'seed', 'timing']) {
        if (args[k] !== undefined) args[k] = Number(args[k]);
    }
    return args;
}

const args = parseArgs(process.argv.slice(2));
if (!existsSync(args.chromium)) {
    fail(`${args.chromium} does not exist: the three.js tests need Chromium (apt-get install chromium, or set CHROMIUM)`);
}
if (!existsSync(resolve(args.bake, 'manifest.json'))) fail(`${args.bake}: not a bake folder (it has no manifest.json)`);
const bakeDir = realpathSync(resolve(args.bake));
const server = await serve(bakeDir);
const origin = `http://127.0.0.1:${server.address().port}`;
const browser = await launch(args.chromium).catch((e) => fail(e.message));
try {
    const { page, errors } = await openPage(browser, `${origin}/engines/three/test/page.html`).catch((e) => fail(e.message));
    const result = await page.evaluate((options) => window.renderBake(options), {
        bake: `${origin}/bake/`,
        mode: args.mode,
        width: args.width,
        height: args.height,
        spp: args.spp,
        frames: args.frames,
        seed: args.seed,
        azimuth: args.azimuth,
        elevation: args.elevation,
        timing: args.timing,
        picture: args.out !== undefined,
        coverage: args.coverage ?? 'exact',
    }).catch((e) => fail(`rendering ${args.bake} (${args.mode}): ${e.message}; ${errors.join('; ')}`));
    if (errors.length > 0) fail(`the page reported errors: ${errors.join('; ')}`);
    if (args.out !== undefined) writeFileSync(args.out, png(result.rgb, args.width, args.height));
    console.log(JSON.stringify({
        out: args.out, mode: args.mode, width: args.width, height: args.height,
        renderer: result.renderer, render_ms: result.renderMs, ms_per_frame: result.msPerFrame ?? null,
    }));
} finally {
    await browser.close();
    server.close();
}
