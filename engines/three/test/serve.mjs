// What the browser tests share: a static server for a bake folder and this package, and the
// headless Chromium they render in.
import { createServer } from 'node:http';
import { existsSync, readFileSync, statSync } from 'node:fs';
import { extname, resolve, sep } from 'node:path';
import { fileURLToPath } from 'node:url';

const packageRoot = resolve(fileURLToPath(new URL('.', import.meta.url)), '..');

/** Serves /bake/ from `bakeDir` and /engines/three/ from this package, nothing else, on a free port of 127.0.0.1. */
export function serve(bakeDir) {
    const types = { '.html': 'text/html', '.js': 'text/javascript', '.mjs': 'text/javascript', '.json': 'application/json' };
    const roots = [['/bake/', bakeDir], ['/engines/three/', packageRoot]];
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
