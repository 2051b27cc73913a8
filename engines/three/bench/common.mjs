// What the three.js benchmarks share (bench/frontier.mjs, bench/gltf.mjs): their arguments, the
// bakes they draw (a shared real-derived table under a shared map, with brdf-fit's glTF material
// and the fit baked as a table of its own) and the test page each bake is drawn in.
import { execFileSync } from 'node:child_process';
import { existsSync, mkdirSync, realpathSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';

import { openPage, serve } from '../test/serve.mjs';

export const ROOT = resolve(fileURLToPath(new URL('.', import.meta.url)), '../../..');

export function fail(message) {
    console.error(`error: ${message}`);
    process.exit(2);
}

/** `--name value` pairs of the command line over `defaults`; numbers where the default is one. */
export function parseArgs(defaults) {
    const args = { ...defaults, chromium: process.env.CHROMIUM ?? '/usr/bin/chromium' };
    for (let i = 2; i < process.argv.length; i += 2) {
        const key = process.argv[i].replace(/^--/, '');
        if (!(key in args) || process.argv[i + 1] === undefined) fail(`unknown or incomplete argument ${process.argv[i]}`);
        args[key] = typeof defaults[key] === 'number' ? Number(process.argv[i + 1]) : process.argv[i + 1];
        if (Number.isNaN(args[key])) fail(`${process.argv[i]} takes a number, not ${process.argv[i + 1]}`);
    }
    return args;
}

// `brdf-bake TABLE --env ENV --out-dir DIR --engine-textures EXTRA`; exit 1 is a validation
// problem (the bake is written), anything else an error.
function runBake(table, env, dir, extra, what) {
    try {
        execFileSync(join(ROOT, 'target/release/brdf-bake'), [table, '--env', env, '--out-dir', dir, '--engine-textures', ...extra, '--quiet'], {
            stdio: ['ignore', 'ignore', 'inherit'],
        });
    } catch (e) {
        if (e.status !== 1) fail(`baking ${what}: exit ${e.status}`);
    }
}

/** Builds brdf-bake (release) and makes `out`. */
export function prepare(out) {
    mkdirSync(out, { recursive: true });
    console.error('building brdf-bake (release)');
    execFileSync('cargo', ['build', '--quiet', '--release', '-p', 'brdf-bake'], { cwd: ROOT, stdio: 'inherit' });
}

/**
 * `material` (target/merl/NAME.binary) baked under `map` (a shared map's name without .hdr)
 * with engine textures and brdf-fit's material into out/MATERIAL-MAP, and the fit's fit.binary
 * baked under the same map into out/MATERIAL-MAP-fit: the glTF BRDF drawn exactly.
 */
export function bakeWithFit(material, map, out) {
    const table = join(ROOT, 'target/merl', `${material}.binary`);
    if (!existsSync(table)) fail(`${table} does not exist: make test-data makes it`);
    const dir = join(out, `${material}-${map}`);
    console.error(`baking ${material} under ${map}`);
    const env = join(ROOT, '../shared/data/env', `${map}.hdr`);
    runBake(table, env, dir, ['--fit'], `${material} under ${map}`);
    const fitDir = `${dir}-fit`;
    runBake(join(dir, 'fit.binary'), env, fitDir, [], `the fit of ${material} under ${map}`);
    return { material, map: map.replace(/_1k$/, ''), dir: realpathSync(dir), fitDir: realpathSync(fitDir) };
}

/**
 * `bake` (bakeWithFit's) served at /bake/ and its fit at /fit-bake/, the test page opened in
 * `browser`, and `call(page, origin)`'s result; the page closed and the server stopped after.
 */
export async function onBakePage(browser, bake, call) {
    const server = await serve(bake.dir, [['/fit-bake/', bake.fitDir]]);
    const origin = `http://127.0.0.1:${server.address().port}`;
    try {
        const { page, errors } = await openPage(browser, `${origin}/engines/three/test/page.html`).catch((e) => fail(e.message));
        const result = await call(page, origin).catch((e) => fail(`${bake.material} under ${bake.map}: ${e.message}; ${errors.join('; ')}`));
        await page.close();
        return result;
    } finally {
        server.close();
    }
}

/** The WebGL renderer `page` draws with, as the browser names it. */
export function rendererName(page) {
    return page.evaluate(() => {
        const gl = document.createElement('canvas').getContext('webgl2');
        const debug = gl.getExtension('WEBGL_debug_renderer_info');
        return gl.getParameter(debug ? debug.UNMASKED_RENDERER_WEBGL : gl.RENDERER);
    });
}
