//! Writes a bake as binary glTF 2.0 (.glb): one mesh node per baked mesh, with positions,
//! triangle indices and linear vertex colours (COLOR_0), so any engine or viewer can load it.

use penumbra::Bake;
use serde_json::json;

/// The .glb bytes for `bake`. Colours are the baked outgoing radiance (linear RGB), as
/// glTF's COLOR_0 (which multiplies the base colour; an unlit material shows it as is).
pub fn to_glb(bake: &Bake) -> Vec<u8> {
    let mut bin: Vec<u8> = Vec::new();
    let mut views = Vec::new();
    let mut accessors = Vec::new();
    let mut meshes = Vec::new();
    let mut nodes = Vec::new();
    let mut push_view = |bin: &mut Vec<u8>, bytes: &[u8], target: u32| -> usize {
        while bin.len() % 4 != 0 {
            bin.push(0);
        }
        let off = bin.len();
        bin.extend_from_slice(bytes);
        views.push(
            json!({"buffer": 0, "byteOffset": off, "byteLength": bytes.len(), "target": target}),
        );
        views.len() - 1
    };
    for m in &bake.meshes {
        if m.triangles.is_empty() {
            continue;
        }
        let pos: Vec<u8> = m
            .positions
            .iter()
            .flat_map(|p| p.iter().flat_map(|&x| (x as f32).to_le_bytes()))
            .collect();
        let col: Vec<u8> = m
            .colors
            .iter()
            .flat_map(|c| c.iter().flat_map(|&x| (x as f32).to_le_bytes()))
            .collect();
        let idx: Vec<u8> = m
            .triangles
            .iter()
            .flat_map(|t| t.iter().flat_map(|&i| i.to_le_bytes()))
            .collect();
        let mut lo = [f32::INFINITY; 3];
        let mut hi = [f32::NEG_INFINITY; 3];
        for p in &m.positions {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k] as f32);
                hi[k] = hi[k].max(p[k] as f32);
            }
        }
        let vp = push_view(&mut bin, &pos, 34962);
        let vc = push_view(&mut bin, &col, 34962);
        let vi = push_view(&mut bin, &idx, 34963);
        let a0 = accessors.len();
        accessors.push(json!({"bufferView": vp, "componentType": 5126, "count": m.positions.len(), "type": "VEC3", "min": lo, "max": hi}));
        accessors.push(json!({"bufferView": vc, "componentType": 5126, "count": m.colors.len(), "type": "VEC3"}));
        accessors.push(json!({"bufferView": vi, "componentType": 5125, "count": m.triangles.len() * 3, "type": "SCALAR"}));
        meshes.push(json!({"name": m.name, "primitives": [{"attributes": {"POSITION": a0, "COLOR_0": a0 + 1}, "indices": a0 + 2, "material": 0}]}));
        nodes.push(json!({"name": format!("{}_baked", m.name), "mesh": meshes.len() - 1}));
    }
    while bin.len() % 4 != 0 {
        bin.push(0);
    }
    let doc = json!({
        "asset": {"version": "2.0", "generator": "penumbra"},
        "extensionsUsed": ["KHR_materials_unlit"],
        "scene": 0,
        "scenes": [{"nodes": (0..nodes.len()).collect::<Vec<_>>()}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": [{"name": "Radiosity", "pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 1.0], "metallicFactor": 0.0}, "extensions": {"KHR_materials_unlit": {}}}],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": bin.len()}],
    });
    let mut text = serde_json::to_vec(&doc).expect("glTF JSON serialises");
    while text.len() % 4 != 0 {
        text.push(b' ');
    }
    let total = 12 + 8 + text.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
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
