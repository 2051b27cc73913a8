// A screenshot of the example page (index.html) on a bake, for a person to check: the sphere,
// the environment behind it, the mode switch and the milliseconds per frame.
//
//   node test/screenshot.mjs --bake DIR --out FILE.png [--mode reference|prefiltered]
//        [--camera AZ,EL] [--frames N] [--chromium PATH]
import { existsSync, realpathSync } from 'node:fs';
import { resolve } from 'node:path';

import { launch, serve } from './serve.mjs';

const args = { mode: 'prefiltered', camera: '30,15', chromium: process.env.CHROMIUM ?? '/usr/bin/chromium' };
for (let i = 2; i < process.argv.length; i += 2) args[process.argv[i].replace(/^--/, '')] = process.argv[i + 1];
if (!args.bake || !args.out) {
    console.error('error: usage: node test/screenshot.mjs --bake DIR --out FILE.png');
    process.exit(2);
}
if (!existsSync(resolve(args.bake, 'manifest.json'))) {
    console.error(`error: ${args.bake}: not a bake folder (it has no manifest.json)`);
    process.exit(2);
}
const server = await serve(realpathSync(resolve(args.bake)));
const origin = `http://127.0.0.1:${server.address().port}`;
let browser;
try {
    browser = await launch(args.chromium);
    const page = await browser.newPage();
    await page.setViewport({ width: 760, height: 640 });
    const errors = [];
    page.on('pageerror', (e) => errors.push(e.message));
    // The live average stopped after --frames frames (default 2), at the camera asked for.
    const frames = Number(args.frames ?? 2);
    await page.goto(`${origin}/engines/three/index.html?bake=/bake/&mode=${args.mode}&frames=${frames}`);
    await page.waitForFunction(() => window.brdfExample !== undefined, { timeout: 0 });
    const [azimuth, elevation] = args.camera.split(',').map(Number);
    await page.evaluate((az, el) => {
        window.brdfExample.view.azimuth = az;
        window.brdfExample.view.elevation = el;
    }, azimuth, elevation);
    await page.waitForFunction(
        (az, n) => window.brdfExample.live.frames >= n && document.getElementById('status').textContent.includes(`camera ${az},`),
        { timeout: 0 },
        azimuth.toFixed(0),
        frames,
    );
    await page.screenshot({ path: args.out });
    console.log(await page.evaluate(() => document.getElementById('status').textContent));
    if (errors.length > 0) throw new Error(errors.join('; '));
} catch (e) {
    console.error(`error: ${e.message}`);
    process.exitCode = 2;
} finally {
    await browser?.close();
    server.close();
}
