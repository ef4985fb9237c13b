//! Penumbra: discontinuity meshing and radiosity after Itoh, Shimada & Doi (1995), with exact
//! direct light. See `ARCHITECTURE.md` beside this crate for the pipeline.
//!
//! The pipeline runs one direction: `scene` → `shadow` → `edges` → `arrangement`/`relation`
//! → `mesh` → `direct` → `indirect` → `bake` (output).

pub mod bake;
pub mod direct;
pub mod error;
pub mod geom;
pub mod indirect;
pub mod mesh;
pub mod progress;
pub mod regions;
pub mod scene;
pub mod shadows;

// Moved into `indirect/` by the hierarchical-radiosity work.
pub mod covered;
pub mod patches;

pub use bake::{bake, bake_scene_json, Bake, BakedMesh, Stats};
pub use error::BakeError;
pub use progress::Progress;
pub use scene::json::SceneJson;
pub use scene::Scene;
