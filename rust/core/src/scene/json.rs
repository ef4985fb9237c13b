//! Scene JSON v1 as serde types: the public interchange format (README documents it).
//! Parsing only; every check of values is in `validate`.

use serde::{Deserialize, Serialize};

pub const SCENE_FORMAT: &str = "penumbra-scene";
pub const SCENE_VERSION: u32 = 1;

#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneJson {
    pub format: String,
    pub version: u32,
    #[serde(default)]
    pub meshes: Vec<MeshJson>,
    #[serde(default)]
    pub lights: Vec<LightJson>,
    #[serde(default)]
    pub settings: SettingsJson,
}

/// One colour per polygon, or one colour for the whole mesh. (Deserialize is in `strict`.)
#[derive(Debug, Clone, Serialize)]
#[serde(untagged)]
pub enum PerPolygon {
    Uniform([f64; 3]),
    PerPolygon(Vec<[f64; 3]>),
}

#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshJson {
    pub name: String,
    pub positions: Vec<[f64; 3]>,
    pub polygons: Vec<Vec<i64>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub albedo: Option<PerPolygon>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub emission: Option<PerPolygon>,
    /// `false`: the mesh takes part (it casts shadows, reflects and emits light) but gets no
    /// output; the bake lists it with no triangles. Default `true`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub output: Option<bool>,
    /// Lightmap UVs, one per polygon corner (polygons flattened in order), as Blender's loops.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub uv: Option<Vec<[f64; 2]>>,
}

/// A light: exactly one of `polygon` (area light, with `radiance`), `point` (with
/// `intensity`, optionally a `spot` cone) or `direction` (sun, with `irradiance`).
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightJson {
    pub name: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub polygon: Option<Vec<[f64; 3]>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radiance: Option<[f64; 3]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub point: Option<[f64; 3]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub intensity: Option<[f64; 3]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spot: Option<SpotJson>,
    /// Point/spot only: radius of a round light. Blender's soft falloff (the default): a disc
    /// facing the receiver, irradiance I·cos/(d² + r²) unoccluded; soft shadows.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius: Option<f64>,
    /// Point/spot with `radius` only: `true` makes the light a sphere (Blender's soft falloff
    /// off), irradiance I·cos/d² unoccluded. Default `false`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sphere: Option<bool>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub direction: Option<[f64; 3]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub irradiance: Option<[f64; 3]>,
    /// Sun only: angular diameter of the sun's disc in radians, in [0, π) (Blender's `angle`);
    /// soft shadows when above 0. Default 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angle: Option<f64>,
}

/// A spot cone as Blender has it: the light points along `direction`; `angle` is the full
/// cone angle in radians, `blend` the soft edge fraction in [0, 1].
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpotJson {
    pub direction: [f64; 3],
    pub angle: f64,
    #[serde(default)]
    pub blend: f64,
}

/// All optional; `validate` fills defaults relative to the scene's size.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SettingsJson {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub element_size: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub penumbra_element_size: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub patch_size: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_angle: Option<f64>,
    /// Relative error of the baked direct light at any point against the exact light
    /// (default 0.01): elements are split until they meet it (`mesh::refine`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tolerance: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_elements: Option<u64>,
    /// Bytes the bake may use, at most by the resource model's estimate (default: half the
    /// machine's memory).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_memory: Option<u64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub indirect: Option<bool>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub convergence: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_shots: Option<u64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ambient: Option<bool>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lighting_only: Option<bool>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub penumbra_visibility: Option<String>,
    /// "fitted" (default: the least-squares fit of the direct light over the elements
    /// around each vertex) or "exact" (the light at the vertex).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vertex_values: Option<String>,
    /// "hierarchical" (default: hierarchical radiosity with clustering) or "progressive"
    /// (round 1's progressive refinement over patches).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub indirect_solver: Option<String>,
    /// "discontinuity" (default) or "uniform": a uniform mesh of `element_size`, with exact
    /// light at its vertices, for comparisons.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub meshing: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub penumbra_samples: Option<u32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub visibility_rays: Option<u32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub threads: Option<u32>,
    /// Radiance of a uniform world around the scene (Blender's Background colour ×
    /// strength), W·sr⁻¹·m⁻² per channel; none when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub world: Option<[f64; 3]>,
    /// Texels on a side of each lightmap; lightmaps are made for meshes with `uv` when set.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lightmap_resolution: Option<i64>,
    /// Rings of texels filled around the UV islands (default 16).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lightmap_margin: Option<i64>,
}
