//! Penumbra: discontinuity meshing and radiosity after Itoh, Shimada & Doi (1995), with exact
//! direct light. See `ARCHITECTURE.md` beside this crate for the pipeline.
//!
//! The pipeline runs one direction: `scene` → `shadow` → `edges` → `arrangement`/`relation`
//! → `mesh` → `direct` → `indirect` → `bake` (output).

pub mod bake;
pub mod elements;
pub mod error;
pub mod geom;
pub mod indirect;
pub mod patches;
pub mod progress;
pub mod relation;
pub mod scene;
pub mod settings;

pub use bake::{bake, bake_scene_json, Bake, BakedMesh, Stats};
pub use error::BakeError;
pub use progress::Progress;
pub use scene::json::SceneJson;
pub use scene::Scene;
