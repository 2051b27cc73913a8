// What the browser tests share: a static server for a bake folder and this package, and the
// headless Chromium they render in.
import { createServer } from 'node:http';
import { existsSync, readFileSync, statSync } from 'node:fs';
import { extname, resolve, sep } from 'node:path';
import { fileURLToPath } from 'node:url';
import { deflateSync } from 'node:zlib';

const packageRoot = resolve(fileURLToPath(new URL('.', import.meta.url)), '..');

/**
 * Serves /bake/ from `bakeDir`, /engines/three/ from this package and each `[prefix, folder]` of
 * `more`, nothing else, on a free port of 127.0.0.1.
 */
export function serve(bakeDir, more = []) {
    const types = { '.html': 'text/html', '.js': 'text/javascript', '.mjs': 'text/javascript', '.json': 'application/json' };
    const roots = [['/bake/', bakeDir], ['/engines/three/', packageRoot], ...more];
    const server = createServer((request, response) => {
        const path = decodeURIComponent(new URL(request.url, 'http://localhost').pathname);
        for (const [prefix, dir] of roots) {
            if (!path.startsWith(prefix)) continue;
            const file = resolve(dir, '.' + sep + path.slice(prefix.length));
            if ((file === dir || file.startsWith(dir + sep)) && existsSync(file) && statSync(file).isFile()) {
                response.writeHead(200, { 'content-type': types[extname(file)] ?? 'application/octet-stream' });
                response.end(readFileSync(file));
                return;
            }
        }
        response.writeHead(404);
        response.end();
    });
    return new Promise((ok) => server.listen(0, '127.0.0.1', () => ok(server)));
}

/**
 * Headless Chromium at `executable` with WebGL 2 on SwiftShader (the same software GPU on every
 * machine), no GPU watchdog (a SwiftShader draw of many samples runs for seconds). Rejects with
 * what to do when Chromium or puppeteer-core is missing.
 */
export async function launch(executable) {
    if (!existsSync(executable)) {
        throw new Error(`${executable} does not exist: the three.js tests need Chromium (apt-get install chromium, or set CHROMIUM)`);
    }
    let puppeteer;
    try {
        puppeteer = (await import('puppeteer-core')).default;
    } catch {
        throw new Error(`puppeteer-core is not installed in ${packageRoot}: run make setup (npm ci in engines/three)`);
    }
    return puppeteer.launch({
        executablePath: executable,
        headless: true,
        args: [
            '--no-sandbox',
            '--use-angle=swiftshader',
            '--enable-unsafe-swiftshader',
            '--ignore-gpu-blocklist',
            '--disable-gpu-watchdog',
            '--disable-background-timer-throttling',
        ],
        protocolTimeout: 0,
    });
}

/**
 * A new page of `browser` at `url` (one of this package's test pages), once it has set
 * `window.ready`; the errors it reports (console errors and uncaught exceptions) collect in
 * `errors`. Rejects with them if it does not get ready within a minute.
 */
export async function openPage(browser, url) {
    const page = await browser.newPage();
    const errors = [];
    page.on('console', (m) => m.type() === 'error' && errors.push(m.text()));
    page.on('pageerror', (e) => errors.push(e.message));
    await page.goto(url);
    await page.waitForFunction('window.ready === true', { timeout: 60000 }).catch(() => {
        throw new Error(`the test page did not load: ${errors.join('; ')}`);
    });
    return { page, errors };
}

const CRC_TABLE = Array.from({ length: 256 }, (_, n) => {
    let c = n;
    for (let k = 0; k < 8; k++) c = c & 1 ? 0xedb88320 ^ (c >>> 1) : c >>> 1;
    return c >>> 0;
});

function crc32(bytes) {
    let c = 0xffffffff;
    for (const b of bytes) c = CRC_TABLE[(c ^ b) & 0xff] ^ (c >>> 8);
    return (c ^ 0xffffffff) >>> 0;
}

// An 8-bit RGB PNG, no interlace, filter 0 on every row.
export function png(rgb, width, height) {
    const chunk = (type, data) => {
        const body = Buffer.concat([Buffer.from(type, 'latin1'), data]);
        const out = Buffer.alloc(12 + data.length);
        out.writeUInt32BE(data.length, 0);
        body.copy(out, 4);
        out.writeUInt32BE(crc32(body), 8 + data.length);
        return out;
    };
    const header = Buffer.alloc(13);
    header.writeUInt32BE(width, 0);
    header.writeUInt32BE(height, 4);
    header.set([8, 2, 0, 0, 0], 8);
    const raw = Buffer.alloc((3 * width + 1) * height);
    for (let y = 0; y < height; y++) {
        Buffer.from(rgb.slice(3 * width * y, 3 * width * (y + 1))).copy(raw, y * (3 * width + 1) + 1);
    }
    return Buffer.concat([
        Buffer.from([0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a]),
        chunk('IHDR', header),
        chunk('IDAT', deflateSync(raw)),
        chunk('IEND', Buffer.alloc(0)),
    ]);
}
