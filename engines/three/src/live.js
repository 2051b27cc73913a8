// The live mode: a render-loop helper that draws a scene once per call and averages the calls
// while nothing moves, so that a bake's material shows a usable picture at once (the split
// estimator's frame: no samples, no noise) and converges while the view is still (frames of its
// spp averaged in); anything that moves starts the average again.

import * as THREE from 'three';

import { QUAD_VERTEX } from './shade.glsl.js';


// The running sum: the previous sum (none for the first frame) plus this frame times its weight,
// texel by texel.
const ADD_FRAGMENT = /* glsl */ `
uniform sampler2D uSum;
uniform sampler2D uFrame;
uniform bool uFirst;
uniform float uWeight;
layout(location = 0) out highp vec4 pc_fragColor;
void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    pc_fragColor = (uFirst ? vec4(0.0) : texelFetch(uSum, p, 0)) + uWeight * texelFetch(uFrame, p, 0);
}
`;

// The mean, through three's tone mapping and output colour space (the renderer's, as for its own
// materials on the canvas).
const SHOW_FRAGMENT = /* glsl */ `
uniform sampler2D uSum;
uniform float uCount;
layout(location = 0) out highp vec4 pc_fragColor;
#define gl_FragColor pc_fragColor
void main() {
    gl_FragColor = texelFetch(uSum, ivec2(gl_FragCoord.xy), 0) / uCount;
    #include <tonemapping_fragment>
    #include <colorspace_fragment>
}
`;

/** A float RGBA render target read texel by texel (nearest, no mipmaps), with `count` textures. */
export function floatTarget(width, height, count = 1) {
    return new THREE.WebGLRenderTarget(width, height, {
        count,
        type: THREE.FloatType,
        format: THREE.RGBAFormat,
        depthBuffer: true,
        minFilter: THREE.NearestFilter,
        magFilter: THREE.NearestFilter,
        generateMipmaps: false,
    });
}

function pass(fragmentShader, uniforms, toneMapped) {
    const material = new THREE.ShaderMaterial({
        glslVersion: THREE.GLSL3,
        vertexShader: QUAD_VERTEX,
        fragmentShader,
        uniforms,
        depthTest: false,
        depthWrite: false,
        toneMapped,
    });
    const scene = new THREE.Scene();
    const mesh = new THREE.Mesh(new THREE.PlaneGeometry(2, 2), material);
    mesh.frustumCulled = false;
    scene.add(mesh);
    return { scene, material, geometry: mesh.geometry };
}

/**
 * How many sampled frames the live mode's split frame counts as by default: the bias it leaves
 * after n sampled frames is 4 / (4 + n) of its own.
 */
export const SPLIT_WEIGHT = 4;

/**
 * Averages the frames of a scene while it stays still. Each `render(scene, camera)` draws the
 * scene once into a float target, with every bake material (`Bake.createMaterial` in three's
 * output, whose radiance is linear; the accumulator takes over its frames) drawing its next
 * frame, adds it to the running sum and shows the mean on the canvas through the renderer's tone
 * mapping and output colour space. A bake material's first frame is the split estimator's (no
 * samples: a picture without noise at 2.2 to 2.8 times the cost of a MeshStandardMaterial frame
 * on SwiftShader, biased; split.js), counted as `splitWeight` frames; each frame after it draws the next frame of
 * the material's samples (frame `firstFrame + n - 1` of its spp, `n` the frames drawn so far), so
 * the split's bias fades as `splitWeight / (splitWeight + n - 1)` and the mean converges to the
 * material's. `splitWeight: 0` starts with the samples instead; a material made with mode
 * 'split' draws the split in every frame. The average starts again when the drawing
 * buffer's size, the camera, any visible object's world matrix (bones and instances included),
 * the scene's environment or background rotation changes, or `reset()` is called (after any other
 * change: a material, a light, a texture). After `maxFrames` frames it only shows the mean.
 *
 *     const live = new Accumulator(renderer);
 *     renderer.setAnimationLoop(() => live.render(scene, camera));
 */
export class Accumulator {
    constructor(renderer, { maxFrames = 4096, splitWeight = SPLIT_WEIGHT } = {}) {
        this.renderer = renderer;
        this.maxFrames = maxFrames;
        this.splitWeight = splitWeight;
        this.frames = 0;
        this.weight = 0;
        this.size = new THREE.Vector2();
        this.targets = null;
        this.signature = [];
        this.add = pass(ADD_FRAGMENT, { uSum: { value: null }, uFrame: { value: null }, uFirst: { value: true }, uWeight: { value: 1 } }, false);
        this.show = pass(SHOW_FRAGMENT, { uSum: { value: null }, uCount: { value: 1 } }, true);
    }

    /** Starts the average again at the next `render`. */
    reset() {
        this.frames = 0;
    }

    /**
     * The running sum (a float render target); the mean is sum / weight, `weight` the frames in
     * it with the split frame counted `splitWeight` times.
     */
    get sum() {
        return this.targets?.sum;
    }

    /** Draws the next frame of `scene` seen by `camera`, adds it, and shows the mean on the canvas. */
    render(scene, camera) {
        const renderer = this.renderer;
        renderer.getDrawingBufferSize(this.size);
        const [width, height] = [this.size.x, this.size.y];
        if (!this.targets || this.targets.sum.width !== width || this.targets.sum.height !== height) {
            this.disposeTargets();
            this.targets = { frame: floatTarget(width, height), sum: floatTarget(width, height), next: floatTarget(width, height) };
            this.frames = 0;
        }
        scene.updateMatrixWorld();
        camera.updateMatrixWorld();
        const signature = signatureOf(scene, camera, width, height);
        if (!sameSignature(signature, this.signature)) this.frames = 0;
        this.signature = signature;
        const previous = renderer.getRenderTarget();
        if (this.frames < this.maxFrames) {
            const bakes = [];
            scene.traverseVisible((object) => {
                for (const material of [object.material ?? []].flat()) {
                    if (material.userData?.brdfBake) bakes.push(material);
                }
            });
            const split = this.frames === 0 && this.splitWeight > 0;
            for (const material of bakes) {
                const u = material.uniforms;
                const bake = material.userData.brdfBake;
                const first = split || bake.mode === 'split';
                if (Boolean(material.defines.SPLIT) !== first) {
                    if (first) material.defines.SPLIT = 1;
                    else delete material.defines.SPLIT;
                    material.needsUpdate = true;
                }
                u.uFirstFrame.value = bake.firstFrame + Math.max(this.frames - (this.splitWeight > 0 ? 1 : 0), 0);
                u.uFrameCount.value = 1;
                u.uDivisor.value = 1;
            }
            const weight = split ? this.splitWeight : 1;
            renderer.setRenderTarget(this.targets.frame);
            renderer.clear();
            renderer.render(scene, camera);
            this.add.material.uniforms.uFirst.value = this.frames === 0;
            this.add.material.uniforms.uWeight.value = weight;
            this.add.material.uniforms.uSum.value = this.targets.sum.texture;
            this.add.material.uniforms.uFrame.value = this.targets.frame.texture;
            renderer.setRenderTarget(this.targets.next);
            renderer.render(this.add.scene, camera);
            [this.targets.sum, this.targets.next] = [this.targets.next, this.targets.sum];
            this.weight = (this.frames === 0 ? 0 : this.weight) + weight;
            this.frames += 1;
        }
        this.show.material.uniforms.uSum.value = this.targets.sum.texture;
        this.show.material.uniforms.uCount.value = this.weight;
        renderer.setRenderTarget(previous);
        renderer.render(this.show.scene, camera);
    }

    disposeTargets() {
        if (this.targets) Object.values(this.targets).forEach((t) => t.dispose());
        this.targets = null;
    }

    dispose() {
        this.disposeTargets();
        for (const p of [this.add, this.show]) {
            p.material.dispose();
            p.geometry.dispose();
        }
    }
}

/** What the average depends on: the size, the camera's matrices, each visible object's place. */
function signatureOf(scene, camera, width, height) {
    const out = [width, height, ...camera.matrixWorld.elements, ...camera.projectionMatrix.elements];
    for (const r of [scene.environmentRotation, scene.backgroundRotation]) if (r) out.push(r.x, r.y, r.z);
    scene.traverseVisible((object) => {
        out.push(object.id, ...object.matrixWorld.elements);
        if (object.isInstancedMesh) out.push(object.count, object.instanceMatrix.version);
    });
    return out;
}

function sameSignature(a, b) {
    return a.length === b.length && a.every((v, i) => v === b[i]);
}
