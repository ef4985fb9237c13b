//! The whole bake, stage by stage, and its output (the bake JSON of DESIGN.md).

use serde::Serialize;

use crate::progress::Progress;
use crate::scene::json::SceneJson;
use crate::scene::Scene;
use crate::BakeError;

/// Figures named as in the paper's tables (times in seconds).
#[derive(Debug, Clone, Default, Serialize, PartialEq)]
#[allow(non_snake_case)]
pub struct Stats {
    /// Receivers before the loop split (convex faces).
    pub N_f1: u64,
    /// Faces after the loop split (regions bounded by loops).
    pub N_f2: u64,
    /// Discontinuity edges.
    pub N_d: u64,
    /// Patches (shooters of indirect light).
    pub N_p: u64,
    /// Elements (output triangles).
    pub N_e: u64,
    /// Output vertices.
    pub N_v: u64,
    pub T_sdw: f64,
    pub T_isr: f64,
    pub T_idd: f64,
    pub T_lop: f64,
    pub T_lit: f64,
    pub T_div: f64,
    pub T_m: f64,
    pub T_direct: f64,
    pub T_rs: f64,
    pub T_total: f64,
    /// Shooting steps of progressive refinement, and the unshot power left at the end as a
    /// fraction of the emitted power.
    pub shots: u64,
    pub unshot_fraction: f64,
    /// Vertex×light pairs: skipped in umbra, computed unoccluded in lit regions, computed
    /// with visibility in penumbra.
    pub pairs_umbra: u64,
    pub pairs_lit: u64,
    pub pairs_penumbra: u64,
    /// (light, occluder) pairs that got shadow volumes, and that were culled.
    pub shadow_pairs: u64,
    pub shadow_pairs_culled: u64,
}

/// One output mesh per input mesh (same name and order).
#[derive(Debug, Clone, Default, Serialize, PartialEq)]
pub struct BakedMesh {
    pub name: String,
    pub positions: Vec<[f64; 3]>,
    pub triangles: Vec<[u32; 3]>,
    /// Linear RGB outgoing radiance per vertex.
    pub colors: Vec<[f32; 3]>,
    /// Per triangle: index of the input polygon it lies in.
    pub source_polygon: Vec<u32>,
    /// Per triangle: one relation code per light (1 lit, 2 penumbra, 3 umbra), in the order
    /// of the input `lights`.
    pub relation: Vec<Vec<u8>>,
}

#[derive(Debug, Clone, Default, Serialize, PartialEq)]
pub struct Bake {
    pub format: &'static str,
    pub version: u32,
    pub meshes: Vec<BakedMesh>,
    pub stats: Stats,
    pub warnings: Vec<String>,
}

impl Bake {
    pub fn to_json(&self) -> String {
        serde_json::to_string(self).expect("bake output is always serialisable")
    }
}

/// Parses, validates and bakes scene JSON text.
pub fn bake_scene_json(text: &str, progress: &Progress) -> Result<Bake, BakeError> {
    let json = SceneJson::from_str(text)?;
    let scene = crate::scene::validate(&json)?;
    bake(&scene, progress)
}

/// Bakes a validated scene.
pub fn bake(scene: &Scene, progress: &Progress) -> Result<Bake, BakeError> {
    progress.check()?;
    let _ = scene;
    Err(BakeError::Empty("pipeline under construction".into()))
}
