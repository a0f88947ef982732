//! A small glTF 2.0 writer for tests and fixtures: accessors over one binary buffer, meshes, nodes and
//! scenes as JSON, written as .glb, as .gltf with a base64 data URI, or as .gltf with an external .bin.
//! Written from the glTF 2.0 specification, independent of the reader under test.
#![allow(dead_code)] // each user needs a different subset

use serde_json::{json, Value};

/// glTF primitive modes (specification 3.7.2.1).
pub const TRIANGLES: u32 = 4;
pub const TRIANGLE_STRIP: u32 = 5;
pub const TRIANGLE_FAN: u32 = 6;
pub const LINES: u32 = 1;
pub const POINTS: u32 = 0;

/// Index component types.
pub const U8: u32 = 5121;
pub const U16: u32 = 5123;
pub const U32: u32 = 5125;
const F32: u32 = 5126;

#[derive(Debug, Default, Clone)]
pub struct GltfBuilder {
    pub bin: Vec<u8>,
    pub views: Vec<Value>,
    pub accessors: Vec<Value>,
    pub meshes: Vec<Value>,
    pub nodes: Vec<Value>,
    pub scenes: Vec<Value>,
    pub scene: Option<usize>,
    pub extensions_used: Vec<String>,
    pub extensions_required: Vec<String>,
}

impl GltfBuilder {
    pub fn new() -> Self {
        Self::default()
    }

    fn view(&mut self, bytes: &[u8]) -> usize {
        while self.bin.len() % 4 != 0 {
            self.bin.push(0);
        }
        self.views
            .push(json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()}));
        self.bin.extend_from_slice(bytes);
        self.views.len() - 1
    }

    /// A float VEC3 POSITION accessor (with its required min and max).
    pub fn positions(&mut self, pts: &[[f32; 3]]) -> usize {
        let bytes: Vec<u8> = pts.iter().flatten().flat_map(|x| x.to_le_bytes()).collect();
        let view = self.view(&bytes);
        let min: Vec<f32> = (0..3)
            .map(|k| pts.iter().map(|p| p[k]).fold(f32::INFINITY, f32::min))
            .collect();
        let max: Vec<f32> = (0..3)
            .map(|k| pts.iter().map(|p| p[k]).fold(f32::NEG_INFINITY, f32::max))
            .collect();
        self.accessors.push(json!({"bufferView": view, "componentType": F32, "count": pts.len(), "type": "VEC3", "min": min, "max": max}));
        self.accessors.len() - 1
    }

    /// An index accessor with the given component type (U8, U16 or U32).
    pub fn indices(&mut self, idx: &[u32], component: u32) -> usize {
        let bytes: Vec<u8> = match component {
            U8 => idx.iter().map(|&i| i as u8).collect(),
            U16 => idx.iter().flat_map(|&i| (i as u16).to_le_bytes()).collect(),
            _ => idx.iter().flat_map(|&i| i.to_le_bytes()).collect(),
        };
        let view = self.view(&bytes);
        self.accessors.push(json!({"bufferView": view, "componentType": component, "count": idx.len(), "type": "SCALAR"}));
        self.accessors.len() - 1
    }

    /// A mesh of primitives `(position accessor, index accessor, mode)`.
    pub fn mesh(&mut self, prims: &[(usize, Option<usize>, u32)]) -> usize {
        let prims: Vec<Value> = prims
            .iter()
            .map(|&(pos, idx, mode)| {
                let mut p = json!({"attributes": {"POSITION": pos}, "mode": mode});
                if let Some(i) = idx {
                    p["indices"] = json!(i);
                }
                p
            })
            .collect();
        self.meshes.push(json!({ "primitives": prims }));
        self.meshes.len() - 1
    }

    /// A node from its JSON (`mesh`, `children`, `matrix` or `translation`/`rotation`/`scale`).
    pub fn node(&mut self, node: Value) -> usize {
        self.nodes.push(node);
        self.nodes.len() - 1
    }

    pub fn add_scene(&mut self, roots: &[usize]) -> usize {
        self.scenes.push(json!({ "nodes": roots }));
        self.scenes.len() - 1
    }

    fn json(&self, buffer: &Value) -> Value {
        let mut root = json!({
            "asset": {"version": "2.0", "generator": "urdf-inertia tests"},
            "buffers": [buffer],
            "bufferViews": self.views,
            "accessors": self.accessors,
            "meshes": self.meshes,
        });
        if !self.nodes.is_empty() {
            root["nodes"] = json!(self.nodes);
        }
        if !self.scenes.is_empty() {
            root["scenes"] = json!(self.scenes);
        }
        if let Some(s) = self.scene {
            root["scene"] = json!(s);
        }
        if !self.extensions_used.is_empty() {
            root["extensionsUsed"] = json!(self.extensions_used);
        }
        if !self.extensions_required.is_empty() {
            root["extensionsRequired"] = json!(self.extensions_required);
        }
        root
    }

    /// Binary glTF: 12-byte header, JSON chunk (space-padded), BIN chunk (zero-padded).
    pub fn glb(&self) -> Vec<u8> {
        let mut js =
            serde_json::to_vec(&self.json(&json!({"byteLength": self.bin.len()}))).expect("json");
        while js.len() % 4 != 0 {
            js.push(b' ');
        }
        let mut bin = self.bin.clone();
        while bin.len() % 4 != 0 {
            bin.push(0);
        }
        let total = 12 + 8 + js.len() + 8 + bin.len();
        let mut out = Vec::with_capacity(total);
        out.extend_from_slice(b"glTF");
        out.extend_from_slice(&2u32.to_le_bytes());
        out.extend_from_slice(&(total as u32).to_le_bytes());
        out.extend_from_slice(&(js.len() as u32).to_le_bytes());
        out.extend_from_slice(b"JSON");
        out.extend_from_slice(&js);
        out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(&bin);
        out
    }

    /// JSON glTF with the buffer inline as a base64 data URI.
    pub fn gltf_data_uri(&self) -> String {
        let uri = format!("data:application/octet-stream;base64,{}", base64(&self.bin));
        serde_json::to_string_pretty(&self.json(&json!({"byteLength": self.bin.len(), "uri": uri})))
            .expect("json")
    }

    /// JSON glTF referring to an external buffer file by `uri` (percent-encoded as written); the caller
    /// writes `self.bin` next to it under the decoded name.
    pub fn gltf_external(&self, uri: &str) -> String {
        serde_json::to_string_pretty(&self.json(&json!({"byteLength": self.bin.len(), "uri": uri})))
            .expect("json")
    }
}

/// Standard base64 with padding (RFC 4648), written here so the test does not reuse the reader's decoder.
pub fn base64(data: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::new();
    for c in data.chunks(3) {
        let n = (u32::from(c[0]) << 16)
            | (u32::from(*c.get(1).unwrap_or(&0)) << 8)
            | u32::from(*c.get(2).unwrap_or(&0));
        s.push(A[(n >> 18) as usize & 63] as char);
        s.push(A[(n >> 12) as usize & 63] as char);
        s.push(if c.len() > 1 {
            A[(n >> 6) as usize & 63] as char
        } else {
            '='
        });
        s.push(if c.len() > 2 {
            A[n as usize & 63] as char
        } else {
            '='
        });
    }
    s
}

/// The 8 corners of an axis-aligned box of edge lengths `size` centred at `centre` (corner i has bits
/// x, y, z) and its 12 outward triangles.
pub fn box_corners(size: [f32; 3], centre: [f32; 3]) -> (Vec<[f32; 3]>, Vec<u32>) {
    let v: Vec<[f32; 3]> = (0..8)
        .map(|i| {
            [0, 1, 2].map(|k| {
                let h = size[k] / 2.0;
                centre[k] + if i & (1 << k) == 0 { -h } else { h }
            })
        })
        .collect();
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let t = quads
        .iter()
        .flat_map(|q| [q[0], q[1], q[2], q[0], q[2], q[3]])
        .collect();
    (v, t)
}

/// A box as a one-mesh glTF: indexed triangles, optionally under a node with the given JSON transform.
pub fn box_builder(size: [f32; 3], centre: [f32; 3], node: Value) -> GltfBuilder {
    let mut b = GltfBuilder::new();
    let (v, t) = box_corners(size, centre);
    let pos = b.positions(&v);
    let idx = b.indices(&t, U16);
    let mesh = b.mesh(&[(pos, Some(idx), TRIANGLES)]);
    let mut node = node;
    node["mesh"] = json!(mesh);
    let n = b.node(node);
    let s = b.add_scene(&[n]);
    b.scene = Some(s);
    b
}

/// The same box as one triangle strip around its four sides and two fans for its caps (U16 strip, U8
/// fans), corners c0..c3 counter-clockwise seen from +Z: three primitives of one mesh, or with
/// `separate_nodes` three meshes on three nodes.
pub fn box_strip_fan(size: [f32; 3], centre: [f32; 3], separate_nodes: bool) -> GltfBuilder {
    let mut b = GltfBuilder::new();
    let (v, _) = box_corners(size, centre);
    // Corner index by (x bit, y bit, z bit); ring order c0=(-,-), c1=(+,-), c2=(+,+), c3=(-,+).
    let ring = [0u32, 1, 3, 2];
    let bottom = |k: usize| ring[k % 4];
    let top = |k: usize| ring[k % 4] + 4;
    let mut strip = Vec::new();
    for k in 0..=4 {
        strip.push(top(k));
        strip.push(bottom(k));
    }
    let pos = b.positions(&v);
    let s = b.indices(&strip, U16);
    let top_fan = b.indices(&[top(0), top(1), top(2), top(3)], U8);
    let bottom_fan = b.indices(&[bottom(0), bottom(3), bottom(2), bottom(1)], U8);
    let prims = [
        (pos, Some(s), TRIANGLE_STRIP),
        (pos, Some(top_fan), TRIANGLE_FAN),
        (pos, Some(bottom_fan), TRIANGLE_FAN),
    ];
    let roots: Vec<usize> = if separate_nodes {
        prims
            .iter()
            .map(|p| {
                let mesh = b.mesh(&[*p]);
                b.node(json!({ "mesh": mesh }))
            })
            .collect()
    } else {
        let mesh = b.mesh(&prims);
        vec![b.node(json!({ "mesh": mesh }))]
    };
    let sc = b.add_scene(&roots);
    b.scene = Some(sc);
    b
}

/// The box as two triangle primitives of one mesh (six triangles each) over one POSITION accessor.
pub fn box_two_primitives(size: [f32; 3], centre: [f32; 3]) -> GltfBuilder {
    let mut b = GltfBuilder::new();
    let (v, t) = box_corners(size, centre);
    let pos = b.positions(&v);
    let first = b.indices(&t[..18], U16);
    let second = b.indices(&t[18..], U32);
    let mesh = b.mesh(&[
        (pos, Some(first), TRIANGLES),
        (pos, Some(second), TRIANGLES),
    ]);
    let n = b.node(json!({ "mesh": mesh }));
    let sc = b.add_scene(&[n]);
    b.scene = Some(sc);
    b
}

/// The same box with no indices: 36 positions, three per triangle.
pub fn box_unindexed(size: [f32; 3], centre: [f32; 3]) -> GltfBuilder {
    let mut b = GltfBuilder::new();
    let (v, t) = box_corners(size, centre);
    let flat: Vec<[f32; 3]> = t.iter().map(|&i| v[i as usize]).collect();
    let pos = b.positions(&flat);
    let mesh = b.mesh(&[(pos, None, TRIANGLES)]);
    let n = b.node(json!({ "mesh": mesh }));
    let sc = b.add_scene(&[n]);
    b.scene = Some(sc);
    b
}
