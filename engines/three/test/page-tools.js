// What the test page's functions share (page.html).
import * as THREE from 'three';

/** A WebGL renderer on a new canvas of `width x height` in the page, at pixel ratio 1. */
export function pageRenderer(width, height, options = {}) {
    const canvas = document.createElement('canvas');
    canvas.width = width;
    canvas.height = height;
    document.body.appendChild(canvas);
    const renderer = new THREE.WebGLRenderer({ canvas, antialias: false, ...options });
    renderer.setPixelRatio(1);
    renderer.setSize(width, height, false);
    return renderer;
}

/**
 * `scene` seen by `camera`, drawn into `target` cleared to transparent black, read back: RGBA
 * floats, rows from the bottom.
 */
export function drawFloats(renderer, target, scene, camera) {
    renderer.setRenderTarget(target);
    renderer.setClearColor(0x000000, 0);
    renderer.clear();
    renderer.render(scene, camera);
    const values = new Float32Array(4 * target.width * target.height);
    renderer.readRenderTargetPixels(target, 0, 0, target.width, target.height, values);
    return values;
}
