// What engines/three/test/render.mjs calls in the test page (page.html): renders a bake on
// brdf-preview's sphere at brdf-preview's camera and size, and hands the picture back
// (window.renderBake).
import * as THREE from 'three';
import { exactCoverage, loadBake, previewSphere, orbitCamera } from '../src/index.js';
import { pageRenderer } from './page-tools.js';

// Renders `bake` with `mode` at width x height into a float target, in tiles of `tile` pixels
// (each one draw of every frame: no draw runs for long), and returns the tone-mapped picture as
// 8-bit RGB, rows from the top, rounded as envmap::tonemap_rgb8 rounds. With `coverage` 'exact'
// the mesh is rasterized at brdf-preview's sub-pixel precision (exactCoverage) and shaded by the
// deferred pass; with 'forward' the material draws the mesh as any scene would. With `timing`,
// also the milliseconds per frame of whole-image draws of one frame each (forward).
window.renderBake = async ({ bake: url, mode, width, height, spp, frames, seed = 0, azimuth = 0, elevation = 0, tile = 64, timing = 0, picture = true, coverage = 'exact' }) => {
    const renderer = pageRenderer(width, height);
    const bake = await loadBake(url);
    // brdf-preview's world and picture.
    const look = { orientation: 'brdf-preview', output: 'brdf-preview' };
    const material = bake.createMaterial({ mode, spp, frames, seed, ...look });
    const scene = new THREE.Scene();
    scene.add(bake.createBackground(look));
    scene.add(new THREE.Mesh(previewSphere(), material));
    const camera = orbitCamera(width / height, azimuth, elevation);
    const target = new THREE.WebGLRenderTarget(width, height, {
        type: THREE.FloatType, format: THREE.RGBAFormat, depthBuffer: true,
        minFilter: THREE.NearestFilter, magFilter: THREE.NearestFilter, generateMipmaps: false,
    });
    const result = {};
    const disposables = [material];
    const gl = renderer.getContext();
    const debug = gl.getExtension('WEBGL_debug_renderer_info');
    result.renderer = gl.getParameter(debug ? debug.UNMASKED_RENDERER_WEBGL : gl.RENDERER);
    if (picture) {
        let drawn = scene;
        if (coverage === 'exact') {
            camera.updateMatrixWorld();
            const gbuffer = exactCoverage(renderer, previewSphere(), camera, width, height);
            drawn = new THREE.Scene();
            drawn.add(bake.createDeferred(gbuffer, { mode, spp, frames, seed, ...look }));
            disposables.push(gbuffer.target);
        }
        renderer.setRenderTarget(target);
        target.scissorTest = true;
        const start = performance.now();
        for (let y = 0; y < height; y += tile) {
            for (let x = 0; x < width; x += tile) {
                target.scissor.set(x, y, Math.min(tile, width - x), Math.min(tile, height - y));
                // The target's scissor takes effect when the target is set.
                renderer.setRenderTarget(target);
                renderer.render(drawn, camera);
                // Wait for the tile, so that no draw queue grows beyond one tile's work.
                renderer.readRenderTargetPixels(target, x, y, 1, 1, new Float32Array(4));
            }
        }
        const renderMs = performance.now() - start;
        target.scissorTest = false;
        const values = new Float32Array(4 * width * height);
        renderer.readRenderTargetPixels(target, 0, 0, width, height, values);
        const rgb = new Uint8Array(3 * width * height);
        for (let y = 0; y < height; y++) {
            // The target's row 0 is the bottom row.
            const row = height - 1 - y;
            for (let x = 0; x < width; x++) {
                for (let c = 0; c < 3; c++) {
                    const v = values[4 * (row * width + x) + c];
                    rgb[3 * (y * width + x) + c] = Math.round(Math.min(Math.max(v, 0), 1) * 255);
                }
            }
        }
        result.rgb = Array.from(rgb);
        result.renderMs = renderMs;
    }
    if (timing > 0) {
        // One frame per draw, the whole image, to the canvas: brdf-preview's ms per frame.
        renderer.setRenderTarget(null);
        material.uniforms.uFrameCount.value = 1;
        material.uniforms.uDivisor.value = 1;
        const pixel = new Uint8Array(4);
        // One pixel first: compiles the programs and uploads the textures, untimed.
        renderer.setScissorTest(true);
        renderer.setScissor(width / 2, height / 2, 1, 1);
        renderer.render(scene, camera);
        gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);
        renderer.setScissorTest(false);
        const t0 = performance.now();
        for (let i = 0; i < timing; i++) {
            material.uniforms.uFirstFrame.value = i;
            renderer.render(scene, camera);
            gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);
        }
        result.msPerFrame = (performance.now() - t0) / timing;
    }
    disposables.forEach((d) => d.dispose());
    bake.dispose();
    target.dispose();
    renderer.dispose();
    return result;
};
