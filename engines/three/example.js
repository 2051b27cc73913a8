// The example page (index.html): a bake on brdf-preview's sphere, the environment behind it,
// orbit by dragging, the mode switch, and the milliseconds per frame of each picture.
import * as THREE from 'three';
import { loadBake, orbitCamera, previewSphere, setOrbit } from './src/index.js';

const canvas = document.getElementById('view');
const status = document.getElementById('status');
const renderer = new THREE.WebGLRenderer({ canvas, antialias: false, preserveDrawingBuffer: true });
renderer.setPixelRatio(1);
renderer.setSize(canvas.width, canvas.height, false);
const camera = orbitCamera(canvas.width / canvas.height);
const view = { azimuth: 0, elevation: 0 };
let current = null;
const look = { orientation: 'brdf-preview', output: 'brdf-preview' };

const params = new URLSearchParams(location.search);
document.getElementById('bake').value = params.get('bake') ?? '/target/demo/bake/';
if (params.get('mode')) document.querySelector(`input[name=mode][value=${CSS.escape(params.get('mode'))}]`).checked = true;
if (params.get('frames')) document.getElementById('frames').value = params.get('frames');

function mode() {
    return document.querySelector('input[name=mode]:checked').value;
}

async function load() {
    const url = document.getElementById('bake').value;
    status.textContent = `loading ${url} ...`;
    try {
        const bake = await loadBake(url);
        current?.bake.dispose();
        const scene = new THREE.Scene();
        // brdf-preview's sphere and camera, so brdf-preview's axes (+z up) and picture.
        scene.add(bake.createBackground(look));
        const mesh = new THREE.Mesh(previewSphere(), bake.createMaterial({ mode: mode(), ...look }));
        scene.add(mesh);
        current = { bake, scene, mesh };
        draw();
    } catch (e) {
        status.textContent = e.message;
    }
}

// One picture: the frames of the chosen mode, timed to the end of the draw (a one-pixel read
// waits for it).
function draw() {
    if (!current) return;
    const { bake, scene, mesh } = current;
    const m = mode();
    const defaults = bake.defaults(m);
    const frames = document.getElementById('frames').value === '1' ? 1 : defaults.frames;
    mesh.material.dispose();
    mesh.material = bake.createMaterial({ mode: m, frames, ...look });
    setOrbit(camera, view.azimuth, view.elevation);
    const gl = renderer.getContext();
    const start = performance.now();
    renderer.render(scene, camera);
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));
    const ms = performance.now() - start;
    const names = `${bake.manifest.material.name} under ${bake.manifest.environment?.name}`;
    status.textContent =
        `${names} | ${m} | ${defaults.spp} spp x ${frames} frames\n` +
        `${canvas.width}x${canvas.height} | exposure ${bake.figures.exposure_ev.toFixed(2)} EV\n` +
        `${(ms / frames).toFixed(1)} ms per frame (${ms.toFixed(0)} ms for the picture) | camera ${view.azimuth.toFixed(0)},${view.elevation.toFixed(0)}`;
}

let drag = null;
canvas.addEventListener('pointerdown', (e) => {
    drag = { x: e.clientX, y: e.clientY, azimuth: view.azimuth, elevation: view.elevation };
    canvas.setPointerCapture(e.pointerId);
});
canvas.addEventListener('pointerup', (e) => {
    if (!drag) return;
    view.azimuth = drag.azimuth - (e.clientX - drag.x) * 0.5;
    view.elevation = Math.max(-89, Math.min(89, drag.elevation + (e.clientY - drag.y) * 0.5));
    drag = null;
    draw();
});
document.getElementById('load').addEventListener('click', load);
document.querySelectorAll('input[name=mode]').forEach((r) => r.addEventListener('change', draw));
document.getElementById('frames').addEventListener('change', draw);
window.brdfExample = { draw, view, setMode: (m) => { document.querySelector(`input[value=${m}]`).checked = true; draw(); } };
load();
