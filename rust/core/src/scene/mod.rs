//! Stage `scene`: the validated scene. Input polygons become convex planar `Face`s (receivers and
//! occluders alike) that remember their source polygon; lights become `Light`s.

pub mod convex;
pub mod disc;
pub mod emitters;
pub mod json;
pub mod machine;
pub mod precision;
pub mod reach;
pub mod resources;
pub mod settings;
pub mod solids;
pub mod strict;
pub mod tolerances;
pub mod validate;

use glam::{DVec2, DVec3};

use crate::geom::{Frame, Plane};
use crate::scene::settings::Settings;

pub use tolerances::Tolerances;
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
    /// Whether the bake writes this mesh's triangles (`MeshJson::output`); a mesh without
    /// output still casts shadows, reflects and emits.
    pub output: bool,
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
        /// Radius of a round light (`disc`): with `sphere` off, Blender's soft falloff, a disc
        /// of this radius facing the receiver (intensity · cos / (d² + r²) unoccluded); with
        /// `sphere` on, a sphere. Its shadows have penumbrae. 0: a point, hard shadows.
        radius: f64,
        sphere: bool,
    },
    /// A directional light: `direction` is where the light travels (unit), `irradiance` on a
    /// surface facing it (W/m²); `half_angle` > 0 makes it a disc of that angular radius
    /// (Blender's `angle` / 2), with penumbrae (`disc`).
    Sun {
        direction: DVec3,
        irradiance: DVec3,
        half_angle: f64,
    },
}

#[derive(Debug, Clone, PartialEq)]
pub struct Light {
    pub name: String,
    /// Index in the input `lights` array (relations are reported in this order).
    pub index: usize,
    pub kind: LightKind,
    /// For a light made from an emissive face (`emitters`), that face: its emission reaches
    /// the scene through this light, so the indirect stage does not send it again.
    pub from_face: Option<u32>,
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

    /// The scene's tolerances (`tolerances`), from its diagonal.
    pub fn tolerances(&self) -> Tolerances {
        Tolerances::new(self.diagonal())
    }
}

impl crate::geom::PlanarPolygon for Face {
    fn verts(&self) -> &[DVec3] {
        &self.verts
    }
    fn plane(&self) -> Plane {
        self.plane
    }
}

#[cfg(test)]
pub(crate) mod test {
    use glam::DVec3;

    use super::Face;
    use crate::geom::polygon::signed_area_2d;
    use crate::geom::{Frame, Plane};

    /// The scene of `meshes` under one point light 5 above the origin: for tests about
    /// geometry, where the light only has to be valid.
    pub(crate) fn with_bulb(meshes: Vec<super::json::MeshJson>) -> super::Scene {
        super::validate(&super::json::SceneJson {
            format: "penumbra-scene".into(),
            version: 1,
            meshes,
            lights: vec![super::json::LightJson {
                name: "Bulb".into(),
                point: Some([0.0, 0.0, 5.0]),
                intensity: Some([1.0; 3]),
                ..Default::default()
            }],
            settings: super::json::SettingsJson::default(),
        })
        .unwrap()
    }

    /// A face from counter-clockwise (seen from the front) vertices.
    pub(crate) fn face(verts: &[DVec3], albedo: DVec3, emission: DVec3) -> Face {
        let plane = Plane::from_polygon(verts).expect("face has area");
        let verts: Vec<DVec3> = verts
            .iter()
            .map(|v| *v - plane.n * plane.dist(*v))
            .collect();
        let frame = Frame::on_plane(&plane, verts[0]);
        let poly2: Vec<_> = verts.iter().map(|v| frame.to_2d(*v)).collect();
        let area = signed_area_2d(&poly2);
        Face {
            mesh: 0,
            source_polygon: 0,
            verts,
            plane,
            frame,
            poly2,
            albedo,
            emission,
            area,
        }
    }
}
