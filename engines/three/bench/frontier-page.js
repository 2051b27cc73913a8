// What engines/three/bench/frontier.mjs calls in the test page (test/page.html): one bake in a
// y-up three.js scene, drawn by three's MeshStandardMaterial and MeshPhysicalMaterial at fitted
// parameters, by the glTF material brdf-fit fitted to the table (the bake's material.gltf, read
// by three's GLTFLoader; beside it the same glTF BRDF drawn exactly, from the fit's own bake) and
// by the bake's material at a few sample counts, timed and compared with the converged estimate
// (window.frontier).
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { loadBake } from '../src/index.js';
import { SPLIT_WEIGHT, floatTarget } from '../src/live.js';
import { drawFloats, pageRenderer } from '../test/page-tools.js';
import { previewLevel as level } from '../test/tonemap.js';

// The sphere at the origin, the camera 3.2 away, 15 degrees above the horizon, 45 degrees of
// field of view: the same picture for every material.
function camera(aspect) {
    const c = new THREE.PerspectiveCamera(45, aspect, 0.032, 320);
    const el = (15 * Math.PI) / 180;
    c.position.set(0, 3.2 * Math.sin(el), 3.2 * Math.cos(el));
    c.lookAt(0, 0, 0);
    c.updateMatrixWorld();
    return c;
}


/**
 * The sphere at the origin of a y-up scene lit by the bake at `url` (its map as
 * scene.environment), drawn into a float target of size x size by a renderer on a canvas of
 * canvasSize x canvasSize without tone mapping: `linear(material)` gives its linear RGBA,
 * `covered` the sphere's pixels (where a drawing writes alpha 1), `psnr(values, truth)` the PSNR
 * of the tone-mapped values there (brdf-preview's tone map at the bake's automatic exposure).
 * What every benchmark page function starts from; `dispose()` frees it all, with whatever was
 * added to `disposables`.
 */
export async function sphereScene(url, size, canvasSize) {
    const renderer = pageRenderer(canvasSize, canvasSize);
    renderer.toneMapping = THREE.NoToneMapping;
    const bake = await loadBake(url);
    const exposure = 2 ** bake.figures.exposure_ev;
    const map = bake.environmentTexture();
    const sphere = new THREE.SphereGeometry(1, 128, 64);
    const mesh = new THREE.Mesh(sphere);
    const scene = new THREE.Scene();
    scene.environment = map;
    scene.add(mesh);
    const target = floatTarget(size, size);
    const view = camera(1);
    const white = new THREE.MeshBasicMaterial({ color: 0xffffff });
    const disposables = [map, sphere, target, white];

    const linear = (material) => {
        mesh.material = material;
        return drawFloats(renderer, target, scene, view);
    };
    const coverage = linear(white);
    const covered = [];
    for (let i = 0; i < size * size; i++) if (coverage[4 * i + 3] > 0.5) covered.push(i);
    // Squared error of the tone-mapped values (what the picture shows), in levels, and as PSNR.
    const toneError = (values, truth) => {
        let sum = 0;
        for (const i of covered) {
            for (let c = 0; c < 3; c++) sum += (level(values[4 * i + c], exposure) - level(truth[4 * i + c], exposure)) ** 2;
        }
        return sum;
    };
    const psnr = (values, truth) => 10 * Math.log10((255 * 255) / (toneError(values, truth) / (3 * covered.length)));
    // The tone-mapped picture as 8-bit RGB, rows from the top, black around the sphere.
    const picture = (values) => {
        const rgb = new Array(3 * size * size).fill(0);
        for (const i of covered) {
            const [x, y] = [i % size, size - 1 - Math.floor(i / size)];
            for (let c = 0; c < 3; c++) rgb[3 * (y * size + x) + c] = level(values[4 * i + c], exposure);
        }
        return rgb;
    };
    const dispose = () => {
        disposables.forEach((d) => d.dispose());
        bake.dispose();
        renderer.dispose();
    };
    return { renderer, bake, exposure, scene, mesh, view, linear, covered, toneError, psnr, picture, disposables, dispose };
}

/**
 * brdf-fit's material as a glTF viewer reads it: three's GLTFLoader turns the bake's
 * material.gltf (brdf-bake --fit) into a MeshStandardMaterial, or a MeshPhysicalMaterial with
 * KHR_materials_specular or KHR_materials_clearcoat, drawn on the sphere of `s`
 * (sphereScene). Beside it, apart from three, the same glTF BRDF drawn exactly (brdf-fit's
 * fit.binary baked with its own engine textures at `fitUrl`, drawn by the reference estimator at
 * 64 samples per strategy x truthFrames frames), and the largest difference between the factors
 * three read and fit.json's.
 */
export async function gltfBeside(url, fitUrl, s, truthFrames) {
    const gltf = await new GLTFLoader().loadAsync(`${url}material.gltf`);
    let material = null;
    gltf.scene.traverse((o) => {
        if (o.isMesh && !material) material = o.material;
    });
    if (!material) throw new Error(`${url}material.gltf holds no mesh`);
    gltf.scene.traverse((o) => o.isMesh && o.geometry.dispose());
    s.disposables.push(material);
    const values = s.linear(material);
    const fitBake = await loadBake(fitUrl);
    const exactMaterial = fitBake.createMaterial({ mode: 'reference', spp: 64, frames: truthFrames });
    s.disposables.push(exactMaterial, fitBake);
    const exact = s.linear(exactMaterial);
    const record = await (await fetch(`${url}fit.json`)).json();
    return { material, values, exact, readBack: factorDifference(material, record.material) };
}

window.frontier = async ({ bake: url, fitBake: fitUrl, size, timingSize, truthFrames, timingDraws }) => {
    const s = await sphereScene(url, size, timingSize);
    const { renderer, bake, exposure, scene, mesh, view, linear, covered, toneError, psnr, disposables } = s;

    // The truth: the bake's reference estimator at 64 samples per strategy and truthFrames frames.
    const truthMaterial = bake.createMaterial({ mode: 'reference', spp: 64, frames: truthFrames });
    disposables.push(truthMaterial);
    const truth = linear(truthMaterial);

    const fitting = { linear, truth, covered, exposure, toneError };
    const colourOf = (c) => (Array.isArray(c) ? new THREE.Color(...c) : new THREE.Color(c, c, c));
    const roughnesses = Array.from({ length: 16 }, (_, i) => 0.02 + (0.98 * i) / 15);
    const standardGrid = [0, 0.25, 0.5, 0.75, 1].flatMap((metalness) => roughnesses.map((roughness) => ({ metalness, roughness })));
    const standard = fit(
        (p, c) => new THREE.MeshStandardMaterial({ color: colourOf(c), metalness: p.metalness, roughness: p.roughness }),
        standardGrid,
        fitting,
    );
    const physicalGrid = [0, 0.5, 1].flatMap((clearcoat) => [0.03, 0.15, 0.4].map((clearcoatRoughness) => ({ ...standard.params, clearcoat, clearcoatRoughness })));
    const physical = fit(
        (p, c) => new THREE.MeshPhysicalMaterial({ color: colourOf(c), ...p }),
        physicalGrid,
        fitting,
    );
    disposables.push(standard.material, physical.material);

    const gltf = await gltfBeside(url, fitUrl, s, truthFrames);
    const fitted = gltf.material;

    // The live mode's first frame: the split estimator (no samples).
    const splitMaterial = bake.createMaterial({ mode: 'split' });
    disposables.push(splitMaterial);
    const splitValues = linear(splitMaterial);

    // The bake's material, one frame at 1, 4 and 16 samples.
    const measured = {};
    for (const spp of [1, 4, 16]) {
        const material = bake.createMaterial({ mode: 'prefiltered', spp, frames: 1 });
        disposables.push(material);
        measured[spp] = { material, psnr: psnr(linear(material), truth) };
    }

    // Milliseconds per frame at timingSize x timingSize on the canvas: one untimed draw (it
    // compiles the programs and uploads the textures; for three's materials it makes the PMREM),
    // then timingDraws draws, each waited for by a one-pixel read.
    renderer.setRenderTarget(null);
    renderer.setSize(timingSize, timingSize, false);
    const time = (material) => msPerFrame(renderer, scene, view, mesh, material, timingDraws);
    const ms = {
        standard: time(standard.material),
        physical: time(physical.material),
        gltf: time(fitted),
        split: time(splitMaterial),
        measured: Object.fromEntries([1, 4, 16].map((spp) => [spp, time(measured[spp].material)])),
    };

    // The live mode after the time of 8 standard frames: its split frame, then as many 1-sample
    // frames as the rest of that time holds, averaged as the Accumulator averages them (the split
    // counted SPLIT_WEIGHT times; its mean of the sampled frames equals one draw of them).
    const liveFrames = Math.max(0, Math.floor((8 * ms.standard - ms.split) / ms.measured[1]));
    let liveValues = splitValues;
    if (liveFrames > 0) {
        const liveMaterial = bake.createMaterial({ mode: 'prefiltered', spp: 1, frames: liveFrames });
        disposables.push(liveMaterial);
        const sampled = linear(liveMaterial);
        liveValues = splitValues.map((v, i) => (SPLIT_WEIGHT * v + liveFrames * sampled[i]) / (SPLIT_WEIGHT + liveFrames));
    }
    const live = { frames: liveFrames, psnr: psnr(liveValues, truth) };

    const result = {
        size,
        timingSize,
        pixels: covered.length,
        standard: { params: standard.params, colour: standard.colour, psnr: psnr(standard.values, truth) },
        physical: { params: physical.params, colour: physical.colour, psnr: psnr(physical.values, truth) },
        gltf: {
            type: fitted.type,
            psnr: psnr(gltf.values, truth),
            exactPsnr: psnr(gltf.exact, truth),
            threeAgainstExact: psnr(gltf.values, gltf.exact),
            readBack: gltf.readBack,
        },
        split: psnr(splitValues, truth),
        measured: Object.fromEntries(Object.entries(measured).map(([spp, m]) => [spp, m.psnr])),
        live,
        ms,
    };
    s.dispose();
    return result;
};

// The largest difference between the factors of fit.json's `material` and those three's
// GLTFLoader gave `material` (a MeshStandardMaterial, or a MeshPhysicalMaterial with
// KHR_materials_specular or KHR_materials_clearcoat; colours in three's linear working space,
// where glTF's factors are linear): 0 where three reads exactly what the fit wrote.
function factorDifference(material, fit) {
    const pairs = [
        [material.color.toArray(), fit.baseColorFactor],
        [material.metalness, fit.metallicFactor],
        [material.roughness, fit.roughnessFactor],
    ];
    if (material.isMeshPhysicalMaterial) {
        pairs.push(
            [material.specularIntensity, fit.specularFactor],
            [material.specularColor.toArray(), fit.specularColorFactor],
            [material.clearcoat, fit.clearcoatFactor],
            [material.clearcoatRoughness, fit.clearcoatRoughnessFactor],
        );
    }
    return Math.max(...pairs.flatMap(([a, b]) => [a].flat().map((x, i) => Math.abs(x - [b].flat()[i]))));
}

// Three's materials at fitted parameters, fitted to what the picture shows: the squared
// error of the tone-mapped values over the sphere's pixels (a fit of linear radiance is ruled
// by the sun's few pixels, which three's PMREM spreads). Their radiance is affine in the base
// colour, per channel (the diffuse part scales with it, the split-sum specular with F0 =
// mix(0.04, colour, metalness)), so for each point of a grid of the other parameters two
// drawings (colour 0 and 1) give every colour's picture: each channel's colour in [0, 1] is
// found by a golden-section search on it, and the grid point with the least error wins.
function fit(make, grid, { linear, truth, covered, exposure, toneError }) {
    let best = null;
    for (const params of grid) {
        const m0 = make(params, 0);
        const m1 = make(params, 1);
        const [c0, c1] = [linear(m0), linear(m1)];
        m0.dispose();
        m1.dispose();
        const colour = [0, 1, 2].map((c) => {
            const error = (k) => {
                let sum = 0;
                for (const i of covered) {
                    const v = c0[4 * i + c] + k * (c1[4 * i + c] - c0[4 * i + c]);
                    sum += (level(v, exposure) - level(truth[4 * i + c], exposure)) ** 2;
                }
                return sum;
            };
            let [a, b] = [0, 1];
            const g = (Math.sqrt(5) - 1) / 2;
            for (let step = 0; step < 24; step++) {
                const [x1, x2] = [b - g * (b - a), a + g * (b - a)];
                if (error(x1) <= error(x2)) b = x2;
                else a = x1;
            }
            return (a + b) / 2;
        });
        const material = make(params, colour);
        const values = linear(material);
        const error = toneError(values, truth);
        if (!best || error < best.error) {
            best?.material.dispose();
            best = { params, colour, error, values, material };
        } else {
            material.dispose();
        }
    }
    return best;
}

/**
 * Milliseconds per frame of `mesh` drawn with `material` in `scene`: one untimed draw, then
 * `draws` timed ones, each waited for by a one-pixel read.
 */
function msPerFrame(renderer, scene, view, mesh, material, draws) {
    const gl = renderer.getContext();
    const pixel = new Uint8Array(4);
    mesh.material = material;
    renderer.render(scene, view);
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);
    const start = performance.now();
    for (let i = 0; i < draws; i++) {
        renderer.render(scene, view);
        gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);
    }
    return (performance.now() - start) / draws;
}
