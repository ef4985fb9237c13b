//! Penumbra: discontinuity meshing and radiosity after Itoh, Shimada & Doi (1995), with exact
//! direct light. See `ARCHITECTURE.md` beside this crate for the pipeline.
//!
//! The pipeline runs one direction, one folder a stage: `scene` → `shadows` → `regions` →
//! `mesh` → `direct` → `indirect` → `bake` (output); `geom` is shared geometry and depends on
//! nothing above it.

// Public: what the CLI, the binding and the tests use (the input format, the bake and its
// output, lightmaps, the built-in scenes, the exact direct light and the geometry it rests
// on); the stages' engines are the crate's own. The order of the pipeline: ARCHITECTURE.md.
pub mod bake;
pub mod direct;
pub(crate) mod indirect;
pub mod lightmap;
pub(crate) mod mesh;
pub mod regions;
pub mod scene;
pub(crate) mod shadows;

pub mod error;
pub mod geom;
pub mod progress;
pub mod scenes;

pub use bake::{bake, bake_scene_json, Bake, BakedMesh, Stats};
pub use error::BakeError;
pub use progress::Progress;
pub use scene::json::SceneJson;
pub use scene::Scene;
