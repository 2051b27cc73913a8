//! The fitted material as a glTF 2.0 asset: a UV sphere (positions and normals, `+Y` up as glTF
//! requires) with one material, `KHR_materials_specular` and `KHR_materials_clearcoat` in
//! `extensionsUsed` when the material needs them. In memory: the caller writes the two files together.

use std::f64::consts::PI;

use serde_json::json;

use crate::model::Material;

/// Segments around the sphere's axis and rings from pole to pole.
pub const SEGMENTS: usize = 64;
pub const RINGS: usize = 32;

/// The `.gltf` document (JSON text) and its `.bin` buffer, which the document names as
/// `bin_name` (a plain file name beside it).
#[derive(Debug, Clone, PartialEq)]
pub struct GltfFiles {
    pub gltf: String,
    pub bin: Vec<u8>,
}

/// A unit sphere about `+Y`: `(RINGS + 1) x (SEGMENTS + 1)` vertices (the seam duplicated, as a
/// textured sphere would have it), one triangle per quad at the poles (no degenerate triangles),
/// counter-clockwise seen from outside. Positions equal normals.
fn sphere() -> (Vec<[f32; 3]>, Vec<u16>) {
    let mut positions = Vec::with_capacity((RINGS + 1) * (SEGMENTS + 1));
    for ring in 0..=RINGS {
        let theta = ring as f64 / RINGS as f64 * PI;
        for segment in 0..=SEGMENTS {
            let phi = segment as f64 / SEGMENTS as f64 * 2.0 * PI;
            let (x, y, z) = (theta.sin() * phi.sin(), theta.cos(), theta.sin() * phi.cos());
            let length = (x * x + y * y + z * z).sqrt();
            positions.push([(x / length) as f32, (y / length) as f32, (z / length) as f32]);
        }
    }
    let vertex = |ring: usize, segment: usize| (ring * (SEGMENTS + 1) + segment) as u16;
    let mut indices = Vec::new();
    for ring in 0..RINGS {
        for segment in 0..SEGMENTS {
            let (a, b) = (vertex(ring, segment), vertex(ring, segment + 1));
            let (c, d) = (vertex(ring + 1, segment), vertex(ring + 1, segment + 1));
            if ring != 0 {
                indices.extend([a, c, b]);
            }
            if ring != RINGS - 1 {
                indices.extend([b, c, d]);
            }
        }
    }
    (positions, indices)
}

/// The glTF files of `material` on a sphere. `name` names the material and the mesh;
/// `generator` is `asset.generator` (the tool and its version).
pub fn gltf_files(material: &Material, name: &str, bin_name: &str, generator: &str) -> GltfFiles {
    let (positions, indices) = sphere();
    let mut bin = Vec::new();
    for p in &positions {
        p.iter().for_each(|v| bin.extend_from_slice(&v.to_le_bytes()));
    }
    let vertex_bytes = bin.len();
    for p in &positions {
        p.iter().for_each(|v| bin.extend_from_slice(&v.to_le_bytes()));
    }
    for i in &indices {
        bin.extend_from_slice(&i.to_le_bytes());
    }
    let index_bytes = indices.len() * 2;
    // A buffer's length is what it holds; the file is padded to 4 bytes as GLB chunks are.
    let byte_length = bin.len();
    while bin.len() % 4 != 0 {
        bin.push(0);
    }
    let (min, max) = bounds(&positions);
    let [r, g, b] = material.base_color;
    let pbr = json!({
        "baseColorFactor": [r, g, b, 1.0],
        "metallicFactor": material.metallic,
        "roughnessFactor": material.roughness,
    });
    let mut gltf_material = json!({ "name": name, "pbrMetallicRoughness": pbr });
    let mut document = json!({
        "asset": { "version": "2.0", "generator": generator },
        "scene": 0,
        "scenes": [{ "nodes": [0] }],
        "nodes": [{ "mesh": 0, "name": name }],
        "meshes": [{
            "name": name,
            "primitives": [{ "attributes": { "POSITION": 0, "NORMAL": 1 }, "indices": 2, "material": 0, "mode": 4 }],
        }],
        "buffers": [{ "uri": bin_name, "byteLength": byte_length }],
        "bufferViews": [
            { "buffer": 0, "byteOffset": 0, "byteLength": vertex_bytes, "target": 34962 },
            { "buffer": 0, "byteOffset": vertex_bytes, "byteLength": vertex_bytes, "target": 34962 },
            { "buffer": 0, "byteOffset": 2 * vertex_bytes, "byteLength": index_bytes, "target": 34963 },
        ],
        "accessors": [
            { "bufferView": 0, "componentType": 5126, "count": positions.len(), "type": "VEC3", "min": min, "max": max },
            { "bufferView": 1, "componentType": 5126, "count": positions.len(), "type": "VEC3" },
            { "bufferView": 2, "componentType": 5123, "count": indices.len(), "type": "SCALAR" },
        ],
    });
    let mut extensions = serde_json::Map::new();
    if material.uses_specular_extension() {
        extensions.insert(
            "KHR_materials_specular".into(),
            json!({ "specularFactor": material.specular, "specularColorFactor": material.specular_color }),
        );
    }
    if material.uses_clearcoat_extension() {
        extensions.insert(
            "KHR_materials_clearcoat".into(),
            json!({ "clearcoatFactor": material.clearcoat, "clearcoatRoughnessFactor": material.clearcoat_roughness }),
        );
    }
    if !extensions.is_empty() {
        gltf_material["extensions"] = serde_json::Value::Object(extensions);
        document["extensionsUsed"] = json!(material.extensions());
    }
    document["materials"] = json!([gltf_material]);
    let gltf = serde_json::to_string_pretty(&document).expect("json values serialize") + "\n";
    GltfFiles { gltf, bin }
}

/// The smallest and largest coordinates of the positions, as `f32` values (the validator
/// compares them with the data exactly).
fn bounds(positions: &[[f32; 3]]) -> ([f32; 3], [f32; 3]) {
    let mut min = [f32::MAX; 3];
    let mut max = [f32::MIN; 3];
    for p in positions {
        for c in 0..3 {
            min[c] = min[c].min(p[c]);
            max[c] = max[c].max(p[c]);
        }
    }
    (min, max)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sphere_is_closed_and_unit() {
        let (positions, indices) = sphere();
        assert!(positions.len() < u16::MAX as usize);
        for p in &positions {
            let length = p.iter().map(|v| (*v as f64).powi(2)).sum::<f64>().sqrt();
            assert!((length - 1.0).abs() < 1e-6, "{p:?}");
        }
        // Two triangles per quad but one at each pole's ring.
        assert_eq!(indices.len(), 3 * (2 * RINGS * SEGMENTS - 2 * SEGMENTS));
        // Outward: each triangle's normal points away from the centre (counter-clockwise).
        for t in indices.chunks(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| glam::Vec3::from(positions[i as usize]));
            let n = (b - a).cross(c - a);
            assert!(n.length() > 0.0, "degenerate {t:?}");
            assert!(n.dot(a + b + c) > 0.0, "inward {t:?}");
        }
    }

    #[test]
    fn extension_only_when_used() {
        let core = Material::core([0.5; 3], 0.0, 0.5);
        let files = gltf_files(&core, "m", "m.bin", "test");
        let doc: serde_json::Value = serde_json::from_str(&files.gltf).unwrap();
        assert!(doc.get("extensionsUsed").is_none());
        assert_eq!(doc["buffers"][0]["byteLength"].as_u64().unwrap() as usize, files.bin.len());
        let specular = Material { specular: 0.5, ..core };
        let doc: serde_json::Value = serde_json::from_str(&gltf_files(&specular, "m", "m.bin", "test").gltf).unwrap();
        assert_eq!(doc["extensionsUsed"], json!(["KHR_materials_specular"]));
        assert_eq!(doc["materials"][0]["extensions"]["KHR_materials_specular"]["specularFactor"], 0.5);
        let coated = Material { clearcoat: 0.7, clearcoat_roughness: 0.1, ..specular };
        let doc: serde_json::Value = serde_json::from_str(&gltf_files(&coated, "m", "m.bin", "test").gltf).unwrap();
        assert_eq!(doc["extensionsUsed"], json!(["KHR_materials_specular", "KHR_materials_clearcoat"]));
        let coat = &doc["materials"][0]["extensions"]["KHR_materials_clearcoat"];
        assert_eq!(
            (coat["clearcoatFactor"].as_f64(), coat["clearcoatRoughnessFactor"].as_f64()),
            (Some(0.7), Some(0.1))
        );
    }
}
