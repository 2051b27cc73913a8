// What engines/three/bench/gltf.mjs calls in the test page (test/page.html): brdf-fit's glTF
// material of one bake as three's GLTFLoader reads it, drawn by three beside the same glTF BRDF
// drawn exactly (window.gltfViewer), and the sheet of every material's two pictures
// (window.gltfSheet).
import { gltfBeside, sphereScene } from './frontier-page.js';

window.gltfViewer = async ({ bake: url, fitBake: fitUrl, size, truthFrames }) => {
    const s = await sphereScene(url, size, size);
    const gltf = await gltfBeside(url, fitUrl, s, truthFrames);
    const result = {
        type: gltf.material.type,
        readBack: gltf.readBack,
        threeAgainstExact: s.psnr(gltf.values, gltf.exact),
        three: s.picture(gltf.values),
        exact: s.picture(gltf.exact),
    };
    s.dispose();
    return result;
};

/**
 * A PNG (data URL) of `rows` (each `{ label, cells: [{ rgb, caption }] }`, every picture size x
 * size 8-bit RGB rows from the top), one row per material under `headings` (one per column,
 * its lines split at newlines), with `title` above and `legend` below.
 */
window.gltfSheet = ({ rows, headings, size, title, legend }) => {
    const [labelWidth, headingHeight, titleHeight, legendHeight, gap] = [170, 34, 28, 24, 4];
    const columns = headings.length;
    const canvas = document.createElement('canvas');
    canvas.width = labelWidth + columns * (size + gap);
    canvas.height = titleHeight + headingHeight + rows.length * (size + gap) + legendHeight;
    const ctx = canvas.getContext('2d');
    ctx.fillStyle = '#ffffff';
    ctx.fillRect(0, 0, canvas.width, canvas.height);
    ctx.fillStyle = '#1a1a1a';
    ctx.font = 'bold 14px sans-serif';
    ctx.fillText(title, 6, 19);
    ctx.font = '12px sans-serif';
    headings.forEach((h, c) => h.split('\n').forEach((line, l) => ctx.fillText(line, labelWidth + c * (size + gap) + 2, titleHeight + 12 + 14 * l)));
    rows.forEach((row, r) => {
        const top = titleHeight + headingHeight + r * (size + gap);
        ctx.fillStyle = '#1a1a1a';
        ctx.fillText(row.label, 6, top + size / 2 + 4);
        row.cells.forEach((cell, c) => {
            const image = ctx.createImageData(size, size);
            for (let i = 0; i < size * size; i++) {
                image.data.set([cell.rgb[3 * i], cell.rgb[3 * i + 1], cell.rgb[3 * i + 2], 255], 4 * i);
            }
            const left = labelWidth + c * (size + gap);
            ctx.putImageData(image, left, top);
            if (cell.caption) {
                ctx.fillStyle = '#e8e8e8';
                ctx.fillText(cell.caption, left + 3, top + size - 5);
            }
        });
    });
    ctx.fillStyle = '#1a1a1a';
    ctx.fillText(legend, 6, canvas.height - 8);
    return canvas.toDataURL('image/png');
};
