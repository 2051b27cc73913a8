// The example page (index.html): a bake on brdf-preview's sphere, the environment behind it, in
// the live mode (Accumulator): the split estimator's frame first, then one frame of the mode's
// samples per animation frame (`?spp=N` per frame, default 1), averaged while the view is still,
// up to `?frames=N` (default 256). Drag to orbit (the average starts again), switch modes; the status line gives the frames
// averaged and the milliseconds of the last one. brdf-preview's axes (+z up) and look: three's Reinhard tone mapping at the bake's
// automatic exposure and sRGB output are brdf-preview's tone map.
import * as THREE from 'three';
import { Accumulator, loadBake, orbitCamera, previewSphere, setOrbit } from './src/index.js';

const canvas = document.getElementById('view');
const status = document.getElementById('status');
const renderer = new THREE.WebGLRenderer({ canvas, antialias: false, preserveDrawingBuffer: true });
renderer.setPixelRatio(1);
renderer.setSize(canvas.width, canvas.height, false);
renderer.toneMapping = THREE.ReinhardToneMapping;
const camera = orbitCamera(canvas.width / canvas.height);
const view = { azimuth: 0, elevation: 0 };
const orientation = 'brdf-preview';
let current = null;

const params = new URLSearchParams(location.search);
document.getElementById('bake').value = params.get('bake') ?? '/target/demo/three-bake/';
if (params.get('mode')) document.querySelector(`input[name=mode][value=${CSS.escape(params.get('mode'))}]`).checked = true;
const live = new Accumulator(renderer, { maxFrames: Number(params.get('frames') ?? 256) });
const spp = Number(params.get('spp') ?? 1);

function mode() {
    return document.querySelector('input[name=mode]:checked').value;
}

async function load() {
    const url = document.getElementById('bake').value;
    status.textContent = `loading ${url} ...`;
    try {
        const bake = await loadBake(url);
        if (current) {
            current.scene.traverse((o) => {
                o.material?.dispose();
                // The background's quad is shared by every bake's background (index.js).
                if (o === current.mesh) o.geometry.dispose();
            });
            current.bake.dispose();
        }
        renderer.toneMappingExposure = 2 ** bake.figures.exposure_ev;
        const scene = new THREE.Scene();
        scene.add(bake.createBackground({ orientation }));
        const mesh = new THREE.Mesh(previewSphere(), bake.createMaterial({ mode: mode(), orientation, spp }));
        scene.add(mesh);
        current = { bake, scene, mesh };
        live.reset();
    } catch (e) {
        status.textContent = e.message;
    }
}

function setMode(m) {
    document.querySelector(`input[name=mode][value=${CSS.escape(m)}]`).checked = true;
    if (!current) return;
    current.mesh.material.dispose();
    current.mesh.material = current.bake.createMaterial({ mode: m, orientation, spp });
    live.reset();
}

// One animation frame: the next frame of samples added (until maxFrames), timed to the end of
// the draw (a one-pixel read waits for it).
function tick() {
    if (!current) return;
    const { bake, scene } = current;
    setOrbit(camera, view.azimuth, view.elevation);
    const adding = live.frames < live.maxFrames;
    const start = performance.now();
    live.render(scene, camera);
    renderer.getContext().readPixels(0, 0, 1, 1, WebGL2RenderingContext.RGBA, WebGL2RenderingContext.UNSIGNED_BYTE, new Uint8Array(4));
    if (!adding) return;
    const ms = performance.now() - start;
    const m = mode();
    const names = `${bake.manifest.material.name} under ${bake.manifest.environment?.name}`;
    const frames = m === 'split' ? 'no samples' : `the split, then ${spp} spp x ${live.frames - 1} frames`;
    status.textContent =
        `${names} | ${m} | ${frames} (live, up to ${live.maxFrames})\n` +
        `${canvas.width}x${canvas.height} | exposure ${bake.figures.exposure_ev.toFixed(2)} EV\n` +
        `${ms.toFixed(1)} ms per frame | camera ${view.azimuth.toFixed(0)},${view.elevation.toFixed(0)}`;
}

let drag = null;
canvas.addEventListener('pointerdown', (e) => {
    drag = { x: e.clientX, y: e.clientY, azimuth: view.azimuth, elevation: view.elevation };
    canvas.setPointerCapture(e.pointerId);
});
canvas.addEventListener('pointermove', (e) => {
    if (!drag) return;
    view.azimuth = drag.azimuth - (e.clientX - drag.x) * 0.5;
    view.elevation = Math.max(-89, Math.min(89, drag.elevation + (e.clientY - drag.y) * 0.5));
});
canvas.addEventListener('pointerup', () => {
    drag = null;
});
document.getElementById('load').addEventListener('click', load);
document.querySelectorAll('input[name=mode]').forEach((r) => r.addEventListener('change', () => setMode(mode())));
window.brdfExample = { view, setMode, live };
renderer.setAnimationLoop(tick);
load();
