//! Bake settings after validation, with defaults relative to the scene's size.

use crate::scene::json::SettingsJson;
use crate::BakeError;

/// How the visible part of an area light is found at penumbra vertices.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PenumbraVisibility {
    /// Light polygon minus the projected occluders (2-D boolean): exact.
    Exact,
    /// The paper's point sampling: stratified rays through the light.
    Sampled,
}

/// What the direct light at an element vertex is (`mesh::fit`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VertexValues {
    /// The least-squares fit of the light over the elements around the vertex.
    Fitted,
    /// The exact light at the vertex.
    Exact,
}

/// How indirect light is solved (`indirect`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IndirectSolver {
    /// Progressive refinement over grid patches, gathered at element vertices.
    Progressive,
    /// Hierarchical radiosity with clustering on the discontinuity mesh.
    Hierarchical,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    /// Element edge length outside penumbra.
    pub element_size: f64,
    /// Element edge length inside penumbra.
    pub penumbra_element_size: f64,
    /// Patch edge length for shooting indirect light.
    pub patch_size: f64,
    /// Smallest inner angle that refinement aims for (degrees).
    pub min_angle: f64,
    /// Relative error of the baked direct light that refinement aims for (`mesh::refine`).
    pub tolerance: f64,
    pub max_elements: u64,
    /// Bytes the bake may use by the resource model's estimate (`scene::resources`).
    pub max_memory: u64,
    pub indirect: bool,
    pub convergence: f64,
    pub max_shots: u64,
    pub ambient: bool,
    pub lighting_only: bool,
    pub penumbra_visibility: PenumbraVisibility,
    /// Refined meshes only: `meshing: uniform` has exact vertex values.
    pub vertex_values: VertexValues,
    pub indirect_solver: IndirectSolver,
    /// Mesh uniformly instead of along discontinuities (for comparisons).
    pub uniform: bool,
    pub penumbra_samples: u32,
    pub visibility_rays: u32,
    pub threads: Option<u32>,
    /// Radiance of a uniform world (light from every direction not blocked by the scene).
    pub world: glam::DVec3,
}

pub const DEFAULT_TOLERANCE: f64 = 0.01;
/// Below this the exact light's own rounding (the polygon booleans snap at ~1e-9 of the
/// scene) would drive the split.
pub const MIN_TOLERANCE: f64 = 1e-5;
pub const DEFAULT_MAX_ELEMENTS: u64 = 4_000_000;
/// Largest `threads` accepted (the CLI's `--threads` too): past it a pool only costs memory.
pub const MAX_THREADS: u32 = 1024;

impl Settings {
    /// Defaults for a scene whose meshes' bounding box (lights left out) has diagonal `diag`.
    pub fn from_json(s: &SettingsJson, diag: f64) -> Result<Self, BakeError> {
        let diag = if diag > 0.0 && diag.is_finite() {
            diag
        } else {
            1.0
        };
        let element_size = positive("element_size", s.element_size, diag / 25.0)?;
        let penumbra_element_size = positive(
            "penumbra_element_size",
            s.penumbra_element_size,
            (element_size / 2.0).min(element_size),
        )?;
        let patch_size = positive("patch_size", s.patch_size, element_size * 2.0)?;
        // Only values the user gave: a derived default follows from one of these.
        for (name, v) in [
            ("element_size", s.element_size),
            ("penumbra_element_size", s.penumbra_element_size),
            ("patch_size", s.patch_size),
        ] {
            let Some(v) = v else { continue };
            if v < diag * 1e-7 {
                return Err(BakeError::setting(
                    name,
                    format!("{v} is below 1e-7 of the scene size {diag}"),
                ));
            }
        }
        let min_angle = s.min_angle.unwrap_or(25.0);
        if !(min_angle.is_finite() && (0.0..=33.0).contains(&min_angle)) {
            return Err(BakeError::setting(
                "min_angle",
                format!("{min_angle} must be in [0, 33] degrees"),
            ));
        }
        let tolerance = s.tolerance.unwrap_or(DEFAULT_TOLERANCE);
        if !(tolerance.is_finite() && (MIN_TOLERANCE..=1.0).contains(&tolerance)) {
            return Err(BakeError::setting(
                "tolerance",
                format!("{tolerance} must be in [{MIN_TOLERANCE:e}, 1]"),
            ));
        }
        let max_elements = s.max_elements.unwrap_or(DEFAULT_MAX_ELEMENTS);
        if max_elements == 0 {
            return Err(BakeError::setting("max_elements", "must be at least 1"));
        }
        let max_memory = s
            .max_memory
            .unwrap_or_else(crate::scene::machine::default_max_memory);
        if max_memory < 1 << 20 {
            return Err(BakeError::setting(
                "max_memory",
                format!("{max_memory} bytes: must be at least 1 MiB (1048576)"),
            ));
        }
        let convergence = s.convergence.unwrap_or(1e-3);
        if !(convergence.is_finite() && convergence > 0.0 && convergence < 1.0) {
            return Err(BakeError::setting(
                "convergence",
                format!("{convergence} must be in (0, 1)"),
            ));
        }
        let uniform = one_of(
            "meshing",
            s.meshing.as_deref(),
            &[("discontinuity", false), ("uniform", true)],
        )?;
        let penumbra_visibility = one_of(
            "penumbra_visibility",
            s.penumbra_visibility.as_deref(),
            &[
                ("exact", PenumbraVisibility::Exact),
                ("sampled", PenumbraVisibility::Sampled),
            ],
        )?;
        let vertex_values = one_of(
            "vertex_values",
            s.vertex_values.as_deref(),
            &[
                ("fitted", VertexValues::Fitted),
                ("exact", VertexValues::Exact),
            ],
        )?;
        let indirect_solver = one_of(
            "indirect_solver",
            s.indirect_solver.as_deref(),
            &[
                ("hierarchical", IndirectSolver::Hierarchical),
                ("progressive", IndirectSolver::Progressive),
            ],
        )?;
        let penumbra_samples = s.penumbra_samples.unwrap_or(64);
        if !(1..=65536).contains(&penumbra_samples) {
            return Err(BakeError::setting(
                "penumbra_samples",
                format!("{penumbra_samples} must be in [1, 65536]"),
            ));
        }
        let visibility_rays = s.visibility_rays.unwrap_or(16);
        if !(1..=4096).contains(&visibility_rays) {
            return Err(BakeError::setting(
                "visibility_rays",
                format!("{visibility_rays} must be in [1, 4096]"),
            ));
        }
        let max_shots = s.max_shots.unwrap_or(100_000);
        if let Some(t) = s.threads {
            if t == 0 || t > MAX_THREADS {
                return Err(BakeError::setting(
                    "threads",
                    format!("{t} must be in [1, {MAX_THREADS}]"),
                ));
            }
        }
        let world = match s.world {
            None => glam::DVec3::ZERO,
            Some(c) if c.iter().all(|x| x.is_finite() && (0.0..=1e30).contains(x)) => {
                glam::DVec3::from_array(c)
            }
            Some(c) => {
                return Err(BakeError::setting(
                    "world",
                    format!("{c:?} must be three finite radiances ≥ 0"),
                ))
            }
        };
        Ok(Settings {
            element_size,
            penumbra_element_size,
            patch_size,
            min_angle,
            tolerance,
            max_elements,
            max_memory,
            indirect: s.indirect.unwrap_or(true),
            convergence,
            max_shots,
            ambient: s.ambient.unwrap_or(false),
            lighting_only: s.lighting_only.unwrap_or(false),
            penumbra_visibility,
            vertex_values,
            indirect_solver,
            uniform,
            penumbra_samples,
            visibility_rays,
            threads: s.threads,
            world,
        })
    }
}

/// The option named `value` among `options` (the first when none is given), or an error
/// that lists them.
fn one_of<T: Copy>(name: &str, value: Option<&str>, options: &[(&str, T)]) -> Result<T, BakeError> {
    let Some(v) = value else {
        return Ok(options[0].1);
    };
    match options.iter().find(|(o, _)| *o == v) {
        Some(&(_, t)) => Ok(t),
        None => {
            let names: Vec<String> = options.iter().map(|(o, _)| format!("{o:?}")).collect();
            Err(BakeError::setting(
                name,
                format!("{v:?} is not {}", names.join(" or ")),
            ))
        }
    }
}

fn positive(name: &str, v: Option<f64>, default: f64) -> Result<f64, BakeError> {
    match v {
        None => Ok(default),
        Some(x) if x.is_finite() && x > 0.0 => Ok(x),
        Some(x) => Err(BakeError::setting(
            name,
            format!("{x} must be a positive finite length"),
        )),
    }
}
