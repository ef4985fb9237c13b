//! Built-in scenes (the paper's test data and benchmark scenes) for the `penumbra scene`
//! command and the benchmarks.

pub mod gltf;
pub mod images;
pub mod scenes;
