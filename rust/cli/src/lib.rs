//! The `penumbra` command's pieces that are not the core: glTF output and lightmap images. The built-in scenes
//! live in the core (`penumbra::scenes`), shared with its tests.

pub mod args;
pub mod gltf;
pub mod images;
