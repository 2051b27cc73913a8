// The loader's checks (node --test): a manifest and its files are untrusted, so a path resolves
// inside the bake folder or is refused, and every figure, listing, response and texture a hostile
// bake can give is a BakeError naming the file.
import assert from 'node:assert/strict';
import { test } from 'node:test';

import { BakeError, resolveInside } from '../src/index.js';

const base = new URL('http://127.0.0.1:8000/bakes/gold/');

test('relative paths resolve inside the bake folder', () => {
    assert.equal(resolveInside(base, 'engine-merl.ktx2').href, 'http://127.0.0.1:8000/bakes/gold/engine-merl.ktx2');
    assert.equal(resolveInside(base, 'sub/a b.ktx2').href, 'http://127.0.0.1:8000/bakes/gold/sub/a%20b.ktx2');
});

test('paths that leave the folder are refused', () => {
    for (const path of ['../x.ktx2', 'a/../../x', '/etc/passwd', 'http://evil.example/x', '//evil.example/x', 'C:\\x',
        'a\\..\\x', '%2e%2e/x', './x', 'a//b', '', 'x?y', 'x#y', null, 3]) {
        assert.throws(() => resolveInside(base, path), BakeError, `accepted ${JSON.stringify(path)}`);
    }
});

// The loader's checks on a synthetic bake served by a fake fetch: each attack of a hostile
// manifest or file is a BakeError naming the file (and the figure, texture or value).
import { createDefaultContainer, write as writeKtx2 } from 'ktx-parse';

import { FLOAT32_MAX, MANIFEST_LIMIT, loadBake, sha256Hex } from '../src/index.js';

const BAKE = new URL('http://127.0.0.1:8000/bakes/synthetic/');

/** A KTX2 file of `channels` float channels, `kind` 2d, array or 3d, of `shape` [w, h, layers or depth]. */
function ktx2(channels, kind, [w, h, n], value = () => 0.5) {
    const container = createDefaultContainer();
    container.vkFormat = channels === 1 ? 100 : 109;
    container.typeSize = 4;
    container.pixelWidth = w;
    container.pixelHeight = h;
    container.pixelDepth = kind === '3d' ? n : 0;
    container.layerCount = kind === 'array' ? n : 0;
    const data = new Float32Array(channels * w * h * n).map((_, i) => value(i));
    const bytes = new Uint8Array(data.buffer);
    container.levels = [{ levelData: bytes, uncompressedByteLength: bytes.byteLength }];
    return writeKtx2(container);
}

/**
 * The synthetic bake's textures by role: the uniform each binds, its channels, kind and shape,
 * and the largest value its role allows (the loader's ranges, all from 0).
 */
const TEXTURES = {
    'engine-merl': { uniform: 'uMerl', channels: 4, kind: '3d', shape: [180, 2, 2], high: FLOAT32_MAX },
    'engine-brdf-tables': { uniform: 'uBrdfTables', channels: 1, kind: 'array', shape: [3, 4, 2], high: 1 },
    'engine-view-layers': { uniform: 'uViewLayers', channels: 1, kind: '2d', shape: [2, 1, 1], high: 2 },
    'engine-environment': { uniform: 'uEnvironment', channels: 4, kind: 'array', shape: [4, 2, 2], high: FLOAT32_MAX },
    'engine-light-tables': { uniform: 'uLightTables', channels: 1, kind: 'array', shape: [5, 3, 2], high: 1 },
    'engine-layers': { uniform: 'uLayers', channels: 4, kind: 'array', shape: [4, 2, 2], high: FLOAT32_MAX },
    'engine-full-layers': { uniform: 'uFullLayers', channels: 4, kind: 'array', shape: [4, 2, 2], high: FLOAT32_MAX },
};

/** The synthetic bake's texture of `role`, 0.5 everywhere but where `value(i)` says otherwise. */
function textureOf(role, value = () => 0.5) {
    const { channels, kind, shape } = TEXTURES[role];
    return ktx2(channels, kind, shape, value);
}

/** A small bake's files and its figures: two slices, rows and sectors, a 4 x 2 map, two layers. */
function syntheticBake() {
    const figures = {
        merl_size: [180, 2, 2], phi_d_range: Math.PI, slices: 2, vectors: 1, samples: 4, rows: 2, sectors: 2,
        view_rows: 2, environment_size: [4, 2], layers_size: [4, 2], exponents: [1, 4], peaks: false,
        peak_threshold: null, diffuse: [0.1, 0.1, 0.1], exposure_ev: -1,
        previewer: { reference: { spp: 4, frames: 2 }, prefiltered: { spp: 2, frames: 2 } },
    };
    const files = Object.fromEntries(Object.keys(TEXTURES).map((role) => [role, textureOf(role)]));
    return { figures, files };
}

/** The manifest of `files` (by role) with `figures`, each listed with its size and SHA-256. */
async function manifestOf(figures, files) {
    const outputs = await Promise.all(
        Object.entries(files).map(async ([role, bytes]) => ({
            path: `${role}.ktx2`, format: 'ktx2', role, size_bytes: bytes.byteLength, sha256: await sha256Hex(bytes),
        })),
    );
    return { manifest_version: 2, stages: [{ name: 'engine-textures', outputs, figures }] };
}

/** A fetch serving `bodies` (path below BAKE to bytes, a ReadableStream or a Response). */
function fakeFetch(bodies) {
    return async (url) => {
        const path = String(url).slice(String(BAKE).length);
        const body = bodies[path];
        if (body === undefined) return new Response(null, { status: 404 });
        return body instanceof Response ? body : new Response(body);
    };
}

/** Loads the synthetic bake after `edit(figures, files)` and `editManifest(manifest)`. */
async function load(edit = () => {}, editManifest = () => {}, serve = (m, f) => f) {
    const { figures, files } = syntheticBake();
    edit(figures, files);
    const manifest = await manifestOf(figures, files);
    editManifest(manifest);
    const bodies = { 'manifest.json': new TextEncoder().encode(JSON.stringify(manifest)) };
    for (const [role, bytes] of Object.entries(files)) bodies[`${role}.ktx2`] = bytes;
    return loadBake(BAKE, { fetch: fakeFetch(serve(manifest, bodies)) });
}

async function refused(promise, ...needles) {
    await assert.rejects(promise, (e) => {
        assert.ok(e instanceof BakeError, `not a BakeError: ${e}`);
        assert.ok(e.message.startsWith('error: '), e.message);
        for (const needle of needles) assert.ok(e.message.includes(needle), `${JSON.stringify(e.message)} lacks ${JSON.stringify(needle)}`);
        return true;
    });
}

test('the synthetic bake loads', async () => {
    const bake = await load();
    assert.equal(bake.figures.slices, 2);
    assert.equal(Object.keys(bake.textures).length, Object.keys(TEXTURES).length);
});

test('figures of the wrong type or out of range are refused, naming the figure', async () => {
    const cases = [
        [(f) => { f.slices = '2'; }, "slices is \"2\""],
        [(f) => { f.rows = -1; }, 'rows is -1'],
        [(f) => { f.sectors = 2 ** 31; }, 'sectors is 2147483648'],
        [(f) => { f.samples = 6; }, 'samples is 6, expected a power of two'],
        [(f) => { f.phi_d_range = 2 * Math.PI; }, 'phi_d_range'],
        [(f) => { f.exponents = []; }, 'exponents is []'],
        [(f) => { f.diffuse = [0.1, null, 0.1]; }, 'diffuse is [0.1,null,0.1]'],
        [(f) => { f.exposure_ev = 1e308 * 10; }, 'exposure_ev is null'],
        [(f) => { f.exposure_ev = 1e308; }, 'exposure_ev is 1e+308, expected a finite exposure within 128 EV'],
        [(f) => { f.previewer.reference.frames = 1e12; }, 'previewer.reference is {"spp":4,"frames":1000000000000}', 'frames from 1 to 65536'],
        [(f) => { f.environment_size = [4, 4]; }, 'environment_size is [4,4], expected a lat-long size'],
        [(f) => { f.previewer.prefiltered.spp = 3; }, 'previewer.prefiltered'],
        [(f) => { f.peaks = 'yes'; }, 'peaks is "yes"'],
    ];
    for (const [edit, ...needles] of cases) await refused(load(edit), `${BAKE}manifest.json`, ...needles);
});

test('textures of the wrong format or shape, or with values out of range, are refused, naming the file', async () => {
    const cases = [
        [(f, files) => { files['engine-brdf-tables'] = ktx2(1, 'array', [3, 4, 3]); }, 'engine-brdf-tables.ktx2: r32f array 3 x 4 x 3, the manifest\'s figures make it r32f array 3 x 4 x 2'],
        [(f, files) => { files['engine-environment'] = ktx2(1, 'array', [4, 2, 2]); }, 'engine-environment.ktx2: r32f array'],
        [(f, files) => { files['engine-merl'] = ktx2(4, 'array', [180, 2, 2]); }, 'engine-merl.ktx2: rgba32f array'],
        [(f, files) => { files['engine-layers'] = ktx2(4, 'array', [4, 2, 2], (i) => (i === 5 ? NaN : 1)); }, 'engine-layers.ktx2: value 5 (texel 1, channel 1) is NaN'],
        [(f, files) => { files['engine-environment'] = ktx2(4, 'array', [4, 2, 2], (i) => (i === 0 ? -1 : 1)); }, 'engine-environment.ktx2: value 0 (texel 0, channel 0) is -1'],
        [(f, files) => { files['engine-light-tables'] = ktx2(1, 'array', [5, 3, 2], (i) => (i === 7 ? 1.5 : 0.5)); }, 'engine-light-tables.ktx2: value 7', 'outside [0, 1]'],
        [(f, files) => { files['engine-view-layers'] = ktx2(1, '2d', [2, 1, 1], () => 2.5); }, 'engine-view-layers.ktx2: value 0', 'outside [0, 2]'],
        [(f, files) => { files['engine-merl'] = new Uint8Array([1, 2, 3]); }, 'engine-merl.ktx2: not a ktx2 file'],
    ];
    for (const [edit, ...needles] of cases) await refused(load(edit), ...needles);
});

/** The message's start for value 1 of `role`'s texture (texel 0 channel 1, or texel 1 of one channel). */
function valueOne(role) {
    const channels = TEXTURES[role].channels;
    return `${BAKE}${role}.ktx2: value 1 (texel ${Math.floor(1 / channels)}, channel ${1 % channels}) is `;
}

test('every role refuses a value that is not finite, negative or above its bound, naming the file and the value', async () => {
    for (const [role, { high }] of Object.entries(TEXTURES)) {
        const bad = [
            [Infinity, 'not a finite number'],
            [-Infinity, 'not a finite number'],
            [NaN, 'not a finite number'],
            [-1, `outside [0, ${high}]`],
            [-1e-40, `outside [0, ${high}]`], // a negative subnormal is negative
        ];
        // Above the bound: 1e30 where it is 1 or K; above FLT_MAX a single float is Infinity, refused above.
        if (high < 1e30) bad.push([1e30, `outside [0, ${high}]`]);
        for (const [value, why] of bad) {
            const edit = (f, files) => { files[role] = textureOf(role, (i) => (i === 1 ? value : 0.5)); };
            await refused(load(edit), `${valueOne(role)}${Math.fround(value)}, ${why}`);
        }
    }
});

// The ranges are what a bake of ours can hold (loader.js, `roles`): radiance and the BRDF up to
// the largest float, since our Rust readers bound them only by being finite, and subnormals in
// every role, being finite and in range.
test('values a bake of ours can hold load: subnormals and -0 in every role, up to FLT_MAX for radiance and the BRDF', async () => {
    const subnormal = Math.fround(1e-40);
    assert.ok(subnormal > 0 && subnormal < 2 ** -126, 'not an f32 subnormal');
    for (const [role, { uniform, high }] of Object.entries(TEXTURES)) {
        const values = high === FLOAT32_MAX ? [subnormal, -0, 1e30, FLOAT32_MAX] : [subnormal, -0, high];
        for (const value of values) {
            const bake = await load((f, files) => { files[role] = textureOf(role, (i) => (i === 1 ? value : 0.5)); });
            assert.equal(bake.textures[uniform].image.data[1], Math.fround(value), `${role}: ${value}`);
        }
    }
});

test('a texture served under another role of the same format and shape is caught by its sha256', async () => {
    // engine-layers and engine-environment are both rgba32f arrays of 4 x 2 x 2 here: the same
    // size, header and shape, told apart only by the hash their listing gives.
    const layers = (f, files) => { files['engine-layers'] = textureOf('engine-layers', () => 0.25); };
    const swap = (m, b) => ({ ...b, 'engine-environment.ktx2': b['engine-layers.ktx2'], 'engine-layers.ktx2': b['engine-environment.ktx2'] });
    await refused(load(layers, () => {}, swap), `${BAKE}engine-environment.ktx2: not the file the manifest describes (its sha256 differs)`);
    // The hash binds a file to its listing, role included: a manifest whose listings themselves
    // swap the two roles describes another bake, consistent in every check, and loads as one.
    const swapRoles = (m) => {
        const [environment, layersListing] = ['engine-environment', 'engine-layers'].map((r) => m.stages[0].outputs.find((o) => o.role === r));
        [environment.role, layersListing.role] = [layersListing.role, environment.role];
    };
    const bake = await load(layers, swapRoles);
    assert.equal(bake.textures.uEnvironment.image.data[0], 0.25);
});

test('outputs listed wrongly are refused, naming the manifest', async () => {
    const texture = (m, role) => m.stages[0].outputs.find((o) => o.role === role);
    const cases = [
        [(m) => { m.stages[0].outputs = m.stages[0].outputs.filter((o) => o.role !== 'engine-layers'); }, 'engine-layers output is missing'],
        [(m) => { m.stages[0].outputs.push({ ...texture(m, 'engine-merl') }); }, 'engine-merl output is listed more than once'],
        [(m) => { texture(m, 'engine-merl').size_bytes = 1e12; }, 'engine-merl output has size_bytes 1000000000000'],
        [(m) => { texture(m, 'engine-merl').size_bytes = '5'; }, 'size_bytes "5"'],
        [(m) => { texture(m, 'engine-merl').sha256 = 'ABC'; }, 'has sha256 "ABC"'],
        [(m) => { texture(m, 'engine-merl').path = '../engine-merl.ktx2'; }, 'leaves the bake folder'],
        [(m) => { m.stages[0].outputs = 'none'; }, 'outputs are not a list'],
        [(m) => { m.stages = []; }, 'the bake has no engine textures'],
    ];
    for (const [editManifest, needle] of cases) await refused(load(() => {}, editManifest), needle);
});

// A reader that did not stop at the limit would read the endless body for ever: the timeout fails it.
test('responses are read as streams up to the listed size, and checked by sha256', { timeout: 20000 }, async () => {
    // A body that never ends: refused once it passes the listed size.
    const endless = () =>
        new Response(new ReadableStream({ pull: (c) => c.enqueue(new Uint8Array(65536)) }));
    await refused(load(() => {}, () => {}, (m, b) => ({ ...b, 'engine-layers.ktx2': endless() })), 'engine-layers.ktx2: more than');
    // A manifest past the limit, declared or not.
    await refused(load(() => {}, () => {}, (m, b) => ({ ...b, 'manifest.json': endless() })), 'manifest.json: more than 16777216 bytes');
    const declared = new Response(new Uint8Array(8), { headers: { 'content-length': String(MANIFEST_LIMIT + 1) } });
    await refused(load(() => {}, () => {}, (m, b) => ({ ...b, 'manifest.json': declared })), 'manifest.json: more than');
    // A shorter file, another file of the same size, a missing one, a manifest that is not JSON.
    await refused(load(() => {}, () => {}, (m, b) => ({ ...b, 'engine-merl.ktx2': b['engine-merl.ktx2'].slice(1) })), 'engine-merl.ktx2: ', 'bytes, the manifest says');
    await refused(load(() => {}, () => {}, (m, b) => ({ ...b, 'engine-merl.ktx2': b['engine-merl.ktx2'].map((v, i) => (i === 100 ? v ^ 1 : v)) })), 'engine-merl.ktx2: not the file the manifest describes');
    await refused(load(() => {}, () => {}, (m, b) => ({ ...b, 'engine-view-layers.ktx2': undefined })), 'engine-view-layers.ktx2: HTTP 404');
    await refused(load(() => {}, () => {}, (m, b) => ({ ...b, 'manifest.json': new Uint8Array([0xff, 0xfe]) })), 'manifest.json: not json');
    // A response with no body at all: no bytes, so not json, or shorter than listed.
    await refused(load(() => {}, () => {}, (m, b) => ({ ...b, 'manifest.json': new Response(null) })), 'manifest.json: not json');
    await refused(load(() => {}, () => {}, (m, b) => ({ ...b, 'engine-merl.ktx2': new Response(null) })), 'engine-merl.ktx2: 0 bytes, the manifest says');
});

test('without WebCrypto the sha256 is still checked', async () => {
    const bytes = new TextEncoder().encode('abc');
    const withCrypto = await sha256Hex(bytes);
    const saved = Object.getOwnPropertyDescriptor(globalThis, 'crypto');
    Object.defineProperty(globalThis, 'crypto', { value: undefined, configurable: true });
    try {
        assert.equal(await sha256Hex(bytes), withCrypto);
        assert.equal(withCrypto, 'ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad');
        await refused(load(() => {}, () => {}, (m, b) => ({ ...b, 'engine-merl.ktx2': b['engine-merl.ktx2'].map((v, i) => (i === 100 ? v ^ 1 : v)) })), 'not the file the manifest describes');
    } finally {
        Object.defineProperty(globalThis, 'crypto', saved);
    }
});
