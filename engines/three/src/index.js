// A bake of the BRDF toolchain (`brdf-bake --engine-textures`) as three.js materials: the
// reference and prefiltered estimators of `brdf-preview`, with the same samples and the same
// per-pixel sample choice, in GLSL ES 3.0 (`shade.glsl.js`) on three's shader chunks, in three's
// world and colour pipeline (or brdf-preview's: ORIENTATIONS, OUTPUTS). The engine textures are
// described in `data-schema/engine-textures.md`; this file reads them and sets the shader's
// inputs.
//
//     import { loadBake } from '@brdf-toolchain/three';
//     const bake = await loadBake('bakes/gold-paint/');
//     const mesh = new THREE.Mesh(new THREE.TorusKnotGeometry(), bake.createMaterial({ mode: 'prefiltered' }));
//     scene.add(bake.createBackground(), mesh);

import * as THREE from 'three';

import { floatTarget } from './live.js';
import { BakeError, readBake } from './loader.js';
import { AZIMUTH_STEPS, ANGLE_STEPS, MAX_PEAK_LIGHTS, effectiveExponents, lightCorrections, lobeMixture, mixtureKernels, mixtureRows, peakLights, splitLayers, texelSpread } from './split.js';

import {
    BACKGROUND_FRAGMENT,
    BACKGROUND_VERTEX,
    GBUFFER_FRAGMENT,
    GBUFFER_VERTEX,
    QUAD_VERTEX,
    SURFACE_FRAGMENT,
    SURFACE_VERTEX,
} from './shade.glsl.js';

export { Accumulator, SPLIT_WEIGHT } from './live.js';
export { BakeError, FLOAT32_MAX, MANIFEST_LIMIT, OUTPUT_LIMIT, STAGE, checkFigures, dataTexture, readBake, resolveInside, sha256Hex } from './loader.js';

/**
 * The estimators, by their names in `brdf-preview --mode`, and their codes in the shader (uMode);
 * and this engine's own, 'split' (split.js: no samples, biased, the live mode's first frame),
 * which is a program of its own (the define SPLIT) and reads no uMode.
 */
export const MODES = { reference: 0, prefiltered: 2, split: 3 };

/**
 * How the world's axes meet the environment map's. `three`: three.js's (+y up; the map read as
 * `equirectUv` reads it for `scene.environment` and `scene.background`, after the scene's
 * `environmentRotation` or `backgroundRotation`), so that the same HDR lights the bake and three's
 * own materials alike. `brdf-preview`: brdf-preview's (+z up, `phi` from +x towards +y; what
 * `orbitCamera` and `previewSphere` assume), where the pictures equal brdf-preview's.
 */
export const ORIENTATIONS = ['three', 'brdf-preview'];

/**
 * What a pixel writes. `three`: the linear radiance (times 2^exposureEv), which the renderer's
 * tone mapping (`renderer.toneMapping`, `toneMappingExposure`) and output colour space take as
 * for its own materials where it draws to the canvas (on a render target: linear, as three's
 * own). `brdf-preview`: brdf-preview's picture (the environment's automatic exposure or
 * exposureEv, Reinhard per channel, sRGB), nothing of three's added.
 */
export const OUTPUTS = ['three', 'brdf-preview'];

/**
 * Reads the bake at `url` (a folder served over HTTP, with or without the trailing `/`) with the
 * checks of `readBake` (loader.js): the manifest, the engine textures' figures and every engine
 * texture by role. `options.fetch` replaces the page's fetch.
 */
export async function loadBake(url, options = {}) {
    const { manifest, figures, textures } = await readBake(url, options);
    return new Bake(manifest, figures, textures);
}

/** A loaded bake: its manifest, the engine textures' figures and the textures. */
export class Bake {
    constructor(manifest, figures, textures) {
        this.manifest = manifest;
        this.figures = figures;
        this.textures = textures;
    }

    /** brdf-preview's defaults for `mode`: `{ spp, frames }` (render::Settings::previewer). */
    defaults(mode) {
        const d = this.figures.previewer?.[mode];
        if (!d) {
            throw new BakeError(`error: the bake's engine textures have no defaults for mode ${mode}`);
        }
        return d;
    }

    /**
     * A material that shades a mesh with the bake's `mode` ('reference' or 'prefiltered'): per
     * pixel, frames `firstFrame .. firstFrame + frames` of `spp` samples each, their sum divided
     * by `divisor` (default `frames`: their average). `spp` and `frames` default to
     * brdf-preview's; `seed` is brdf-preview's --seed. The pixel index (which samples a pixel
     * takes) counts rows from the top of the drawing buffer, whose size the material reads from
     * the renderer at each draw. Built on three's shader chunks: instanced, batched, skinned and
     * morphed meshes, clipping planes and a logarithmic depth buffer work as with three's own
     * materials. `orientation` (ORIENTATIONS) and `output` (OUTPUTS) say how it meets the scene;
     * `exposureEv` scales the radiance by 2^EV (default: none in three's output, the environment's
     * automatic exposure in brdf-preview's).
     */
    createMaterial(options = {}) {
        const material = this.shaderMaterial(options, {
            name: `brdf-bake ${options.mode ?? 'reference'}`,
            defines: this.defines(options.mode),
            vertexShader: SURFACE_VERTEX,
            fragmentShader: SURFACE_FRAGMENT,
            // render::raster culls no back face: at a silhouette a pixel may see one.
            side: THREE.DoubleSide,
            clipping: true,
            uniforms: this.shadingUniforms(options),
        });
        // What the live mode (Accumulator) looks for, and the frame it counts from.
        material.userData.brdfBake = { firstFrame: options.firstFrame ?? 0, mode: options.mode ?? 'reference' };
        material.onBeforeRender = (renderer, scene) => {
            const u = material.uniforms;
            this.bindSplit(material);
            resolution(renderer, u.uResolution.value);
            if (material.defines.TURNED) envFromWorld(scene.environmentRotation, u.uEnvFromWorld.value);
        };
        return material;
    }

    /**
     * The material's estimators as a full-screen pass over a G-buffer (`exactCoverage`): what a
     * pixel covers is read from `gbuffer` rather than rasterized at the pixel, and uncovered
     * pixels show the environment. `options` as for `createMaterial`.
     */
    createDeferred(gbuffer, options = {}) {
        const material = this.shaderMaterial(options, {
            name: `brdf-bake ${options.mode ?? 'reference'} (deferred)`,
            defines: { DEFERRED: 1, ...this.defines(options.mode) },
            vertexShader: QUAD_VERTEX,
            fragmentShader: SURFACE_FRAGMENT,
            depthTest: false,
            depthWrite: false,
            uniforms: {
                ...this.shadingUniforms(options),
                uGPosition: { value: gbuffer.target.textures[0] },
                uGNormal: { value: gbuffer.target.textures[1] },
                uGScale: { value: gbuffer.scale },
            },
        });
        // Its defines stay as made (the live mode draws createMaterial's materials only).
        this.bindSplit(material);
        return fullScreen(material, 'environmentRotation');
    }

    shadingUniforms({ mode = 'reference', spp, frames, firstFrame = 0, divisor, seed = 0 }) {
        if (!(mode in MODES)) {
            throw new BakeError(`error: unknown mode ${mode}: ${Object.keys(MODES).join(', ')}`);
        }
        const f = this.figures;
        // The split estimator takes no samples: the sampled estimators' settings stay valid.
        const defaults = this.defaults(mode === 'split' ? 'prefiltered' : mode);
        spp = spp ?? defaults.spp;
        frames = frames ?? defaults.frames;
        if (!(spp > 0 && (spp & (spp - 1)) === 0 && f.samples % spp === 0)) {
            throw new BakeError(`error: spp ${spp} must be a power of two dividing the bake's ${f.samples} samples`);
        }
        return {
            ...this.textureUniforms(),
            uPhiDRange: { value: f.phi_d_range },
            uMode: { value: MODES[mode] },
            uSeed: { value: seed >>> 0 },
            uSpp: { value: spp },
            uSlices: { value: f.slices },
            uVectors: { value: f.vectors },
            uSamples: { value: f.samples },
            uRows: { value: f.rows },
            uSectors: { value: f.sectors },
            uPeaks: { value: Boolean(f.peaks) },
            uDiffuse: { value: new THREE.Vector3(...f.diffuse) },
            uFirstFrame: { value: firstFrame },
            uFrameCount: { value: frames },
            uDivisor: { value: divisor ?? frames },
            uFilterSamples: { value: spp * frames },
            uLayerExponents: { value: layerExponents(f.exponents) },
            // The split estimator's, set by bindSplit where SPLIT is drawn.
            uLobes: { value: null },
            uLayersLinear: { value: null },
            uCorrections: { value: null },
            uPeakCount: { value: 0 },
            uPeakDirections: { value: new Float32Array(3 * MAX_PEAK_LIGHTS) },
            uPeakPowers: { value: new Float32Array(3 * MAX_PEAK_LIGHTS) },
            uPeakNear: { value: new Float32Array(2 * MAX_PEAK_LIGHTS) },
            ...rayUniforms(),
        };
    }

    /**
     * A material's defines for `mode`: SPLIT for the split estimator, and in every material
     * MIX_LAYERS, the split estimator's layers and level 0 (the live mode defines SPLIT on a
     * sampled material for its first frame).
     */
    defines(mode) {
        return { MIX_LAYERS: this.figures.exponents.length + 1, ...(mode === 'split' && { SPLIT: 1 }) };
    }

    /**
     * `material`'s split uniforms from splitInputs, before a draw with SPLIT defined (made with
     * mode 'split', or the live mode's first frame): the inputs are derived at the first such
     * draw, not for bakes that never draw one.
     */
    bindSplit(material) {
        const u = material.uniforms;
        if (!material.defines.SPLIT || u.uLobes.value) return;
        const split = this.splitInputs();
        u.uLobes.value = split.lobes;
        u.uLayersLinear.value = split.layers;
        u.uCorrections.value = split.corrections;
        u.uPeakCount.value = split.count;
        u.uPeakDirections.value = split.directions;
        u.uPeakPowers.value = split.powers;
        u.uPeakNear.value = split.near;
    }

    /**
     * The split estimator's inputs (split.js), derived once: the lobe mixture (`lobes`), the peak
     * lights' corrections (`corrections`) and the whole environment's layers with level 0
     * (`layers`), the three textures disposed with the bake, and the peak lights (`count`,
     * `directions`, `powers`, `near`).
     */
    splitInputs() {
        if (!this.split) {
            const f = this.figures;
            const layers = this.textures.uFullLayers.image;
            const exponents = effectiveExponents(layerExponents(f.exponents).slice(0, f.exponents.length + 1), texelSpread(layers.height));
            const merl = this.textures.uMerl.image.data;
            const table = lobeMixture(merl, f.merl_size, f.phi_d_range, f.diffuse, f.view_rows, exponents);
            const lobes = new THREE.DataTexture(table, f.view_rows, mixtureRows(exponents.length), THREE.RGBAFormat, THREE.FloatType);
            // Linear along the views (u = 1 - cos_o: the rows' centres at (r + 1/2) / rows), each
            // row of the texture read at its centre.
            lobes.minFilter = THREE.LinearFilter;
            lobes.magFilter = THREE.LinearFilter;
            lobes.needsUpdate = true;
            // The peak lights' corrections per angle, azimuth and view, linear in all three.
            const kernels = mixtureKernels(table, f.view_rows, exponents);
            const values = lightCorrections(merl, f.merl_size, f.phi_d_range, f.diffuse, f.view_rows, table, kernels);
            const corrections = new THREE.Data3DTexture(values, ANGLE_STEPS, AZIMUTH_STEPS, f.view_rows);
            corrections.format = THREE.RGBAFormat;
            corrections.type = THREE.FloatType;
            corrections.minFilter = THREE.LinearFilter;
            corrections.magFilter = THREE.LinearFilter;
            corrections.unpackAlignment = 4;
            corrections.needsUpdate = true;
            // The whole environment's layers with its level 0 as one more layer (splitLayers),
            // filtered by the GPU: one bilinear read where env_bilinear makes four fetches, and no
            // branch between the layers and level 0. Float32 filtering is WebGL 2's
            // OES_texture_float_linear.
            const environment = this.textures.uEnvironment.image;
            const [width, height] = [environment.width, environment.height];
            const extended = splitLayers(layers.data, layers.width, layers.height, layers.depth, environment.data, width, height);
            const linear = new THREE.DataArrayTexture(extended, layers.width, layers.height, layers.depth + 1);
            linear.format = THREE.RGBAFormat;
            linear.type = THREE.FloatType;
            linear.minFilter = THREE.LinearFilter;
            linear.magFilter = THREE.LinearFilter;
            linear.wrapS = THREE.RepeatWrapping;
            linear.wrapT = THREE.ClampToEdgeWrapping;
            linear.generateMipmaps = false;
            linear.flipY = false;
            linear.needsUpdate = true;
            const none = {
                count: 0,
                directions: new Float32Array(3 * MAX_PEAK_LIGHTS),
                powers: new Float32Array(3 * MAX_PEAK_LIGHTS),
                near: new Float32Array(2 * MAX_PEAK_LIGHTS),
            };
            const peaks = environment.data.subarray(4 * width * height, 8 * width * height);
            this.split = { lobes, corrections, layers: linear, ...(f.peaks ? peakLights(peaks, width, height) : none) };
        }
        return this.split;
    }

    /**
     * The environment behind everything: level 0 along each pixel's camera ray
     * (render::Camera::ray), turned and written as the material is (`orientation`, `output`,
     * `exposureEv`; in three's orientation after the scene's `backgroundRotation`). A full-screen
     * quad drawn first, not tested against or written to depth.
     */
    createBackground(options = {}) {
        const material = this.shaderMaterial(options, {
            name: 'brdf-bake background',
            vertexShader: BACKGROUND_VERTEX,
            fragmentShader: BACKGROUND_FRAGMENT,
            depthTest: false,
            depthWrite: false,
            uniforms: { uEnvironment: { value: this.textures.uEnvironment }, ...rayUniforms() },
        });
        const mesh = fullScreen(material, 'backgroundRotation');
        mesh.renderOrder = -Infinity;
        return mesh;
    }

    /**
     * A THREE.ShaderMaterial (GLSL ES 3.0) of `params` drawing in `orientation` and writing
     * `output`: their defines, the exposure and the environment's frame as uniforms.
     */
    shaderMaterial({ orientation = 'three', output = 'three', exposureEv }, params) {
        if (!ORIENTATIONS.includes(orientation)) {
            throw new BakeError(`error: unknown orientation ${orientation}: ${ORIENTATIONS.join(' or ')}`);
        }
        if (!OUTPUTS.includes(output)) {
            throw new BakeError(`error: unknown output ${output}: ${OUTPUTS.join(' or ')}`);
        }
        const preview = output === 'brdf-preview';
        return new THREE.ShaderMaterial({
            glslVersion: THREE.GLSL3,
            ...params,
            defines: { ...params.defines, ...(orientation === 'three' && { TURNED: 1 }), ...(preview && { PREVIEW_OUTPUT: 1 }) },
            // brdf-preview's output maps its own tones; three's goes through the renderer's.
            toneMapped: !preview,
            uniforms: {
                ...params.uniforms,
                uExposure: { value: 2 ** (exposureEv ?? (preview ? this.figures.exposure_ev : 0)) },
                uEnvFromWorld: { value: new THREE.Matrix3() },
            },
        });
    }

    /**
     * The bake's environment (level 0 of engine-environment.ktx2) as the equirectangular texture
     * a three.js user loads from the HDR for `scene.environment` or `scene.background`: rows from
     * the bottom (three's v runs up), linear, filtered; what the material's default orientation
     * lines up with. The caller disposes it.
     */
    environmentTexture() {
        const image = this.textures.uEnvironment.image;
        const { width, height } = image;
        const rowLength = 4 * width;
        const data = new Float32Array(rowLength * height);
        for (let y = 0; y < height; y++) {
            data.set(image.data.subarray(y * rowLength, (y + 1) * rowLength), (height - 1 - y) * rowLength);
        }
        const texture = new THREE.DataTexture(data, width, height, THREE.RGBAFormat, THREE.FloatType);
        texture.mapping = THREE.EquirectangularReflectionMapping;
        texture.colorSpace = THREE.LinearSRGBColorSpace;
        texture.minFilter = THREE.LinearFilter;
        texture.magFilter = THREE.LinearFilter;
        texture.needsUpdate = true;
        return texture;
    }

    textureUniforms() {
        return Object.fromEntries(Object.entries(this.textures).map(([name, texture]) => [name, { value: texture }]));
    }

    dispose() {
        Object.values(this.textures).forEach((t) => t.dispose());
        this.split?.lobes.dispose();
        this.split?.corrections.dispose();
        this.split?.layers.dispose();
    }
}

// three's world (+y up) into brdf-preview's environment frame (+z up): the direction whose
// equirectUv is the texel env_uv finds. equirectUv reads u = atan(d.z, d.x) / 2 pi + 1/2 and
// v from asin(d.y) with the top row up; env_uv reads u = atan(e.y, e.x) / 2 pi from +x towards
// +y and theta from +z, the top row up. So e = (-d.x, -d.z, d.y): a turn and a mirror (the two
// run phi opposite ways around the up axis). A MERL table is isotropic, so the material's
// reflection in a mirror is the material itself: only the environment is turned.
const THREE_TO_ENV = new THREE.Matrix3().set(-1, 0, 0, 0, 0, -1, 0, 1, 0);
const rotation4 = new THREE.Matrix4();
const rotation3 = new THREE.Matrix3();
const turn = new THREE.Euler();

/**
 * `out` set to the environment frame from three's world under `euler` (a scene's
 * environmentRotation or backgroundRotation), as three's renderer turns the directions it looks
 * up in an equirect map or a PMREM (WebGLMaterials, WebGLBackground: by the rotation's inverse,
 * its transpose).
 */
function envFromWorld(euler, out) {
    turn.copy(euler ?? IDENTITY_TURN);
    rotation3.setFromMatrix4(rotation4.makeRotationFromEuler(turn)).transpose();
    return out.copy(THREE_TO_ENV).multiply(rotation3);
}

const IDENTITY_TURN = new THREE.Euler();

/**
 * A full-screen quad drawing `material` (the background or the deferred pass): at each draw, the
 * image size and the pixel rays from the camera, and in three's orientation the environment frame
 * from the scene's `rotation` (its name on THREE.Scene).
 */
function fullScreen(material, rotation) {
    const mesh = new THREE.Mesh(QUAD, material);
    mesh.frustumCulled = false;
    mesh.onBeforeRender = (renderer, scene, camera) => {
        setRay(material.uniforms, renderer, camera);
        if (material.defines.TURNED) envFromWorld(scene[rotation], material.uniforms.uEnvFromWorld.value);
    };
    return mesh;
}

/** The full-screen quad's geometry, shared by every background and deferred pass (never disposed). */
const QUAD = new THREE.PlaneGeometry(2, 2);

// uLayerExponents: the layers' exponents, then render::past_exponent (the last one's times the
// last step's ratio, 4 times it for a single layer), padded to MAX_LAYERS + 1 (65).
function layerExponents(exponents) {
    const n = exponents.length;
    const step = n >= 2 ? exponents[n - 1] / exponents[n - 2] : 4;
    const values = new Float32Array(65);
    values.set(exponents);
    values[n] = exponents[n - 1] * step;
    return values;
}

function rayUniforms() {
    return {
        uResolution: { value: new THREE.Vector2(1, 1) },
        uRayForward: { value: new THREE.Vector3() },
        uRayRight: { value: new THREE.Vector3() },
        uRayUp: { value: new THREE.Vector3() },
    };
}

// The image size and the pixel rays' basis (render::Camera::ray) for the draw about to run, from
// the camera's projection, so that zoom, a view offset and an orthographic camera (whose rays are
// parallel: no change across the image) are drawn as three draws them: the rays through the image's
// centre and through the middle of its right and top edges, in view space at z = -1, turned to
// the world.
function setRay(u, renderer, camera) {
    resolution(renderer, u.uResolution.value);
    const toWorld = worldTurn.setFromMatrix4(camera.matrixWorld);
    const at = (x, y, out) => {
        out.set(x, y, 0.5).applyMatrix4(camera.projectionMatrixInverse);
        return camera.isOrthographicCamera ? out.set(0, 0, -1) : out.divideScalar(-out.z);
    };
    at(0, 0, u.uRayForward.value);
    at(1, 0, u.uRayRight.value).sub(u.uRayForward.value).applyMatrix3(toWorld);
    at(0, 1, u.uRayUp.value).sub(u.uRayForward.value).applyMatrix3(toWorld);
    u.uRayForward.value.applyMatrix3(toWorld);
}

const worldTurn = new THREE.Matrix3();

/**
 * The G-buffer of `geometry` seen by `camera` at `width x height` with brdf-preview's coverage:
 * render::raster snaps vertices to 1/256 pixel, as lavapipe does, where a WebGL implementation
 * may snap coarser (SwiftShader: 1/16), and a pixel whose centre lies that close to a silhouette
 * edge would be covered by one renderer only. So the mesh is drawn at `scale` (16) times the size,
 * shifted by half a pixel of that size so that texel `(S x + S / 2, S y + S / 2)` is centred on
 * pixel `(x, y)`'s centre: its coverage is that of the pixel centre with vertices on a grid of
 * 1 / (16 S) pixel. Only those texels are written (position, and normal with w = 1), into two
 * float textures of `S width x S height` (128 MB for 128 x 128): for tests and stills, not for
 * frames. `createDeferred` shades from it.
 */
export function exactCoverage(renderer, geometry, camera, width, height, scale = 16) {
    const target = floatTarget(scale * width, scale * height, 2);
    const material = new THREE.RawShaderMaterial({
        name: 'brdf-bake g-buffer',
        glslVersion: THREE.GLSL3,
        vertexShader: GBUFFER_VERTEX,
        fragmentShader: GBUFFER_FRAGMENT,
        side: THREE.DoubleSide,
        uniforms: { uGScale: { value: scale } },
    });
    const scene = new THREE.Scene();
    scene.add(new THREE.Mesh(geometry, material));
    const shifted = camera.clone();
    // Half a texel right and up: three's view offset moves the frustum, so the picture moves the
    // other way (x from the left, y from the top).
    shifted.setViewOffset(scale * width, scale * height, -0.5, 0.5, scale * width, scale * height);
    const previous = { target: renderer.getRenderTarget(), color: renderer.getClearColor(new THREE.Color()), alpha: renderer.getClearAlpha() };
    renderer.setRenderTarget(target);
    renderer.setClearColor(0x000000, 0);
    renderer.clear();
    renderer.render(scene, shifted);
    renderer.setRenderTarget(previous.target);
    renderer.setClearColor(previous.color, previous.alpha);
    material.dispose();
    return { target, scale };
}

function resolution(renderer, target) {
    const rt = renderer.getRenderTarget();
    if (rt) {
        target.set(rt.width, rt.height);
    } else {
        renderer.getDrawingBufferSize(target);
    }
}

/**
 * The sphere brdf-preview draws by default (render::Mesh::sphere(1, 128, 64)): a UV sphere around
 * the z axis, one vertex at each pole, normals exactly radial, the same vertices and triangles in
 * the same order.
 */
export function previewSphere(radius = 1, segments = 128, rings = 64) {
    const positions = [];
    const normals = [];
    const push = (n) => {
        normals.push(...n);
        positions.push(...n.map((c) => c * radius));
    };
    push([0, 0, 1]);
    for (let i = 1; i < rings; i++) {
        const theta = (Math.PI * i) / rings;
        for (let j = 0; j < segments; j++) {
            const phi = (2 * Math.PI * j) / segments;
            push([Math.sin(theta) * Math.cos(phi), Math.sin(theta) * Math.sin(phi), Math.cos(theta)]);
        }
    }
    push([0, 0, -1]);
    const south = positions.length / 3 - 1;
    const ring = (i, j) => 1 + (i - 1) * segments + (j % segments);
    const indices = [];
    for (let j = 0; j < segments; j++) indices.push(0, ring(1, j), ring(1, j + 1));
    for (let i = 1; i < rings - 1; i++) {
        for (let j = 0; j < segments; j++) {
            const [a, b, c, d] = [ring(i, j), ring(i + 1, j), ring(i + 1, j + 1), ring(i, j + 1)];
            indices.push(a, b, c, a, c, d);
        }
    }
    for (let j = 0; j < segments; j++) indices.push(ring(rings - 1, j), south, ring(rings - 1, j + 1));
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.Float32BufferAttribute(positions, 3));
    geometry.setAttribute('normal', new THREE.Float32BufferAttribute(normals, 3));
    geometry.setIndex(indices);
    return geometry;
}

/**
 * brdf-preview's camera (render::Camera::orbit with the default target, distance and field of
 * view): at `azimuthDeg`, `elevationDeg` (brdf-preview --camera AZ,EL) around the origin, +z up,
 * 45 degrees vertical field of view, near and far planes at 1% and 100 times the distance.
 */
export function orbitCamera(aspect, azimuthDeg = 0, elevationDeg = 0, distance = 3.2) {
    const camera = new THREE.PerspectiveCamera(45, aspect, distance * 0.01, distance * 100);
    setOrbit(camera, azimuthDeg, elevationDeg, distance);
    return camera;
}

/** Moves `camera` to azimuth and elevation (degrees) at `distance` from the origin, +z up. */
export function setOrbit(camera, azimuthDeg, elevationDeg, distance = 3.2) {
    const max = Math.PI / 2 - 1e-3;
    const el = Math.min(Math.max((elevationDeg * Math.PI) / 180, -max), max);
    const az = (azimuthDeg * Math.PI) / 180;
    camera.up.set(0, 0, 1);
    camera.position.set(
        distance * Math.cos(el) * Math.cos(az),
        distance * Math.cos(el) * Math.sin(az),
        distance * Math.sin(el),
    );
    camera.lookAt(0, 0, 0);
    camera.updateMatrixWorld();
}
