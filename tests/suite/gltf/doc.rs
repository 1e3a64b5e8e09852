//! glTF documents written for the tests: the unit box as a mesh in one buffer, placed by the
//! nodes a test gives, with accessors appended, as a `.gltf` (data URI or `.bin` beside) or a
//! `.glb`.

use crate::meshes::{box_corners, BOX_FACES};
use base64::Engine;
use glam::DVec3;
use serde_json::{json, Value};

/// A glTF document being written: its JSON and its one buffer.
pub(super) struct Doc {
    pub json: Value,
    pub bin: Vec<u8>,
}

impl Doc {
    /// The unit box centred on its origin as mesh 0 (12 triangles, counter-clockwise from
    /// outside), in buffer 0, with `nodes` as the scene's nodes (node 0 the top).
    pub(super) fn unit_box(nodes: Value) -> Doc {
        let mut bin = Vec::new();
        let centre = DVec3::new(0.0, 10.5, 0.0);
        for c in box_corners() {
            for x in (c - centre).to_array() {
                bin.extend_from_slice(&(x as f32).to_le_bytes());
            }
        }
        let positions = bin.len();
        for f in BOX_FACES {
            for t in [[f[0], f[1], f[2]], [f[0], f[2], f[3]]] {
                for i in t {
                    bin.extend_from_slice(&(i - 1).to_le_bytes());
                }
            }
        }
        let json = json!({
            "asset": {"version": "2.0"},
            "scene": 0,
            "scenes": [{"nodes": [0]}],
            "nodes": nodes,
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
            "buffers": [{"byteLength": bin.len()}],
            "bufferViews": [
                {"buffer": 0, "byteOffset": 0, "byteLength": positions},
                {"buffer": 0, "byteOffset": positions, "byteLength": bin.len() - positions}
            ],
            "accessors": [
                {"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3",
                 "min": [-0.5, -0.5, -0.5], "max": [0.5, 0.5, 0.5]},
                {"bufferView": 1, "componentType": 5125, "count": 36, "type": "SCALAR"}
            ]
        });
        Doc { json, bin }
    }

    /// Append f32 data as a new accessor of `kind` ("SCALAR", "VEC3"); its index.
    pub(super) fn accessor(&mut self, values: &[f32], kind: &str, count: usize) -> usize {
        let offset = self.bin.len();
        for v in values {
            self.bin.extend_from_slice(&v.to_le_bytes());
        }
        let views = self.json["bufferViews"].as_array_mut().unwrap();
        views.push(json!({"buffer": 0, "byteOffset": offset, "byteLength": values.len() * 4}));
        let view = views.len() - 1;
        self.json["buffers"][0]["byteLength"] = json!(self.bin.len());
        let mut acc =
            json!({"bufferView": view, "componentType": 5126, "count": count, "type": kind});
        if kind == "SCALAR" {
            let (lo, hi) = values
                .iter()
                .fold((f32::MAX, f32::MIN), |(a, b), &v| (a.min(v), b.max(v)));
            acc["min"] = json!([lo]);
            acc["max"] = json!([hi]);
        }
        let accessors = self.json["accessors"].as_array_mut().unwrap();
        accessors.push(acc);
        accessors.len() - 1
    }

    /// As a `.gltf` with its buffer in a data URI.
    pub(super) fn embedded(&self) -> String {
        let mut j = self.json.clone();
        let data = base64::engine::general_purpose::STANDARD.encode(&self.bin);
        j["buffers"][0]["uri"] = json!(format!("data:application/octet-stream;base64,{data}"));
        j.to_string()
    }

    /// As a `.gltf` naming `bin` beside it.
    pub(super) fn beside(&self, bin: &str) -> String {
        let mut j = self.json.clone();
        j["buffers"][0]["uri"] = json!(bin);
        j.to_string()
    }

    /// As a `.glb`.
    pub(super) fn glb(&self) -> Vec<u8> {
        let mut text = self.json.to_string().into_bytes();
        while !text.len().is_multiple_of(4) {
            text.push(b' ');
        }
        let mut bin = self.bin.clone();
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        let total = 12 + 8 + text.len() + 8 + bin.len();
        let mut out = Vec::new();
        out.extend_from_slice(b"glTF");
        out.extend_from_slice(&2u32.to_le_bytes());
        out.extend_from_slice(&(total as u32).to_le_bytes());
        out.extend_from_slice(&(text.len() as u32).to_le_bytes());
        out.extend_from_slice(b"JSON");
        out.extend_from_slice(&text);
        out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(&bin);
        out
    }
}

/// GOOD's box as one node keyed by `keys` (file time, translation), interpolated by
/// `interpolation`.
pub(super) fn keyed_box(keys: &[(f32, [f32; 3])], interpolation: &str) -> Doc {
    let mut doc = Doc::unit_box(json!([{"name": "box", "translation": [0, 10.5, 0], "mesh": 0}]));
    let t: Vec<f32> = keys.iter().map(|k| k.0).collect();
    let p: Vec<f32> = keys.iter().flat_map(|k| k.1).collect();
    let times = doc.accessor(&t, "SCALAR", keys.len());
    let values = doc.accessor(&p, "VEC3", keys.len());
    doc.json["animations"] = json!([{
        "channels": [{"sampler": 0, "target": {"node": 0, "path": "translation"}}],
        "samplers": [{"input": times, "output": values, "interpolation": interpolation}]
    }]);
    doc
}

/// The box of GOOD placed by two levels of nodes: a parent at (0, 10, 0) scaling by 2, its
/// child at (0, 0.25, 0) scaling by 1/2 (every number exact in binary).
pub(super) fn nested_nodes() -> Value {
    json!([
        {"name": "holder", "translation": [0, 10, 0], "scale": [2, 2, 2], "children": [1]},
        {"name": "box", "translation": [0, 0.25, 0], "scale": [0.5, 0.5, 0.5], "mesh": 0}
    ])
}
