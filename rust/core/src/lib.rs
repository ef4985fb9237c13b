//! Penumbra: discontinuity meshing and radiosity after Itoh, Shimada & Doi (1995), with exact
//! direct light. See `ARCHITECTURE.md` beside this crate for the pipeline.
//!
//! The pipeline runs one direction: `scene` → `shadow` → `edges` → `arrangement`/`relation`
//! → `mesh` → `direct` → `indirect` → `bake` (output).

pub mod arrangement;
pub mod bake;
pub mod buried;
pub mod coverage;
pub mod covered;
pub mod cuts;
pub mod direct;
pub mod edges;
pub mod elements;
pub mod error;
pub mod events;
pub mod geom;
pub mod indirect;
pub mod mesh;
pub mod mesh_cancel;
pub mod patches;
pub mod progress;
pub mod regions;
pub mod relation;
pub mod scene;
pub mod screens;
pub mod settings;
pub mod shadow;
pub mod sizing;
pub mod umbra_cover;
pub mod vertex_light;

pub use bake::{bake, bake_scene_json, Bake, BakedMesh, Stats};
pub use error::BakeError;
pub use progress::Progress;
pub use scene::json::SceneJson;
pub use scene::Scene;
