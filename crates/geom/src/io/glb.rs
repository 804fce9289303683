//! Binary glTF 2.0 (`.glb`) export of a part or of a stack of placed parts, for any viewer.
//!
//! Layout (glTF 2.0 specification, section 4.4 "GLB File Format"): a 12-byte header (`glTF`, version 2, total length),
//! a JSON chunk padded with spaces to a multiple of 4 bytes, and a BIN chunk padded with zeros. Each item (part, pose,
//! colour) becomes one mesh with one triangle primitive: every face of every convex component is fanned from its first
//! vertex, and vertices are duplicated per face so each carries its face's flat normal (non-indexed `TRIANGLES`,
//! `POSITION` and `NORMAL` as `VEC3`/`FLOAT`, `POSITION` with exact `min`/`max` of the stored `f32` values), and one
//! node carrying the pose as a column-major matrix. All item nodes hang below a root node that converts stackplan's
//! millimetres and +z up to glTF's metres and +y up (scale 0.001, rotation -90 degrees about x), so vertex data stay
//! in millimetres. O(total face size).
//!
//! The JSON is written with `serde_json::json!` rather than `gltf-json`'s typed structs: the document is a dozen fixed
//! objects, the macro mirrors the specification's JSON directly, and the tests validate the output independently by
//! parsing it back with `gltf-json` and running its validator.

use super::IoError;
use crate::part::Part;
use crate::pose::Pose;
use serde_json::json;
use std::path::Path;

/// One mesh instance of a `.glb` export.
#[derive(Debug, Clone, Copy)]
pub struct GlbItem<'a> {
    /// The part.
    pub part: &'a Part,
    /// Where it is.
    pub pose: Pose,
    /// Base colour, linear RGBA in [0, 1].
    pub color: [f32; 4],
}

impl<'a> GlbItem<'a> {
    /// The part at the identity pose in a neutral grey.
    pub fn part(part: &'a Part) -> Self {
        GlbItem { part, pose: Pose::IDENTITY, color: [0.7, 0.72, 0.75, 1.0] }
    }
}

const MAGIC: u32 = 0x4654_6C67; // "glTF"
const CHUNK_JSON: u32 = 0x4E4F_534A; // "JSON"
const CHUNK_BIN: u32 = 0x004E_4942; // "BIN\0"
const ARRAY_BUFFER: u32 = 34962;
const FLOAT: u32 = 5126;
const TRIANGLES: u32 = 4;

/// The `.glb` bytes for `items`.
pub fn glb_bytes(items: &[GlbItem<'_>]) -> Vec<u8> {
    let mut bin: Vec<u8> = Vec::new();
    let mut buffer_views = Vec::new();
    let mut accessors = Vec::new();
    let mut meshes = Vec::new();
    let mut materials = Vec::new();
    let mut nodes = vec![json!({
        "name": "stackplan (mm, z up)",
        "matrix": [0.001, 0.0, 0.0, 0.0, 0.0, 0.0, -0.001, 0.0, 0.0, 0.001, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0],
        "children": (1..=items.len()).collect::<Vec<_>>(),
    })];
    for (i, item) in items.iter().enumerate() {
        let mut positions: Vec<[f32; 3]> = Vec::new();
        let mut normals: Vec<[f32; 3]> = Vec::new();
        for c in &item.part.components {
            let v = c.vertices();
            for f in c.faces() {
                let n = f.plane.normal.as_vec3().to_array();
                let idx = &f.vertices;
                for w in idx[1..].windows(2) {
                    for k in [idx[0], w[0], w[1]] {
                        positions.push(v[k].as_vec3().to_array());
                        normals.push(n);
                    }
                }
            }
        }
        let mut min = [f32::INFINITY; 3];
        let mut max = [f32::NEG_INFINITY; 3];
        for p in &positions {
            for k in 0..3 {
                min[k] = min[k].min(p[k]);
                max[k] = max[k].max(p[k]);
            }
        }
        for (data, with_bounds) in [(&positions, true), (&normals, false)] {
            let offset = bin.len();
            for p in data.iter() {
                for x in p {
                    bin.extend_from_slice(&x.to_le_bytes());
                }
            }
            buffer_views.push(json!({
                "buffer": 0, "byteOffset": offset, "byteLength": bin.len() - offset, "target": ARRAY_BUFFER,
            }));
            let mut accessor = json!({
                "bufferView": buffer_views.len() - 1, "componentType": FLOAT, "count": data.len(), "type": "VEC3",
            });
            if with_bounds {
                accessor["min"] = json!(min.map(f64::from));
                accessor["max"] = json!(max.map(f64::from));
            }
            accessors.push(accessor);
        }
        let color = item.color.map(|c| f64::from(c.clamp(0.0, 1.0)));
        let mut material = json!({
            "name": format!("{} colour", item.part.name),
            "pbrMetallicRoughness": {"baseColorFactor": color, "metallicFactor": 0.2, "roughnessFactor": 0.7},
        });
        if color[3] < 1.0 {
            material["alphaMode"] = json!("BLEND");
        }
        materials.push(material);
        meshes.push(json!({
            "name": item.part.name,
            "primitives": [{
                "attributes": {"POSITION": 2 * i, "NORMAL": 2 * i + 1},
                "material": i,
                "mode": TRIANGLES,
            }],
        }));
        let r = item.pose.rotation;
        let p = item.pose.position;
        let matrix = [
            r.x_axis.x, r.x_axis.y, r.x_axis.z, 0.0, r.y_axis.x, r.y_axis.y, r.y_axis.z, 0.0, r.z_axis.x, r.z_axis.y,
            r.z_axis.z, 0.0, p.x, p.y, p.z, 1.0,
        ];
        // nodes are named after the parts' numbers, counted from 1 as people read them
        nodes.push(json!({"name": format!("{} #{}", item.part.name, i + 1), "mesh": i, "matrix": matrix}));
    }
    let mut document = json!({
        "asset": {"version": "2.0", "generator": "stackplan"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "accessors": accessors,
        "bufferViews": buffer_views,
    });
    if !bin.is_empty() {
        document["buffers"] = json!([{"byteLength": bin.len()}]);
    }
    let mut json_bytes = document.to_string().into_bytes();
    while !json_bytes.len().is_multiple_of(4) {
        json_bytes.push(b' ');
    }
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let bin_chunk = if bin.is_empty() { 0 } else { 8 + bin.len() };
    let total = 12 + 8 + json_bytes.len() + bin_chunk;
    let mut out = Vec::with_capacity(total);
    for word in [MAGIC, 2, total as u32, json_bytes.len() as u32, CHUNK_JSON] {
        out.extend_from_slice(&word.to_le_bytes());
    }
    out.extend_from_slice(&json_bytes);
    if !bin.is_empty() {
        out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
        out.extend_from_slice(&CHUNK_BIN.to_le_bytes());
        out.extend_from_slice(&bin);
    }
    out
}

/// Writes a `.glb` of `items` atomically.
pub fn write_glb(path: impl AsRef<Path>, items: &[GlbItem<'_>]) -> Result<(), IoError> {
    super::atomic::write_atomic(path, &glb_bytes(items))
}
