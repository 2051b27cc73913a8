// Reading a bake's engine textures over HTTP (data-schema/engine-textures.md). A manifest and its
// files are untrusted: every path resolves inside the bake folder, every response is read as a
// stream up to the size the manifest gives (the manifest itself up to 16 MiB), every file's
// SHA-256 is checked (WebCrypto, or @noble/hashes where a page has none: an http page off
// localhost), the figures are typed and bounded, each texture's format and shape are its role's
// and its values are finite and in their role's range. Every failure is a BakeError whose message
// names the file.

import { read as readKtx2 } from 'ktx-parse';
import { sha256 as nobleSha256 } from '@noble/hashes/sha2.js';
import * as THREE from 'three';

/** An error in a bake's files, naming the file. */
export class BakeError extends Error {}

/** The stage of the manifest that lists the engine textures. */
export const STAGE = 'engine-textures';

/** The largest manifest read, in bytes (asset::MANIFEST_LIMIT). */
export const MANIFEST_LIMIT = 16 * 1024 * 1024;

/** The largest file a manifest may list, in bytes (asset::OUTPUT_LIMIT). */
export const OUTPUT_LIMIT = 4296015936;

/** The largest count a figure may give (rows, sectors, slices, samples, texture sides). */
const COUNT_LIMIT = 1 << 20;

/**
 * The largest finite single float (FLT_MAX, Rust's `f32::MAX`): the bound of the roles whose
 * values are radiance or a BRDF, which our Rust side bounds only by being finite f32 (see `roles`).
 * In a Float32Array every value up to it is finite, so the bound is the finiteness check itself.
 */
export const FLOAT32_MAX = 3.4028234663852886e38;

// KTX2 vkFormat codes of the data textures.
const VK_FORMAT_R32_SFLOAT = 100;
const VK_FORMAT_R32G32B32A32_SFLOAT = 109;

/**
 * Resolves a path a manifest names inside the bake folder `base` (a URL ending in `/`): a
 * relative path of `/`-separated components, none empty, `.` or `..`, without `\`, `:`, `?` or
 * `#` (the manifest's own rule, data-schema/README.md "Paths", and no scheme or query that
 * would take a fetch elsewhere). Anything else is refused.
 */
export function resolveInside(base, path) {
    const components = typeof path === 'string' ? path.split('/') : [''];
    const bad = components.some((c) => c === '' || c === '.' || c === '..' || /[\\:?#\0%]/.test(c));
    if (bad) {
        throw new BakeError(`error: manifest.json: the output path ${JSON.stringify(path)} leaves the bake folder`);
    }
    const url = new URL(components.map(encodeURIComponent).join('/'), base);
    if (url.origin !== base.origin || !url.pathname.startsWith(base.pathname)) {
        throw new BakeError(`error: manifest.json: the output path ${JSON.stringify(path)} leaves the bake folder`);
    }
    return url;
}

/**
 * The body of `url` read as a stream: at most `limit` bytes (a longer body is refused as soon as
 * it passes the limit, or from its Content-Length before anything is read), exactly `exact`
 * where given. `what` names the file in errors.
 */
async function fetchCapped(fetch, url, what, limit, exact) {
    let response;
    try {
        response = await fetch(url);
    } catch (e) {
        throw new BakeError(`error: ${what}: fetching ${url}: ${e.message}`);
    }
    if (!response.ok) {
        throw new BakeError(`error: ${what}: HTTP ${response.status} fetching ${url}`);
    }
    const tooLong = (n) => new BakeError(`error: ${what}: more than ${limit} bytes${exact === undefined ? '' : ', the size the manifest gives'}${n ? ` (${n} declared)` : ''}`);
    const declared = Number(response.headers.get('content-length') ?? NaN);
    if (declared > limit) {
        await response.body?.cancel();
        throw tooLong(declared);
    }
    const chunks = [];
    let total = 0;
    // A response without a body (an empty file, as some servers send it) reads as no bytes.
    const reader = response.body?.getReader();
    while (reader) {
        const { done, value } = await reader.read();
        if (done) break;
        total += value.byteLength;
        if (total > limit) {
            await reader.cancel();
            throw tooLong();
        }
        chunks.push(value);
    }
    if (exact !== undefined && total !== exact) {
        throw new BakeError(`error: ${what}: ${total} bytes, the manifest says ${exact}`);
    }
    const bytes = new Uint8Array(total);
    let at = 0;
    for (const chunk of chunks) {
        bytes.set(chunk, at);
        at += chunk.byteLength;
    }
    return bytes;
}

/** SHA-256 of `bytes` as lower-case hex: WebCrypto where the page has it, else @noble/hashes. */
export async function sha256Hex(bytes) {
    const digest = globalThis.crypto?.subtle
        ? new Uint8Array(await globalThis.crypto.subtle.digest('SHA-256', bytes))
        : nobleSha256(bytes);
    return Array.from(digest, (b) => b.toString(16).padStart(2, '0')).join('');
}

// Figure checks: each returns the value or throws naming the figure.
function figureError(name, value, expected) {
    return new BakeError(`error: manifest.json: the engine textures' ${name} is ${JSON.stringify(value)}, expected ${expected}`);
}

function count(figures, name, { min = 1, max = COUNT_LIMIT } = {}) {
    const v = figures[name];
    if (!(Number.isInteger(v) && v >= min && v <= max)) throw figureError(name, v, `a whole number from ${min} to ${max}`);
    return v;
}

function counts(figures, name, length) {
    const v = figures[name];
    if (!(Array.isArray(v) && v.length === length && v.every((c) => Number.isInteger(c) && c >= 1 && c <= COUNT_LIMIT))) {
        throw figureError(name, v, `${length} whole numbers from 1 to ${COUNT_LIMIT}`);
    }
    return v;
}

/**
 * The stage's figures once each is typed and bounded (data-schema/engine-textures.md, "The
 * stage's figures"): what the shader takes as constants and what the textures' shapes are checked
 * against, under the manifest's names.
 */
export function checkFigures(f) {
    if (typeof f !== 'object' || f === null || Array.isArray(f)) throw figureError('figures', f, 'an object');
    ['slices', 'vectors', 'rows', 'sectors', 'view_rows'].forEach((name) => count(f, name));
    const merlSize = counts(f, 'merl_size', 3);
    const phi = f.phi_d_range;
    const phiCells = { 180: Math.PI, 360: 2 * Math.PI }[merlSize[0]];
    if (!(typeof phi === 'number' && phiCells !== undefined && Math.abs(phi - phiCells) < 1e-6)) {
        throw figureError('phi_d_range', phi, `pi for 180 phi_d cells or 2 pi for 360 (merl_size ${JSON.stringify(merlSize)})`);
    }
    const samples = count(f, 'samples');
    if ((samples & (samples - 1)) !== 0) throw figureError('samples', samples, 'a power of two');
    for (const name of ['environment_size', 'layers_size']) {
        const [w, h] = counts(f, name, 2);
        if (w !== 2 * h) throw figureError(name, [w, h], 'a lat-long size, width twice the height');
    }
    const exponents = f.exponents;
    if (!(Array.isArray(exponents) && exponents.length >= 1 && exponents.length <= 64 && exponents.every((n) => Number.isInteger(n) && n >= 1))) {
        throw figureError('exponents', exponents, 'from 1 to 64 whole Phong exponents of at least 1');
    }
    if (typeof f.peaks !== 'boolean') throw figureError('peaks', f.peaks, 'true or false');
    const diffuse = f.diffuse;
    if (!(Array.isArray(diffuse) && diffuse.length === 3 && diffuse.every((v) => Number.isFinite(v) && v >= 0))) {
        throw figureError('diffuse', diffuse, 'three finite values of at least 0 (a bake older than this loader: bake it again)');
    }
    if (!(Number.isFinite(f.exposure_ev) && Math.abs(f.exposure_ev) <= 128)) {
        throw figureError('exposure_ev', f.exposure_ev, 'a finite exposure within 128 EV');
    }
    for (const mode of ['reference', 'prefiltered']) {
        const d = f.previewer?.[mode];
        const ok = d && Number.isInteger(d.spp) && d.spp >= 1 && (d.spp & (d.spp - 1)) === 0 && samples % d.spp === 0
            && Number.isInteger(d.frames) && d.frames >= 1 && d.frames <= 65536;
        if (!ok) throw figureError(`previewer.${mode}`, d, `{ spp, frames }: spp a power of two dividing the ${samples} samples, frames from 1 to 65536`);
    }
    return f;
}

/**
 * What each role's texture must be (data-schema/engine-textures.md, "The files"), from the
 * checked figures: its channels, its kind (2d, array or 3d), its width, height and layers or
 * depth, and the range of its values, every one finite.
 *
 * The ranges are what a bake of our tools can hold, so that none fails here:
 * - `engine-brdf-tables`, `engine-light-tables`: CDFs from 0 to 1 and the row edges
 *   `t = 1 - cos theta_h` of `[0, pi / 2]`, so `[0, 1]`.
 * - `engine-view-layers`: a layer coordinate from 0 to the number of layers.
 * - `engine-merl`: a cell's BRDF in 1/sr (0 without data, A 0 or 1). The MERL reader takes any
 *   finite value (`merl::MerlTable::from_raw`); a bake refuses only a cell that alone reflects
 *   more than twice the light received (`bake::stage::material_info::UNPHYSICAL_LIMIT`), which
 *   bounds nothing towards grazing angles or below the horizon, where a cell has no share
 *   (`merl::summary::cell_share`); the writer casts to f32 (`bake::stage::engine::run`) and
 *   refuses only what is then not finite (`prefilter::ktx::encode_data`). So up to FLT_MAX.
 * - `engine-environment`, `engine-layers`, `engine-full-layers`: radiance. The map's reader takes any finite
 *   non-negative f32 (`envmap`'s `check_radiance`), the bake keeps texels above 65504 as single
 *   floats (`prefilter::ktx::Storage::Auto`) and the writer refuses only what is not finite. So
 *   up to FLT_MAX.
 * Subnormal values are accepted: they are finite and in range, the writers' f64 to f32 casts
 * make them from tiny legitimate values (a CDF's step, a dim texel), and a GPU that flushes them
 * to 0 (GLSL ES 3.00 allows it) changes a value by less than 1.2e-38.
 */
function roles(f) {
    const [W, H] = f.environment_size;
    const [Wl, Hl] = f.layers_size;
    const R = f.rows;
    const C = f.sectors;
    return {
        'engine-merl': { uniform: 'uMerl', channels: 4, kind: '3d', shape: f.merl_size, range: [0, FLOAT32_MAX] },
        'engine-brdf-tables': { uniform: 'uBrdfTables', channels: 1, kind: 'array', shape: [Math.max(R, C) + 1, R + 2, f.slices], range: [0, 1] },
        'engine-view-layers': { uniform: 'uViewLayers', channels: 1, kind: '2d', shape: [f.view_rows, 1, 1], range: [0, f.exponents.length] },
        'engine-environment': { uniform: 'uEnvironment', channels: 4, kind: 'array', shape: [W, H, 2], range: [0, FLOAT32_MAX] },
        'engine-light-tables': { uniform: 'uLightTables', channels: 1, kind: 'array', shape: [Math.max(W, H) + 1, H + 1, 2], range: [0, 1] },
        'engine-layers': { uniform: 'uLayers', channels: 4, kind: 'array', shape: [Wl, Hl, f.exponents.length], range: [0, FLOAT32_MAX] },
        'engine-full-layers': { uniform: 'uFullLayers', channels: 4, kind: 'array', shape: [Wl, Hl, f.exponents.length], range: [0, FLOAT32_MAX] },
    };
}

/**
 * A data texture of the bake (KTX2, one level, R32_SFLOAT or R32G32B32A32_SFLOAT, 2D, 2D array or
 * 3D) as a three.js texture read with texelFetch: nearest filtering, no mipmaps, no flip (row 0
 * of the file is row 0 of the texture). With `expect` (a role's entry of `roles`), its format,
 * kind and shape must be the role's and every value finite and within the role's range.
 */
export function dataTexture(bytes, name, expect) {
    let container;
    try {
        container = readKtx2(bytes);
    } catch (e) {
        throw new BakeError(`error: ${name}: not a ktx2 file: ${e.message}`);
    }
    const { vkFormat, pixelWidth: w, pixelHeight: h, pixelDepth: d, layerCount: layers, levels } = container;
    const channels = { [VK_FORMAT_R32_SFLOAT]: 1, [VK_FORMAT_R32G32B32A32_SFLOAT]: 4 }[vkFormat];
    if (!channels || container.supercompressionScheme !== 0 || levels.length !== 1 || container.faceCount !== 1) {
        throw new BakeError(`error: ${name}: expected one level of r32f or rgba32f texels, found vkFormat ${vkFormat}`);
    }
    const kind = d > 0 ? '3d' : layers > 0 ? 'array' : '2d';
    const shape = [w, Math.max(h, 1), Math.max(d, layers, 1)];
    if (expect) {
        const format = (c) => (c === 1 ? 'r32f' : 'rgba32f');
        const found = `${format(channels)} ${kind} ${shape.join(' x ')}`;
        const wanted = `${format(expect.channels)} ${expect.kind} ${expect.shape.join(' x ')}`;
        if (found !== wanted) {
            throw new BakeError(`error: ${name}: ${found}, the manifest's figures make it ${wanted}`);
        }
    }
    const level = levels[0].levelData;
    const expected = 4 * channels * shape[0] * shape[1] * shape[2];
    if (level.byteLength !== expected) {
        throw new BakeError(`error: ${name}: level 0 holds ${level.byteLength} bytes, expected ${expected}`);
    }
    // Copied so that the floats are aligned whatever the level's offset in the file.
    const data = new Float32Array(level.slice().buffer);
    if (expect) {
        const [low, high] = expect.range;
        for (let i = 0; i < data.length; i++) {
            const v = data[i];
            if (!(Number.isFinite(v) && v >= low && v <= high)) {
                const texel = Math.floor(i / channels);
                const why = Number.isFinite(v) ? `outside [${low}, ${high}]` : 'not a finite number';
                throw new BakeError(`error: ${name}: value ${i} (texel ${texel}, channel ${i % channels}) is ${v}, ${why}`);
            }
        }
    }
    const format = channels === 1 ? THREE.RedFormat : THREE.RGBAFormat;
    let texture;
    if (kind === '3d') {
        texture = new THREE.Data3DTexture(data, w, h, d);
    } else if (kind === 'array') {
        texture = new THREE.DataArrayTexture(data, w, h, layers);
    } else {
        texture = new THREE.DataTexture(data, w, h);
    }
    texture.format = format;
    texture.type = THREE.FloatType;
    texture.minFilter = THREE.NearestFilter;
    texture.magFilter = THREE.NearestFilter;
    texture.generateMipmaps = false;
    texture.flipY = false;
    texture.unpackAlignment = 4;
    texture.needsUpdate = true;
    return texture;
}

function outputError(base, role, what) {
    return new BakeError(`error: ${base}manifest.json: the engine textures' ${role} output ${what}`);
}

/**
 * Reads the bake at `url` (a folder served over HTTP, with or without the trailing `/`): its
 * `manifest.json`, the engine textures' figures, then every engine texture by role (resolved
 * inside the folder, read up to its listed size, its SHA-256 checked, its format, shape and
 * values checked against its role). `fetch` is the page's unless given. Returns `{ manifest,
 * figures, textures }`, the textures by the uniform they bind.
 */
export async function readBake(url, { fetch = globalThis.fetch } = {}) {
    const base = new URL(String(url).endsWith('/') ? String(url) : `${url}/`, globalThis.location?.href);
    const manifestUrl = new URL('manifest.json', base);
    const manifestBytes = await fetchCapped(fetch, manifestUrl, String(manifestUrl), MANIFEST_LIMIT);
    let manifest;
    try {
        manifest = JSON.parse(new TextDecoder('utf-8', { fatal: true }).decode(manifestBytes));
    } catch (e) {
        throw new BakeError(`error: ${manifestUrl}: not json: ${e.message}`);
    }
    const stage = Array.isArray(manifest?.stages) ? manifest.stages.find((s) => s?.name === STAGE) : undefined;
    if (!stage) {
        throw new BakeError(`error: ${manifestUrl}: the bake has no engine textures: bake it with brdf-bake --engine-textures`);
    }
    if (!Array.isArray(stage.outputs)) throw new BakeError(`error: ${manifestUrl}: the engine textures' outputs are not a list`);
    let figures;
    try {
        figures = checkFigures(stage.figures);
    } catch (e) {
        throw new BakeError(e.message.replace('error: manifest.json:', `error: ${manifestUrl}:`));
    }
    const textures = {};
    await Promise.all(
        Object.entries(roles(figures)).map(async ([role, expect]) => {
            const listed = stage.outputs.filter((o) => o?.role === role);
            if (listed.length !== 1) {
                throw outputError(base, role, listed.length === 0 ? 'is missing' : 'is listed more than once');
            }
            const output = listed[0];
            if (!(Number.isInteger(output.size_bytes) && output.size_bytes >= 1 && output.size_bytes <= OUTPUT_LIMIT)) {
                throw outputError(base, role, `has size_bytes ${JSON.stringify(output.size_bytes)}, expected a whole number from 1 to ${OUTPUT_LIMIT}`);
            }
            if (!(typeof output.sha256 === 'string' && /^[0-9a-f]{64}$/.test(output.sha256))) {
                throw outputError(base, role, `has sha256 ${JSON.stringify(output.sha256)}, expected 64 lower-case hexadecimal digits`);
            }
            const fileUrl = resolveInside(base, output.path);
            const name = String(fileUrl);
            const bytes = await fetchCapped(fetch, fileUrl, name, output.size_bytes, output.size_bytes);
            if ((await sha256Hex(bytes)) !== output.sha256) {
                throw new BakeError(`error: ${name}: not the file the manifest describes (its sha256 differs)`);
            }
            textures[expect.uniform] = dataTexture(bytes, name, expect);
        }),
    );
    return { manifest, figures, textures };
}
