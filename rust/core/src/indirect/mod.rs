//! Stage 7: indirect light by progressive refinement (Cohen, Chen, Wallace & Greenberg 1988),
//! as in the paper's §2.6: the patch with the most unshot power shoots it to every element
//! vertex that can see it, until what is left is a small fraction of what was emitted.
//!
//! Units follow `DESIGN.md`: irradiance E and radiosity B in W/m² per RGB channel; a face's
//! `emission` is radiance, so it leaves the face as radiosity π·Le.
//!
//! Form factors are exact point-to-polygon integrals (Lambert's formula) times a visible
//! fraction from rays to stratified points on the patch, each ray weighted by its own
//! point-to-point form factor. Most pairs need no rays: a face can only be in the way if it
//! pokes out in front of both the shooter's and the receiver's planes inside the box around
//! the shooter and a group of receiver vertices ([`Occluders::candidates`]), and its plane
//! has the shooter and the group on opposite sides ([`Occluders::straddled_by`]), which for
//! convex objects and floors is never. Rays to far patches are fewer (1 or ~4). Far groups
//! with nothing in the way take the factor from an interpolant checked against exact values
//! (`fit`). Shots are parallel over receiver vertices; each vertex's value is computed
//! alone and added in a fixed order, so results do not depend on the thread count.
//!
//! Light is computed at a subset of the element vertices and interpolated at the others
//! (`gather`, by moving least squares: `mls`): the elements are as fine as direct light
//! needs, and indirect light is smooth across a penumbra.
//!
//! Files: `shooter` (a shot and its kept factors), `blockers` (what could be in the way),
//! `receiver` (one vertex's factor), `fit` (far groups), `gather` and `mls` (which
//! vertices, and the rest from them).

mod back;
mod blockers;
pub(crate) mod coplanar_contacts;
mod fit;
mod gather;
pub mod hierarchical;
mod mls;
mod pair;
pub(crate) mod patches;
mod receiver;
mod shooter;

use std::f64::consts::PI;

use glam::DVec3;
use rayon::prelude::*;

use gather::Gather;
#[cfg(test)]
use receiver::form_factor;
use shooter::Shooter;

use crate::geom::raycast::Occluders;
use crate::indirect::patches::{build_patches, Patch};
use crate::mesh::elements::Elements;
use crate::progress::Progress;
use crate::scene::settings::IndirectSolver;
use crate::scene::Scene;
use crate::BakeError;

#[derive(Debug, Clone, Default, PartialEq)]
pub struct IndirectResult {
    /// Indirect irradiance (W/m², RGB) at each element vertex: everything that arrives after
    /// at least one diffuse bounce, plus what emissive faces send.
    pub irradiance: Vec<DVec3>,
    pub patches: u64,
    /// Element vertices at which indirect light was computed; the rest interpolate.
    pub gather_vertices: u64,
    pub shots: u64,
    /// Unshot power left at the end over the power emitted (reflected direct light plus
    /// emission), before any ambient term. For the hierarchical solver, the power the last
    /// sweep added, over the power emitted.
    pub unshot_fraction: f64,
    /// Hierarchical solver only: links after refinement, leaves (element triangles not
    /// under a cover, and again for each back of a thin face), visibility rays cast while
    /// refining, and memory of the hierarchy and links per leaf in bytes.
    pub links: u64,
    pub leaves: u64,
    pub rays: u64,
    pub bytes_per_leaf: f64,
    /// Hierarchical solver only: pairs from planar sources that refinement dropped because
    /// all their rays were blocked (after a second look); seconds spent refining links and
    /// in the final gather at the vertices.
    pub hidden: u64,
    pub t_refine: f64,
    pub t_gather: f64,
    /// Hierarchical solver only: visibility rays the final gather cast (leaves' and
    /// vertices' own looks at their links' sources).
    pub gather_rays: u64,
    /// Hierarchical solver only: the element mesh split where indirect light curves, with
    /// `irradiance` then per vertex of that mesh.
    pub subdivided: Option<hierarchical::subdivide::Subdivided>,
}

/// Patches whose apparent size (radius over distance) falls under these use 1 or ~4 rays
/// instead of `visibility_rays`: a far patch is seen nearly all or nothing.
const FEW_RAYS_BELOW: f64 = 0.15;
const ONE_RAY_BELOW: f64 = 0.06;
/// Candidate occluder lists longer than this are handed to the BVH instead.
const MAX_LISTED_OCCLUDERS: usize = 24;
/// Per shooter face, candidate lists (for all its patches) longer than this are not kept:
/// each group of receiver vertices asks the BVH for its own, which beats sifting a long
/// list once per group.
const MAX_FACE_OCCLUDERS: usize = 64;
/// Face ids kept in those lists over the whole bake (4 bytes each).
const FACE_OCCLUDER_BUDGET: usize = 1 << 24;
/// Form factors kept for repeat shots, over the whole bake, in 4-byte units (256 MB at
/// most): a vertex's factor is one, a run of vertices two, a receiving patch's gain four.
/// A closed room of 24k vertices and 2.6k patches keeps about 41M.
const FACTOR_BUDGET: usize = 1 << 26;
/// Indirect light is computed at vertices about this many element sizes apart and
/// interpolated between (`gather`).
const GATHER_SPACING: f64 = 1.0;
/// Receiver vertices per parallel work item.
const CHUNK: usize = 256;

/// Progressive-refinement radiosity over the element mesh `el` of `scene`, starting from
/// the direct irradiance `direct` (one per element vertex). Checks `progress` for
/// cancellation between shots.
pub fn indirect(
    scene: &Scene,
    el: &Elements,
    direct: &[DVec3],
    occ: &Occluders,
    progress: &Progress,
) -> Result<IndirectResult, BakeError> {
    if scene.settings.indirect_solver == IndirectSolver::Hierarchical {
        return hierarchical::indirect(scene, el, direct, occ, progress);
    }
    let spacing = GATHER_SPACING * scene.settings.element_size;
    indirect_at(scene, el, direct, occ, progress, spacing)
}

/// One direct irradiance per element vertex, or an error naming the stage.
fn check_direct(el: &Elements, direct: &[DVec3]) -> Result<(), BakeError> {
    let nv = el.positions.len();
    if direct.len() != nv {
        return Err(BakeError::invalid(
            "indirect",
            "direct",
            format!("{} values for {nv} element vertices", direct.len()),
        ));
    }
    Ok(())
}

/// `indirect`, computed at vertices about `spacing` apart (every vertex for 0).
fn indirect_at(
    scene: &Scene,
    el: &Elements,
    direct: &[DVec3],
    occ: &Occluders,
    progress: &Progress,
    spacing: f64,
) -> Result<IndirectResult, BakeError> {
    let settings = &scene.settings;
    let nv = el.positions.len();
    check_direct(el, direct)?;
    let cover_tol = 1e-6 * scene.diagonal();
    let covers = crate::indirect::coplanar_contacts::covers(&scene.faces, cover_tol);
    let open = crate::indirect::coplanar_contacts::open_parts_of(&scene.faces, &covers, cover_tol);
    let mut patches = build_patches(
        &scene.faces,
        &open,
        el,
        settings.patch_size,
        settings.visibility_rays,
        progress,
    )?;
    let albedo = |p: &Patch| scene.faces[p.face as usize].albedo;
    // Emissive faces that are also area lights have sent their light as direct light.
    let mut emission: Vec<DVec3> = scene.faces.iter().map(|f| f.emission).collect();
    for l in &scene.lights {
        if let Some(f) = l.from_face {
            emission[f as usize] = DVec3::ZERO;
        }
    }
    // The backs of thin faces (`back`) come after every front.
    let fronts = patches.len();
    let two_sided = back::two_sided(scene, &emission, occ.tolerance());
    patches.extend(back::back_patches(
        scene,
        &two_sided,
        el,
        settings.patch_size,
        settings.visibility_rays,
    ));
    progress.check()?;
    let back_direct = back::back_direct(scene, occ, &patches[fronts..], progress)?;
    let mut unshot: Vec<DVec3> = patches
        .iter()
        .map(|p| albedo(p) * mean(&p.weights, direct) + PI * emission[p.face as usize])
        .collect();
    for (u, (p, e)) in unshot[fronts..]
        .iter_mut()
        .zip(patches[fronts..].iter().zip(&back_direct))
    {
        *u += albedo(p) * *e;
    }
    let power = |b: DVec3, p: &Patch| b.element_sum() * p.area;
    let emitted: f64 = unshot.iter().zip(&patches).map(|(b, p)| power(*b, p)).sum();
    let mut irradiance = vec![DVec3::ZERO; nv];
    let mut result = IndirectResult {
        patches: patches.len() as u64,
        ..Default::default()
    };
    if !(emitted > 0.0) || !emitted.is_finite() {
        result.irradiance = irradiance;
        return Ok(result);
    }

    // D0-row copies sit at least 1e-9 of the scene off their line (`mesh`), so a tenth of
    // that tells their side from the line itself.
    let gather = Gather::new(&scene.faces, &covers, el, spacing, 1e-10 * scene.diagonal());
    result.gather_vertices = gather.kept_count() as u64;
    let shooter = Shooter::new(scene, el, &patches, occ, emitted, &gather);
    // Radiosity shot so far by each patch whose factors are kept.
    let mut shot_total = vec![DVec3::ZERO; patches.len()];
    // Radiosity shot so far by each patch, for vertices computed at the end.
    let mut shot_all = vec![DVec3::ZERO; patches.len()];
    let mut remaining;
    loop {
        progress.check()?;
        let mut best = 0;
        remaining = 0.0;
        for (i, (b, p)) in unshot.iter().zip(&patches).enumerate() {
            let w = power(*b, p);
            remaining += w;
            if w > power(unshot[best], &patches[best]) {
                best = i;
            }
        }
        let fraction = remaining / emitted;
        let by_energy = (fraction.max(1e-300).ln() / settings.convergence.ln()).clamp(0.0, 1.0);
        progress
            .set_fraction(by_energy.max(result.shots as f64 / settings.max_shots.max(1) as f64));
        if fraction < settings.convergence || result.shots >= settings.max_shots {
            break;
        }

        let b = std::mem::take(&mut unshot[best]);
        shot_all[best] += b;
        // A kept patch's repeat shots are added once, at the end (`add_kept`).
        let (factors, exact) = shooter.factors(best, b);
        match exact {
            Some(g) => shooter.add_to(&factors, &g, b, &mut irradiance),
            None => shot_total[best] += b,
        }
        for &(q, m) in &factors.to_patches {
            unshot[q as usize] += albedo(&patches[q as usize]) * b * m;
        }
        result.shots += 1;
    }
    shooter.add_kept(&shot_total, &mut irradiance);
    let unsure = gather.spread(&mut irradiance);
    let exact: Vec<DVec3> = unsure
        .par_iter()
        .map(|&v| shooter.gathered(v, &shot_all))
        .collect();
    for (&v, e) in unsure.iter().zip(exact) {
        irradiance[v as usize] = e;
    }
    result.gather_vertices += unsure.len() as u64;
    result.unshot_fraction = remaining / emitted;

    if settings.ambient {
        let amb = ambient(&patches, &unshot, |p| albedo(p));
        irradiance.iter_mut().for_each(|e| *e += amb);
    }
    result.irradiance = irradiance;
    Ok(result)
}

/// Cohen et al.'s ambient term: the unshot radiosity, averaged over the scene's area, after
/// endless bounces off a surface of the average reflectance. Assumes a closed scene; in an
/// open one part of that light would escape, so this overestimates.
fn ambient(patches: &[Patch], unshot: &[DVec3], albedo: impl Fn(&Patch) -> DVec3) -> DVec3 {
    let area: f64 = patches.iter().map(|p| p.area).sum();
    if !(area > 0.0) {
        return DVec3::ZERO;
    }
    let rho = patches.iter().map(|p| albedo(p) * p.area).sum::<DVec3>() / area;
    let u = unshot
        .iter()
        .zip(patches)
        .map(|(b, p)| *b * p.area)
        .sum::<DVec3>()
        / area;
    // A white scene would bounce forever; cap the series at a thousand bounces.
    u / (DVec3::ONE - rho.min(DVec3::splat(0.999)))
}

fn mean<T>(weights: &[(u32, f64)], values: &[T]) -> T
where
    T: Copy + std::ops::Mul<f64, Output = T> + std::iter::Sum,
{
    weights.iter().map(|&(v, w)| values[v as usize] * w).sum()
}

#[cfg(test)]
pub(crate) mod test;
