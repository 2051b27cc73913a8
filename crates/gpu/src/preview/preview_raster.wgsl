//! The previewer's visibility pass: which triangle covers each pixel centre, by the rasterizer
//! itself, whose rules the `render` crate's specification follows (no culling, depth test LESS so
//! that ties keep the triangle drawn first, no multisampling). It writes the triangle's index plus
//! one (0: none) and nothing else: the shading pass interpolates the vertices itself
//! (`preview_geometry.wgsl`, `interpolate_hit`), from the snapped coordinates as the specification
//! says, where a rasterizer's own interpolation is free to differ (lavapipe's is off by up to
//! 1/500 of a pixel's footprint at grazing angles).
//!
//! The draw is not indexed: vertex `i` of the draw is corner `i % 3` of triangle `i / 3`, read
//! from the same mesh buffers the shading pass reads. The vertices' clip-space positions are the
//! CPU's (`render::raster::project`): a GPU may fuse the projection's multiply-adds and round
//! differently.

// Twelve values per vertex (`preview_shade.wgsl`): the clip-space position first.
@group(0) @binding(0) var<storage, read> mesh_vertices: array<f32>;
// Three per triangle (`render::Mesh::indices`).
@group(0) @binding(1) var<storage, read> mesh_indices: array<u32>;

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) @interpolate(flat) triangle: u32,
}

// The hardware rasterizes by the rules of `render::raster::rasterize` (the clip positions are
// `render::raster::project`'s).
@vertex
fn raster_vertex(@builtin(vertex_index) corner: u32) -> VertexOut {
    let v = 12u * mesh_indices[corner];
    let clip = vec4<f32>(mesh_vertices[v], mesh_vertices[v + 1u], mesh_vertices[v + 2u], mesh_vertices[v + 3u]);
    return VertexOut(clip, corner / 3u);
}

// The triangle that `render::raster::rasterize` finds at the pixel, plus one.
@fragment
fn raster_fragment(in: VertexOut) -> @location(0) u32 {
    return in.triangle + 1u;
}
