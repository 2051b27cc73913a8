// brdf-preview's tone map of one linear value (envmap::tonemap_rgb8, preview_present.wgsl's
// tonemap; three's ReinhardToneMapping and sRGB output are the same): the exposure, Reinhard's
// x / (1 + x), the sRGB transfer function, 8 bits. No imports: node scripts and the test page
// share it.
export function previewLevel(v, exposure) {
    const x = Math.min(Math.max(v * exposure, 0), 3e38);
    const r = x / (1 + x);
    const s = r <= 0.0031308 ? 12.92 * r : 1.055 * r ** (1 / 2.4) - 0.055;
    return Math.round(Math.min(Math.max(s, 0), 1) * 255);
}
