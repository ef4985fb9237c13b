//! The `penumbra` command's pieces that are not the core: glTF output. The built-in scenes
//! live in the core (`penumbra::scenes`), shared with its tests.

pub mod gltf;
