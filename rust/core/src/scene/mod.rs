//! Stage 1: the validated scene. Input polygons become convex planar `Face`s (receivers and
//! occluders alike) that remember their source polygon; lights become `Light`s.

pub mod convex;
pub mod json;
pub mod precision;
pub mod reach;
pub mod solids;
pub mod strict;
pub mod validate;

use glam::{DVec2, DVec3};

use crate::geom::{Frame, Plane};
use crate::settings::Settings;

pub use validate::validate;

/// A convex planar piece of an input polygon: the unit every later stage works on.
#[derive(Debug, Clone)]
pub struct Face {
    pub mesh: u32,
    pub source_polygon: u32,
    /// Counter-clockwise seen from the front, exactly planar (projected onto `plane`).
    pub verts: Vec<DVec3>,
    pub plane: Plane,
    pub frame: Frame,
    /// `verts` in `frame`, counter-clockwise.
    pub poly2: Vec<DVec2>,
    pub albedo: DVec3,
    pub emission: DVec3,
    pub area: f64,
}

impl Face {
    /// The face's size (its farthest vertex from the first), never below 1e-9 of the scene
    /// diagonal `diag`: the arrangement's snapping distance is relative to it.
    pub fn extent(&self, diag: f64) -> f64 {
        self.poly2
            .iter()
            .map(|p| (*p - self.poly2[0]).length())
            .fold(0.0, f64::max)
            .max(diag * 1e-9)
    }
}

#[derive(Debug, Clone)]
pub struct MeshInfo {
    pub name: String,
    pub n_polygons: usize,
    /// Faces of this mesh are `faces[face_start..face_end]`.
    pub face_start: usize,
    pub face_end: usize,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Spot {
    /// Unit direction the cone points along.
    pub direction: DVec3,
    /// cos of the half angle: outside this the spot gives nothing.
    pub cos_half_angle: f64,
    pub blend: f64,
}

#[derive(Debug, Clone, PartialEq)]
pub enum LightKind {
    /// A uniform diffuse convex polygon emitting from its front (counter-clockwise side).
    Area {
        verts: Vec<DVec3>,
        plane: Plane,
        radiance: DVec3,
    },
    /// An isotropic point (W/sr), optionally masked by a spot cone.
    Point {
        position: DVec3,
        intensity: DVec3,
        spot: Option<Spot>,
        /// Blender's soft falloff for a light of this radius: intensity · cos / (d² + r²)
        /// (Cycles treats such a point as a disk facing the receiver). Shadows stay hard.
        radius: f64,
    },
    /// A directional light: `direction` is where the light travels (unit), `irradiance` on a
    /// surface facing it (W/m²).
    Sun { direction: DVec3, irradiance: DVec3 },
}

#[derive(Debug, Clone, PartialEq)]
pub struct Light {
    pub name: String,
    /// Index in the input `lights` array (relations are reported in this order).
    pub index: usize,
    pub kind: LightKind,
}

/// A scene ready for the pipeline.
#[derive(Debug, Clone)]
pub struct Scene {
    pub meshes: Vec<MeshInfo>,
    pub faces: Vec<Face>,
    /// What casts shadows: single faces, and closed convex components as solids.
    pub occluders: Vec<solids::Occluder>,
    /// The occluder each face belongs to.
    pub face_occluder: Vec<u32>,
    pub lights: Vec<Light>,
    pub settings: Settings,
    pub bounds_min: DVec3,
    pub bounds_max: DVec3,
    /// Things dropped or repaired on the way in (degenerate polygons); not errors.
    pub warnings: Vec<String>,
}

impl Scene {
    pub fn diagonal(&self) -> f64 {
        (self.bounds_max - self.bounds_min).length()
    }
}
