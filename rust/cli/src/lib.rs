//! Built-in scenes (the paper's test data and benchmark scenes) for the `penumbra scene`
//! command and the benchmarks.

pub mod args;
pub mod gltf;
pub mod scenes;
