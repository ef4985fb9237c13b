//! Stage 7: indirect light by hierarchical radiosity with clustering (Hanrahan, Salzman &
//! Aupperle 1991; Smits, Arvo & Greenberg 1994; Sillion 1995), on the discontinuity mesh.
//!
//! Units follow `DESIGN.md`: irradiance E and radiosity B in W/m² per RGB channel; a face's
//! `emission` is radiance, so it leaves the face as radiosity π·Le.
//!
//! The element triangles are the leaves of one tree (`hierarchy`): clusters of faces, a
//! face, its regions (cut along the discontinuity loops first, so a lit region, a penumbra
//! and an umbra never shoot as one), then halves of a region. Links between nodes (`link`)
//! are made by refining the root's link to itself (`refine`) until each link's power is
//! under a tolerance, near pairs down to leaves; visibility per link is a shaft test, then
//! a fixed set of rays for the partly blocked (`visibility`). Jacobi sweeps with push–pull
//! (`solve`) run until a sweep adds less than `convergence` of the emitted power, and each
//! element vertex gathers once more over the links above it, with factors from the vertex
//! itself and, where a link's shaft is not clear, visibility from its leaf or itself
//! (`vertices`). Where that light is not linear along an element edge (beside a contact,
//! on a face direct light left coarse), the edge is split and its midpoint becomes a vertex
//! (`subdivide`): the element mesh that comes out is the direct stage's, refined for
//! indirect light. Every step gives the same bits for any thread count.
//!
//! Parts of faces lying against another face (`covered`) or buried in another solid
//! (`buried`) neither shoot nor receive. The backs of thin faces with something behind them
//! are faces of their own in the hierarchy (`back`), which receive and shoot into the
//! half-space behind.
//!
//! Settings: `convergence` sets both the link tolerance and the end of the solve;
//! `visibility_rays` is the ray count for links carrying the most; `max_shots` caps the
//! sweeps; `tolerance` (direct light's, times `SUBDIVIDE_SCALE`) decides the splits;
//! `patch_size` is not used (the hierarchy replaces the grid patches).

mod back;
mod bisect;
mod buried;
mod exact;
mod from_point;
mod hierarchy;
mod link;
mod own_look;
mod refine;
mod solve;
pub mod subdivide;
mod vertices;
mod visibility;

use std::f64::consts::PI;

use glam::{DVec2, DVec3};
use rayon::prelude::*;

use hierarchy::Hierarchy;
use refine::Refiner;
use solve::{Gathering, Leaves, Solver};
use visibility::Visibility;

use crate::geom::box_grid::{bounds, BoxGrid};
use crate::geom::polygon::strictly_inside_convex;
use crate::geom::raycast::Occluders;
use crate::mesh::elements::{append, Elements};
use crate::progress::Progress;
use crate::scene::Scene;
use crate::BakeError;

use super::IndirectResult;

/// Refinement tolerance: a link may carry up to this times `convergence` of the emitted power.
const EPS_SCALE: f64 = 1.0;
/// The solve ends when a sweep adds less than this times `convergence` of the emitted power.
const SWEEP_SCALE: f64 = 0.01;
/// Leaves of the hierarchy are groups of element triangles whose centroids lie within this
/// times `patch_size` of each other's centre.
const LEAF_RADIUS: f64 = 0.25;

/// Links allowed per leaf (plus `LINK_FLOOR`) before the bake is refused: bounds memory.
const LINKS_PER_LEAF: u64 = 400;
const LINK_FLOOR: u64 = 1 << 22;
/// A leaf, then a vertex, leaves to its links' mean visibilities at most this times
/// `convergence` of its light (`vertices`; a leaf, of its indirect light). The time it costs (user seconds, loaded machine):
/// room-78 3.48 % at 21.8, room-245 7.44 % at 119; at 400, 3.69 % at 9.1 and 7.63 % at 54;
/// with mean visibilities 4.45 % at 6.7 and 9.70 % at 19. At 200 and 400 the floor under a
/// table (`test`) is off by up to 14 % and 18 %.
const VISIBILITY_SCALE: f64 = 100.0;
/// Elements are split for indirect light (`subdivide`) where its linear interpolant errs by
/// more than this times `tolerance` of the local light: above the final gather's noise.
const SUBDIVIDE_SCALE: f64 = 3.0;
/// Cap on sweeps whatever `max_shots` says.
const MAX_SWEEPS: u64 = 1000;

/// Hierarchical radiosity over the element mesh `el` of `scene`, starting from the direct
/// irradiance `direct` (one per element vertex). Checks `progress` for cancellation while
/// refining and between sweeps.
pub fn indirect(
    scene: &Scene,
    el: &Elements,
    direct: &[DVec3],
    occ: &Occluders,
    progress: &Progress,
) -> Result<IndirectResult, BakeError> {
    let settings = &scene.settings;
    let nv = el.positions.len();
    super::check_direct(el, direct)?;
    let faces = &scene.faces;
    let covers = Covers::new(crate::indirect::coplanar_contacts::covers(
        faces,
        1e-6 * scene.diagonal(),
    ));
    let leaf_radius = LEAF_RADIUS * settings.patch_size;
    // From here on, faces include the backs of thin faces (`back`).
    let backs = back::Backs::new(scene, occ);
    let faces: &[crate::scene::Face] = &backs.faces;
    let buried = buried::Buried::new(scene, 1e-6 * scene.diagonal());
    // Decided for every triangle up front, on all threads: the hierarchy's build asks in
    // turn (room-8328: 2.5 s of one thread, perf).
    let kept: Vec<bool> = (0..el.triangles.len() as u32)
        .into_par_iter()
        .map(|t| !covered(scene, el, &covers, t) && !buried.buried(el, t))
        .collect();
    let keep = |t: u32| kept[t as usize];
    let mut h = Hierarchy::build_two_sided(faces, el, keep, leaf_radius, &backs.of);
    h.set_boxes(faces, el);
    let nl = h.order.len();
    let mut result = IndirectResult {
        patches: h.nodes.len() as u64,
        leaves: nl as u64,
        gather_vertices: nv as u64,
        irradiance: vec![DVec3::ZERO; nv],
        ..Default::default()
    };
    progress.check()?;

    let mut leaves = leaf_inputs(scene, el, direct, &h);
    back::set_direct(scene, occ, el, &h, &mut leaves.direct, progress)?;
    let emitted_power: f64 = (0..nl)
        .map(|i| {
            let b = leaves.albedo[i] * leaves.direct[i] + leaves.emitted[i];
            b.element_sum() * h.area[i]
        })
        .sum();
    if !(emitted_power > 0.0) || !emitted_power.is_finite() {
        result.bytes_per_leaf = h.bytes_per_leaf();
        return Ok(result);
    }

    h.weigh(el, &radiosity_estimate(&h, &leaves, emitted_power));
    let b_max = radiosity_bounds(&h, &leaves, emitted_power);
    let b_range = first_radiosity_range(&h, &leaves);
    let max_links = LINKS_PER_LEAF * nl as u64 + LINK_FLOOR;
    let refiner = Refiner::new(
        Visibility {
            h: &h,
            faces,
            el,
            occ,
            solid_of: &scene.face_occluder,
            occluders: &scene.occluders,
        },
        &b_max,
        &b_range,
        EPS_SCALE * settings.convergence * emitted_power,
        settings.visibility_rays,
        max_links,
        progress,
    );
    let t_refine = std::time::Instant::now();
    let mut refined = refiner.run();
    exact::fill(&h, faces, &mut refined.links);
    result.t_refine = t_refine.elapsed().as_secs_f64();
    progress.check()?;
    if refined.over_budget {
        return Err(BakeError::setting(
            "convergence",
            format!(
                "{} is too fine for this scene: over {max_links} links for {nl} elements \
                 (raise it, or raise element_size)",
                settings.convergence
            ),
        ));
    }
    result.links = refined.links.len() as u64;
    result.rays = refined.rays;
    result.hidden = refined.dropped;
    let g = Gathering::new(refined.links, h.nodes.len());
    result.bytes_per_leaf = h.bytes_per_leaf()
        + (g.links.len() * std::mem::size_of::<link::Link>() + g.start.len() * 4) as f64
            / nl.max(1) as f64;

    progress.set_fraction(0.0);
    let solver = Solver::new(&h, faces, &g);
    let max_sweeps = settings.max_shots.clamp(1, MAX_SWEEPS);
    let sol = solver.solve(
        &leaves,
        emitted_power,
        settings.convergence * SWEEP_SCALE,
        max_sweeps,
        progress,
    )?;
    result.shots = sol.sweeps;
    result.unshot_fraction = sol.last_change;
    progress.check()?;
    let b = sol.radiosity.as_ref().expect("the solve pulls at its end");
    let vis = Visibility {
        h: &h,
        faces,
        el,
        occ,
        solid_of: &scene.face_occluder,
        occluders: &scene.occluders,
    };
    let t_gather = std::time::Instant::now();
    let gather = vertices::Gather::new(
        &h,
        faces,
        el,
        &g,
        &solver,
        b,
        &vis,
        direct,
        VISIBILITY_SCALE * settings.convergence,
    );
    let gathered = gather.vertices();
    // New vertices get exact direct light but not the world's, which is sampled per vertex
    // elsewhere (`direct::world`): with world light on, the mesh stays as it is.
    let sub = if settings.world == DVec3::ZERO {
        let tol = SUBDIVIDE_SCALE * settings.tolerance;
        subdivide::subdivide(
            scene, &h, faces, el, &gather, &gathered, direct, tol, progress,
        )?
    } else {
        None
    };
    let mut at = gathered.irradiance;
    if let Some(sub) = sub {
        append(&mut at, sub.indirect.clone());
        result.subdivided = Some(sub);
    }
    result.t_gather = t_gather.elapsed().as_secs_f64();
    result.gather_rays = gather.rays();
    if settings.ambient {
        let amb = ambient(&h, &leaves, sol.last_delta);
        at.iter_mut().for_each(|e| *e += amb);
    }
    // A vertex's own look replaces its links' mean by subtracting (`vertices`): where it
    // sees none of a source, rounding can leave −1e-16 of light.
    at.iter_mut().for_each(|e| *e = e.max(DVec3::ZERO));
    result.irradiance = at;
    Ok(result)
}

/// The covers of each face (`coplanar_contacts::covers`: coplanar faces against it, facing
/// the other way), with a grid over their boxes: a floor under thousands of boxes has
/// thousands of covers, and trying each for every one of its triangles took room-8328's
/// bake 7 s on one thread.
struct Covers {
    polys: Vec<Vec<Vec<DVec2>>>,
    grids: Vec<Option<BoxGrid>>,
}

impl Covers {
    fn new(polys: Vec<Vec<Vec<DVec2>>>) -> Self {
        let grids = polys
            .iter()
            .map(|ps| {
                let boxes: Vec<(DVec2, DVec2)> = ps.iter().map(|p| bounds(p)).collect();
                (!boxes.is_empty()).then(|| BoxGrid::new(&boxes))
            })
            .collect();
        Covers { polys, grids }
    }

    /// Whether `p` (in face `f`'s frame) lies strictly inside one of its covers.
    fn hold(&self, f: usize, p: DVec2) -> bool {
        let Some(grid) = &self.grids[f] else {
            return false;
        };
        grid.at(p)
            .iter()
            .any(|&i| strictly_inside_convex(&self.polys[f][i as usize], p))
    }
}

/// Whether element triangle `t` lies under a cover of its face (its centroid inside one).
fn covered(scene: &Scene, el: &Elements, covers: &Covers, t: u32) -> bool {
    let f = el.tri_face[t as usize] as usize;
    if covers.grids[f].is_none() {
        return false;
    }
    let c = el.triangles[t as usize]
        .iter()
        .map(|&v| el.positions[v as usize])
        .sum::<DVec3>()
        / 3.0;
    covers.hold(f, scene.faces[f].frame.to_2d(c))
}

/// Per leaf position: direct irradiance (the mean of its corners'), albedo, π·Le.
fn leaf_inputs(scene: &Scene, el: &Elements, direct: &[DVec3], h: &Hierarchy) -> Leaves {
    let face = |t: u32| &scene.faces[el.tri_face[t as usize] as usize];
    let light_faces: std::collections::BTreeSet<u32> =
        scene.lights.iter().filter_map(|l| l.from_face).collect();
    Leaves {
        direct: h
            .order
            .iter()
            .map(|&t| {
                el.triangles[t as usize]
                    .iter()
                    .map(|&v| direct[v as usize])
                    .sum::<DVec3>()
                    / 3.0
            })
            .collect(),
        albedo: h.order.iter().map(|&t| face(t).albedo).collect(),
        // Emissive faces that are also area lights have sent their light as direct light.
        emitted: h
            .order
            .iter()
            .map(|&t| {
                let f = el.tri_face[t as usize];
                if light_faces.contains(&f) {
                    DVec3::ZERO
                } else {
                    PI * face(t).emission
                }
            })
            .collect(),
    }
}

/// Per node, a bound on its radiosity over the solve (channels summed), for refinement:
/// its leaves' largest first radiosity, plus its albedo times the irradiance that the
/// emitted power would give everywhere after endless bounces (light reaches shadowed
/// surfaces only by bounces, and they must refine too).
fn radiosity_bounds(h: &Hierarchy, leaves: &Leaves, emitted_power: f64) -> Vec<f64> {
    let area = h.nodes[0].area.max(1e-300);
    let bounce = emitted_power / area / (1.0 - mean_albedo(h, leaves).max_element().min(0.95));
    let mut b = vec![0.0; h.nodes.len()];
    for i in (0..h.nodes.len()).rev() {
        let n = &h.nodes[i];
        b[i] = if n.is_leaf() {
            (n.lo as usize..n.hi as usize)
                .map(|p| {
                    let first = leaves.albedo[p] * leaves.direct[p] + leaves.emitted[p];
                    first.element_sum() + leaves.albedo[p].max_element() * bounce
                })
                .fold(0.0, f64::max)
        } else {
            b[n.kids[0] as usize].max(b[n.kids[1] as usize])
        };
    }
    b
}

/// Per leaf position, an estimate of its radiosity over the solve (channels summed): its
/// first radiosity plus its albedo times the mean irradiance the bounces give a closed scene
/// (the emitted power over the area, over 1 − ρ), for `Hierarchy::weigh`.
fn radiosity_estimate(h: &Hierarchy, leaves: &Leaves, emitted_power: f64) -> Vec<f64> {
    let area = h.nodes.first().map_or(0.0, |n| n.area).max(1e-300);
    let rho = mean_albedo(h, leaves).element_sum() / 3.0;
    let bounce = emitted_power / area / (1.0 - rho).max(0.05) / 3.0;
    (0..h.order.len())
        .map(|p| {
            let first = leaves.albedo[p] * leaves.direct[p] + leaves.emitted[p];
            first.element_sum() + leaves.albedo[p].element_sum() * bounce
        })
        .collect()
}

/// Per node, how much its leaves' first radiosity (reflected direct light plus emission,
/// channels summed) varies over it: a source whose light is not uniform sends it unevenly,
/// and a mean over it misplaces that light (the bright pool under a lamp).
fn first_radiosity_range(h: &Hierarchy, leaves: &Leaves) -> Vec<f64> {
    let mut lo = vec![f64::INFINITY; h.nodes.len()];
    let mut hi = vec![f64::NEG_INFINITY; h.nodes.len()];
    for i in (0..h.nodes.len()).rev() {
        let n = &h.nodes[i];
        if n.is_leaf() {
            for p in n.lo as usize..n.hi as usize {
                let b = (leaves.albedo[p] * leaves.direct[p] + leaves.emitted[p]).element_sum();
                lo[i] = lo[i].min(b);
                hi[i] = hi[i].max(b);
            }
        } else {
            for k in n.kids {
                lo[i] = lo[i].min(lo[k as usize]);
                hi[i] = hi[i].max(hi[k as usize]);
            }
        }
    }
    lo.iter().zip(&hi).map(|(l, h)| (h - l).max(0.0)).collect()
}

/// The leaves' albedo, area-weighted (0 without area).
fn mean_albedo(h: &Hierarchy, leaves: &Leaves) -> DVec3 {
    let area = h.nodes.first().map_or(0.0, |n| n.area);
    if !(area > 0.0) {
        return DVec3::ZERO;
    }
    (0..h.order.len())
        .map(|i| leaves.albedo[i] * h.area[i])
        .sum::<DVec3>()
        / area
}

/// Cohen et al.'s ambient term for what the sweeps left: the last sweep added `delta`
/// (area-weighted mean irradiance); each later one would add about ρ times the one before.
/// The final gather at the vertices is one of those (it gathers the radiosity the last
/// sweep's irradiance gives), so what is left starts at ρ²: ρ²/(1 − ρ) times `delta`.
/// Assumes a closed scene.
fn ambient(h: &Hierarchy, leaves: &Leaves, delta: DVec3) -> DVec3 {
    let rho = mean_albedo(h, leaves).min(DVec3::splat(0.999));
    delta.max(DVec3::ZERO) * rho * rho / (DVec3::ONE - rho)
}

#[cfg(test)]
pub(crate) mod test;
