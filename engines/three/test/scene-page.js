// What engines/three/test/scene.mjs calls in the test page (page.html): the material in a
// three.js scene as a three.js user builds one (+y up, the bake's map as three's
// scene.environment and scene.background), beside three's own drawings of the same scene
// (window.renderScenes).
import * as THREE from 'three';
import { Accumulator, loadBake } from '../src/index.js';
import { floatTarget } from '../src/live.js';
import { drawFloats, pageRenderer } from './page-tools.js';

// Each scene drawn into a float target (linear radiance, no tone mapping), returned as RGB floats,
// rows from the top. The checks, each a pair (three.js alone and with the bake, or two ways):
// - background-N: three's scene.background from the map against the bake's createBackground,
//   under scene rotations N (none, then a turn about every axis);
// - mirror: a MeshStandardMaterial mirror ball lit by scene.environment against the bake's
//   material on the same sphere (the bake a near-mirror), seen from 30 degrees above;
// - scale: the bake's material (32 frames) on a sphere squashed by the mesh's scale (1, 0.4, 1)
//   and turned, against the same shape made in its geometry;
// - instances: an InstancedMesh of 100 against 100 meshes; skinning: a sphere skinned to a bone
//   against a mesh moved as the bone;
// - environment-turned: the bake's material under scene.environmentRotation (a turn about +y)
//   against the unturned scene seen by a camera turned back by as much;
// - morph: a sphere morphed into a squashed one (a morph target of influence 1) against the
//   squashed shape made in its geometry;
// - clipping: the material on a sphere with a clipping plane through its centre against the same
//   material on the sphere's lower half made in its geometry;
// - batched: a BatchedMesh of 9 spheres (two geometries) against 9 meshes; logarithmic-depth:
//   the bake's sphere cutting through one of three's, drawn by a renderer with a logarithmic
//   depth buffer against the same scene drawn by one without (the occlusion between the two);
// - live: the accumulator's mean of 8 calls against one draw of the same 8 frames, and its count
//   after the camera moved; with the split first frame, 9 calls against the split frame and the
//   8 weighted alike;
// - canvases: the mirror scene's bake drawn to the canvas under ACES filmic and no tone mapping
//   (8 bits; against three's formulas applied to pictures['mirror-bake'] by scene.mjs).
window.renderScenes = async ({ bake: url, width, height }) => {
    const s = await setUp(url, width, height);
    backgrounds(s);
    const mirrorScene = mirror(s);
    scale(s);
    instances(s);
    batched(s);
    logarithmicDepth(s);
    skinning(s);
    orthographic(s, mirrorScene);
    environmentTurned(s);
    morphTarget(s);
    clipping(s);
    const live = liveMode(s);
    const canvases = toneMapped(s, mirrorScene);
    const gl = s.renderer.getContext();
    const debug = gl.getExtension('WEBGL_debug_renderer_info');
    const result = {
        renderer: gl.getParameter(debug ? debug.UNMASKED_RENDERER_WEBGL : gl.RENDERER),
        exposureEv: s.bake.figures.exposure_ev,
        pictures: s.pictures,
        canvases,
        toneMappingExposure: TONE_MAPPING_EXPOSURE,
        live,
    };
    s.disposables.forEach((d) => d.dispose());
    s.bake.dispose();
    s.renderer.dispose();
    return result;
};

/** The exposure of the canvas drawings under three's tone mapping. */
const TONE_MAPPING_EXPOSURE = 1.7;

/**
 * What every check draws with: the renderer, the bake and its map, the sphere and the bake's
 * prefiltered material on brdf-preview's defaults and at 32 frames, `draw(name, scene, camera)` into
 * `pictures[name]`, a camera 3.2 away at an elevation, and what is disposed at the end.
 */
async function setUp(url, width, height) {
    const renderer = pageRenderer(width, height, { preserveDrawingBuffer: true });
    renderer.toneMapping = THREE.NoToneMapping;
    const bake = await loadBake(url);
    const map = bake.environmentTexture();
    const target = floatTarget(width, height);
    const sphere = new THREE.SphereGeometry(1, 128, 64);
    const material = bake.createMaterial({ mode: 'prefiltered' });
    // Four times brdf-preview's frames, for the checks that draw one shape made two ways (scale,
    // morph): the two drawings' normals differ by rounding, which moves their samples a little;
    // with less noise that moves the picture less.
    const converged = bake.createMaterial({ mode: 'prefiltered', frames: 32 });
    const disposables = [map, target, sphere, material, converged];
    const pictures = {};
    // RGBA values read back (rows from the bottom) as RGB, rows from the top, each divided by `d`.
    const topDownRgb = (values, d = 1) => {
        const rgb = new Array(3 * width * height);
        for (let y = 0; y < height; y++) {
            const row = height - 1 - y;
            for (let x = 0; x < width; x++) {
                for (let c = 0; c < 3; c++) rgb[3 * (y * width + x) + c] = values[4 * (row * width + x) + c] / d;
            }
        }
        return rgb;
    };
    const draw = (name, scene, camera) => {
        pictures[name] = topDownRgb(drawFloats(renderer, target, scene, camera));
    };
    const camera = (elevationDeg) => {
        const c = new THREE.PerspectiveCamera(45, width / height, 0.032, 320);
        const el = (elevationDeg * Math.PI) / 180;
        c.position.set(0, 3.2 * Math.sin(el), 3.2 * Math.cos(el));
        c.lookAt(0, 0, 0);
        c.updateMatrixWorld();
        return c;
    };
    return { renderer, bake, map, sphere, material, converged, disposables, pictures, draw, camera, topDownRgb, width, height };
}

/** three's scene.background against the bake's createBackground, unturned and turned. */
function backgrounds({ bake, map, disposables, draw, camera }) {
    const rotations = [new THREE.Euler(0, 0, 0), new THREE.Euler(0.3, 1.1, -0.4, 'YXZ')];
    rotations.forEach((rotation, i) => {
        const three = new THREE.Scene();
        three.background = map;
        three.backgroundRotation.copy(rotation);
        const ours = new THREE.Scene();
        ours.backgroundRotation.copy(rotation);
        const background = bake.createBackground();
        disposables.push(background.material);
        ours.add(background);
        draw(`background-${i}-three`, three, camera(10));
        draw(`background-${i}-bake`, ours, camera(10));
    });
}

/**
 * A MeshStandardMaterial mirror ball lit by scene.environment against the bake's material on the
 * same sphere, from 30 degrees above; returns the bake's scene.
 */
function mirror({ bake, map, sphere, material, disposables, draw, camera }) {
    const mirror = new THREE.MeshStandardMaterial({ color: 0xffffff, metalness: 1, roughness: 0 });
    disposables.push(mirror);
    const three = new THREE.Scene();
    three.environment = map;
    three.add(new THREE.Mesh(sphere, mirror));
    draw('mirror-three', three, camera(30));
    const ours = new THREE.Scene();
    ours.add(new THREE.Mesh(sphere, material));
    draw('mirror-bake', ours, camera(30));
    return ours;
}

/** A sphere squashed by its mesh's scale against the same shape made in its geometry. */
function scale({ sphere, converged, disposables, draw, camera }) {
    const turned = new THREE.Euler(0.4, 0.7, 0.2);
    const squashed = new THREE.Mesh(sphere, converged);
    squashed.scale.set(1, 0.4, 1);
    squashed.rotation.copy(turned);
    const byMesh = new THREE.Scene();
    byMesh.add(squashed);
    draw('scale-mesh', byMesh, camera(20));
    const shape = sphere.clone();
    squashed.updateMatrixWorld();
    shape.applyMatrix4(squashed.matrixWorld);
    disposables.push(shape);
    const byGeometry = new THREE.Scene();
    byGeometry.add(new THREE.Mesh(shape, converged));
    draw('scale-geometry', byGeometry, camera(20));
}

/**
 * `count` matrices on a grid of `columns` columns `spacing` apart around the origin, each turned
 * by the Euler angles `turn(col, row, i)` and scaled by `scale(col)`, and a scene of one mesh per
 * matrix (`geometryOf(i)`, `material`) placed by it: what instanced and batched meshes are drawn
 * against.
 */
function placed(count, columns, spacing, turn, scale, geometryOf, material) {
    const rows = count / columns;
    const separate = new THREE.Scene();
    const matrices = Array.from({ length: count }, (_, i) => {
        const [col, row] = [i % columns, Math.floor(i / columns)];
        const position = new THREE.Vector3(spacing * (col - (columns - 1) / 2), spacing * (row - (rows - 1) / 2), 0);
        const quaternion = new THREE.Quaternion().setFromEuler(new THREE.Euler(...turn(col, row, i)));
        const matrix = new THREE.Matrix4().compose(position, quaternion, new THREE.Vector3(...scale(col)));
        const mesh = new THREE.Mesh(geometryOf(i), material);
        matrix.decompose(mesh.position, mesh.quaternion, mesh.scale);
        separate.add(mesh);
        return matrix;
    });
    return { matrices, separate };
}

/**
 * A 10 x 10 InstancedMesh of small spheres, turned and scaled each its own way, against 100
 * meshes with the same matrices.
 */
function instances({ material, disposables, draw, camera }) {
    const small = new THREE.SphereGeometry(0.14, 32, 16);
    disposables.push(small);
    const instanced = new THREE.InstancedMesh(small, material, 100);
    const { matrices, separate } = placed(100, 10, 0.3, (col, row, i) => [0.3 * col, 0.2 * row, 0.1 * i], (col) => [1, 0.5 + 0.05 * col, 1], () => small, material);
    matrices.forEach((m, i) => instanced.setMatrixAt(i, m));
    const instances = new THREE.Scene();
    instances.add(instanced);
    draw('instances-instanced', instances, camera(0));
    draw('instances-separate', separate, camera(0));
    instanced.dispose();
}

/** A BatchedMesh of 9 spheres of two sizes, moved and turned, against 9 meshes with the same matrices. */
function batched({ material, disposables, draw, camera }) {
    const shapes = [new THREE.SphereGeometry(0.3, 48, 24), new THREE.SphereGeometry(0.2, 32, 16)];
    disposables.push(...shapes);
    const batch = new THREE.BatchedMesh(9, 2 * 48 * 24 * 4, 2 * 48 * 24 * 6, material);
    const ids = shapes.map((g) => batch.addGeometry(g));
    const { matrices, separate } = placed(9, 3, 0.75, (col, row, i) => [0.4 * col, 0.3 * row, 0.2 * i], () => [1, 1, 1], (i) => shapes[i % 2], material);
    matrices.forEach((m, i) => batch.setMatrixAt(batch.addInstance(ids[i % 2]), m));
    const batchedScene = new THREE.Scene();
    batchedScene.add(batch);
    draw('batched-batched', batchedScene, camera(10));
    draw('batched-separate', separate, camera(10));
    batch.dispose();
}

/**
 * The bake's sphere cutting through a MeshStandardMaterial sphere beside it (scene.environment
 * the map), drawn by a renderer with a logarithmic depth buffer (a second one of the page)
 * against the same scene drawn by the renderer without: where the two spheres meet, which covers
 * the other is the depth each material writes.
 */
function logarithmicDepth({ bake, map, sphere, material, disposables, pictures, draw, camera, topDownRgb, width, height }) {
    const scene = new THREE.Scene();
    scene.environment = map;
    const ours = new THREE.Mesh(sphere, material);
    ours.position.set(-0.45, 0, 0);
    const standard = new THREE.MeshStandardMaterial({ color: 0x808080, roughness: 0.4, metalness: 0.5 });
    const theirs = new THREE.Mesh(sphere, standard);
    theirs.position.set(0.45, 0, -0.2);
    scene.add(ours, theirs);
    disposables.push(standard);
    draw('logarithmic-depth-linear', scene, camera(10));
    const logarithmic = pageRenderer(width, height, { logarithmicDepthBuffer: true });
    logarithmic.toneMapping = THREE.NoToneMapping;
    const target = floatTarget(width, height);
    pictures['logarithmic-depth-logarithmic'] = topDownRgb(drawFloats(logarithmic, target, scene, camera(10)));
    target.dispose();
    logarithmic.dispose();
    void bake;
}

/** A sphere skinned to one bone, turned and moved, against a mesh moved as the bone. */
function skinning({ sphere, material, disposables, draw, camera }) {
    const skinned = sphere.clone();
    const count = skinned.attributes.position.count;
    skinned.setAttribute('skinIndex', new THREE.Uint16BufferAttribute(new Uint16Array(4 * count), 4));
    const weights = new Float32Array(4 * count);
    for (let i = 0; i < count; i++) weights[4 * i] = 1;
    skinned.setAttribute('skinWeight', new THREE.Float32BufferAttribute(weights, 4));
    disposables.push(skinned);
    const bone = new THREE.Bone();
    const body = new THREE.SkinnedMesh(skinned, material);
    body.add(bone);
    body.bind(new THREE.Skeleton([bone]));
    bone.position.set(0.2, -0.1, 0.1);
    bone.rotation.set(0.5, -0.8, 0.3);
    // A uniform scale: three's skinning turns normals by the skin matrix itself (for its own
    // materials too), right only where the bones scale evenly.
    bone.scale.setScalar(0.8);
    const skinScene = new THREE.Scene();
    skinScene.add(body);
    skinScene.updateMatrixWorld(true);
    draw('skinning-skinned', skinScene, camera(20));
    const moved = new THREE.Mesh(sphere, material);
    moved.position.copy(bone.position);
    moved.rotation.copy(bone.rotation);
    moved.scale.copy(bone.scale);
    const movedScene = new THREE.Scene();
    movedScene.add(moved);
    draw('skinning-moved', movedScene, camera(20));
    body.skeleton.dispose();
}

/**
 * An orthographic camera against a perspective one so far away that its rays are parallel
 * within 3e-4 radians (the same view: 2.4 units across, looking down 20 degrees), on `ours`.
 */
function orthographic({ draw }, ours) {
    const view = (c, distance) => {
        const el = (20 * Math.PI) / 180;
        c.position.set(0, distance * Math.sin(el), distance * Math.cos(el));
        c.lookAt(0, 0, 0);
        c.updateMatrixWorld();
        return c;
    };
    const orthographic = view(new THREE.OrthographicCamera(-1.2, 1.2, 1.2, -1.2, 1, 10), 5);
    const far = 4000;
    const distant = view(new THREE.PerspectiveCamera((2 * Math.atan(1.2 / far) * 180) / Math.PI, 1, far - 2, far + 2), far);
    draw('orthographic-orthographic', ours, orthographic);
    draw('orthographic-distant', ours, distant);
}

/**
 * scene.environmentRotation turns the environment the material reads as three turns its own: a
 * turn of the environment by `angle` about +y is the unturned environment seen by a camera turned
 * by `-angle` (three reads a turned map along the inverse turn of each direction). The angle is a
 * whole number of the sphere's 128 segments, so that the turned view sees the same triangles and
 * every pixel the same normal and samples; the scene has no background.
 */
function environmentTurned({ sphere, material, draw, camera }) {
    const angle = (22 * 2 * Math.PI) / 128;
    const turned = new THREE.Scene();
    turned.environmentRotation.set(0, angle, 0);
    turned.add(new THREE.Mesh(sphere, material));
    const plain = new THREE.Scene();
    plain.add(new THREE.Mesh(sphere, material));
    const back = camera(30);
    back.position.applyMatrix4(new THREE.Matrix4().makeRotationY(-angle));
    back.lookAt(0, 0, 0);
    back.updateMatrixWorld();
    draw('environment-turned-scene', turned, camera(30));
    draw('environment-turned-camera', plain, back);
}

/**
 * A sphere with a morph target, the same sphere squashed to (1, 0.4, 1), at influence 1 (three
 * then draws the target's positions and normals), against the squashed shape made in its
 * geometry: three's morph chunks in the material's vertex shader.
 */
function morphTarget({ sphere, converged, disposables, draw, camera }) {
    const squashed = sphere.clone().applyMatrix4(new THREE.Matrix4().makeScale(1, 0.4, 1));
    const morphed = sphere.clone();
    morphed.morphAttributes.position = [squashed.getAttribute('position')];
    morphed.morphAttributes.normal = [squashed.getAttribute('normal')];
    disposables.push(squashed, morphed);
    const mesh = new THREE.Mesh(morphed, converged);
    mesh.morphTargetInfluences[0] = 1;
    const byMorph = new THREE.Scene();
    byMorph.add(mesh);
    draw('morph-morphed', byMorph, camera(20));
    const byGeometry = new THREE.Scene();
    byGeometry.add(new THREE.Mesh(squashed, converged));
    draw('morph-geometry', byGeometry, camera(20));
}

/**
 * The material on the sphere with a clipping plane through its centre that keeps the lower half
 * (renderer.localClippingEnabled), from 30 degrees above, against the same material on the
 * sphere's lower half made in its geometry (the sphere's rows end at the equator, so the two hold
 * the same triangles below it; the bowl's inside shows in both).
 */
function clipping({ renderer, bake, sphere, material, disposables, draw, camera }) {
    const clipped = bake.createMaterial({ mode: 'prefiltered' });
    clipped.clippingPlanes = [new THREE.Plane(new THREE.Vector3(0, -1, 0), 0)];
    const bowl = new THREE.SphereGeometry(1, 128, 32, 0, 2 * Math.PI, Math.PI / 2, Math.PI / 2);
    disposables.push(clipped, bowl);
    const cut = new THREE.Scene();
    cut.add(new THREE.Mesh(sphere, clipped));
    renderer.localClippingEnabled = true;
    draw('clipping-plane', cut, camera(30));
    renderer.localClippingEnabled = false;
    const half = new THREE.Scene();
    half.add(new THREE.Mesh(bowl, material));
    draw('clipping-geometry', half, camera(30));
}

/**
 * The live mode. Without the split first frame (splitWeight 0): eight calls of the accumulator,
 * one frame each, against one draw of the same eight frames; then the camera moves and the
 * average starts again. With it (the default): nine calls, the first the split estimator's frame
 * counted splitWeight (4) times, against that frame and the eight drawn apart, weighted as the
 * accumulator weighs them. Returns its frame counts and weights.
 */
function liveMode({ renderer, bake, sphere, disposables, pictures, draw, camera, topDownRgb, width, height }) {
    const live = new Accumulator(renderer, { splitWeight: 0 });
    const liveScene = new THREE.Scene();
    const liveMaterial = bake.createMaterial({ mode: 'prefiltered', frames: 8 });
    disposables.push(liveMaterial, live);
    liveScene.add(new THREE.Mesh(sphere, liveMaterial));
    const accumulate = (accumulator, calls) => {
        renderer.setRenderTarget(null);
        for (let i = 0; i < calls; i++) accumulator.render(liveScene, camera(30));
        const sum = new Float32Array(4 * width * height);
        renderer.readRenderTargetPixels(accumulator.sum, 0, 0, width, height, sum);
        return topDownRgb(sum, accumulator.weight);
    };
    pictures['live-accumulated'] = accumulate(live, 8);
    const liveFrames = live.frames;
    const drawnScene = new THREE.Scene();
    const drawnMaterial = bake.createMaterial({ mode: 'prefiltered', frames: 8 });
    disposables.push(drawnMaterial);
    drawnScene.add(new THREE.Mesh(sphere, drawnMaterial));
    draw('live-drawn', drawnScene, camera(30));
    renderer.setRenderTarget(null);
    live.render(liveScene, camera(31));
    const liveRestart = live.frames;

    const split = new Accumulator(renderer);
    disposables.push(split);
    pictures['live-split-accumulated'] = accumulate(split, 9);
    const splitScene = new THREE.Scene();
    const splitMaterial = bake.createMaterial({ mode: 'split' });
    disposables.push(splitMaterial);
    splitScene.add(new THREE.Mesh(sphere, splitMaterial));
    draw('live-split-frame', splitScene, camera(30));
    const w = split.splitWeight;
    pictures['live-split-expected'] = pictures['live-split-frame'].map((v, i) => (w * v + 8 * pictures['live-drawn'][i]) / (w + 8));
    return { frames: liveFrames, framesAfterMoving: liveRestart, splitFrames: split.frames, splitWeight: split.weight };
}

/**
 * three's colour pipeline: `ours` drawn to the canvas under ACES filmic tone mapping (and none),
 * 8 bits as three writes them, beside its linear radiance on the float target.
 */
function toneMapped({ renderer, camera, topDownRgb, width, height }, ours) {
    const canvases = {};
    const drawCanvas = (name, toneMapping) => {
        renderer.setRenderTarget(null);
        renderer.toneMapping = toneMapping;
        renderer.toneMappingExposure = TONE_MAPPING_EXPOSURE;
        renderer.render(ours, camera(30));
        const pixels = new Uint8Array(4 * width * height);
        gl.readPixels(0, 0, width, height, gl.RGBA, gl.UNSIGNED_BYTE, pixels);
        canvases[name] = topDownRgb(pixels);
    };
    const gl = renderer.getContext();
    drawCanvas('aces', THREE.ACESFilmicToneMapping);
    drawCanvas('none', THREE.NoToneMapping);
    return canvases;
}
