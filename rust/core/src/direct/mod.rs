//! Stage `direct` (T_direct): direct light at every element vertex, driven by the relations (paper 2.6 (1)).
//! A vertex takes the relations of the triangles around it (after the D0 split, only those
//! of its own side): umbra everywhere → nothing to do; lit everywhere → the unoccluded
//! integral; otherwise the exact visible part of the light, with only the occluders whose
//! penumbra contains one of those triangles as candidates.

pub(crate) mod back;
pub mod exact;
pub mod round;
pub mod world;

use glam::DVec3;
use rayon::prelude::*;

use crate::geom::polygon::convex_hull_2d;
use crate::geom::{Frame, Plane};
use crate::mesh::elements::Elements;
use crate::regions::relation::Relation;
use crate::regions::Region;
use crate::scene::solids::{Occluder, Solid};
use crate::scene::{LightKind, Scene, Tolerances};

/// Direct irradiance (W/m², RGB) per vertex, and the vertex×light counts
/// (umbra skipped, lit, penumbra).
pub fn direct_irradiance(
    scene: &Scene,
    tol: &Tolerances,
    el: &Elements,
    progress: &crate::Progress,
) -> Result<(Vec<DVec3>, [u64; 3]), crate::BakeError> {
    let nv = el.positions.len();
    // Regions around each vertex (CSR).
    let (count, corners) = el.corners_by_vertex();
    let around: Vec<u32> = corners
        .iter()
        .map(|&(t, _)| el.tri_region[t as usize])
        .collect();
    let simple = outlines(scene);
    progress.check()?;
    let done = std::sync::atomic::AtomicUsize::new(0);
    let results: Vec<(DVec3, [u64; 3])> = (0..nv)
        .into_par_iter()
        .map(|v| {
            let k = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            if k % 4096 == 0 {
                progress.set_fraction(k as f64 / nv as f64);
                // The memory watchdog looks only in `check`; a cancel it makes is seen
                // below, at every vertex.
                let _ = progress.check();
            }
            if progress.is_cancelled() {
                return (DVec3::ZERO, [0; 3]);
            }
            // Computed while refining the mesh (`mesh::refine`): not again.
            if let Some(known) = el.known_direct.get(v).copied().flatten() {
                return known;
            }
            let mut regions: Vec<u32> = around[count[v] as usize..count[v + 1] as usize].to_vec();
            regions.sort_unstable();
            regions.dedup();
            vertex_direct(scene, tol, el, v, &regions, &simple)
        })
        .collect();
    progress.check()?;
    let mut counts = [0u64; 3];
    let e = results
        .into_iter()
        .map(|(e, c)| {
            for k in 0..3 {
                counts[k] += c[k];
            }
            e
        })
        .collect();
    Ok((e, counts))
}

/// Where to evaluate an area light at `p` on receiver `face`: `p` itself, unless `p` lies in the
/// light's plane. That happens where a receiver meets an emissive face (`scene::emitters`):
/// a floor vertex on the foot of a glowing wall sees the wall edge-on, so no light at all,
/// where the floor a hair away gets plenty. A point a hair into the vertex's own face gives
/// the limit that the elements around it show.
fn on_light_plane(
    scene: &Scene,
    face: u32,
    p: DVec3,
    plane: &crate::geom::Plane,
    tol: &Tolerances,
) -> DVec3 {
    if plane.dist(p).abs() > tol.flat {
        return p;
    }
    let f = &scene.faces[face as usize];
    let centre = f.verts.iter().copied().sum::<DVec3>() / f.verts.len().max(1) as f64;
    let d = centre - p;
    let l = d.length();
    if !(l > 0.0) {
        return p;
    }
    p + d * (crate::geom::hair(l, 100.0 * tol.flat) / l)
}

fn vertex_direct(
    scene: &Scene,
    tol: &Tolerances,
    el: &Elements,
    v: usize,
    regions: &[u32],
    simple: &[Option<Vec<DVec3>>],
) -> (DVec3, [u64; 3]) {
    let regions: Vec<&Region> = regions.iter().map(|&r| &el.regions[r as usize]).collect();
    light_at(
        scene,
        tol,
        el.vertex_face[v],
        el.eval[v],
        el.normals[v],
        &regions,
        simple,
    )
}

/// Many-edged faces' outlines for the area-light booleans (see geom::simplify), per face.
pub(crate) fn outlines(scene: &Scene) -> Vec<Option<Vec<DVec3>>> {
    scene
        .faces
        .par_iter()
        .map(|f| crate::geom::simplify::simplified(&f.verts))
        .collect()
}

/// Direct irradiance at `p` (normal `n`) of receiver `face`, lying in or on the border of
/// `regions`, and the light counts (umbra skipped, lit, penumbra); `simple` from `outlines`.
/// Shared by the direct stage (at vertices) and by refinement to a tolerance
/// (`mesh::refine`, at any point), so that both compute one light.
pub(crate) fn light_at(
    scene: &Scene,
    tol: &Tolerances,
    face: u32,
    p: DVec3,
    n: DVec3,
    regions: &[&Region],
    simple: &[Option<Vec<DVec3>>],
) -> (DVec3, [u64; 3]) {
    let mut e = DVec3::ZERO;
    let mut counts = [0u64; 3];
    let mut occ: Vec<u32> = Vec::new();
    for (li, light) in scene.lights.iter().enumerate() {
        let rels = regions.iter().map(|r| r.relations[li]);
        let all = |want: Relation| rels.clone().all(|r| r == want);
        let relation = if regions.is_empty() || all(Relation::Umbra) {
            Relation::Umbra
        } else if all(Relation::Lit) {
            Relation::Lit
        } else {
            Relation::Penumbra
        };
        match relation {
            Relation::Umbra => {
                counts[0] += 1;
                continue;
            }
            Relation::Lit => counts[1] += 1,
            _ => counts[2] += 1,
        }
        occ.clear();
        if relation == Relation::Penumbra {
            for r in regions {
                occ.extend_from_slice(&r.blockers[li]);
            }
            occ.sort_unstable();
            occ.dedup();
        }
        // A solid hides exactly what its outline seen from p hides: one convex polygon (or,
        // failing that, its faces turned towards p).
        // A round light lights p through its disc facing p (`scene::disc`); the sun's is put
        // beyond everything in the scene.
        let disc = crate::scene::disc::facing(&light.kind, p, 2.0 * scene.diagonal());
        let light_plane = match &light.kind {
            LightKind::Area { plane, .. } => Some(*plane),
            _ => disc.as_ref().map(|d| d.plane()),
        };
        let mut owned: Vec<Vec<DVec3>> = Vec::new();
        let mut face_refs: Vec<u32> = Vec::new();
        // A point inside a closed solid (a receiver passing through it) sees no light. The
        // margin keeps points on a solid's surface (contacts) outside.
        let margin = tol.flat;
        let buried = occ.iter().any(|&o| match &scene.occluders[o as usize] {
            Occluder::Solid { solid, .. } => solid.planes.iter().all(|f| f.dist(p) < -margin),
            Occluder::Face(_) => false,
        });
        if buried {
            continue;
        }
        for &o in &occ {
            match &scene.occluders[o as usize] {
                Occluder::Face(f) => face_refs.push(*f),
                Occluder::Solid { faces, solid } => {
                    match light_plane.and_then(|lp| solid_outline(p, solid, &lp)) {
                        Some(poly) => owned.push(poly),
                        None => face_refs.extend(
                            faces
                                .iter()
                                .copied()
                                .filter(|&f| scene.faces[f as usize].plane.dist(p) > 0.0),
                        ),
                    }
                }
            }
        }
        let polys: Vec<&[DVec3]> = face_refs
            .iter()
            .map(|&f| scene.faces[f as usize].verts.as_slice())
            .chain(owned.iter().map(|v| v.as_slice()))
            .collect();
        let simple_polys: Vec<&[DVec3]> = face_refs
            .iter()
            .map(|&f| {
                simple[f as usize]
                    .as_deref()
                    .unwrap_or(scene.faces[f as usize].verts.as_slice())
            })
            .chain(owned.iter().map(|v| v.as_slice()))
            .collect();
        let area_at = match &light.kind {
            LightKind::Area { plane, .. } => on_light_plane(scene, face, p, plane, tol),
            _ => p,
        };
        e += light_irradiance(
            scene,
            light,
            p,
            area_at,
            n,
            relation,
            &polys,
            &simple_polys,
            disc.as_ref(),
        );
    }
    (e, counts)
}

/// One light's irradiance at `p` (unit normal `n`) for `relation`: `polys` are the convex
/// occluders that may hide it (`simple_polys` the same with many-edged outlines simplified,
/// for the area-light booleans), `disc` a round light's disc facing `p`, and `area_at` where
/// an area light is evaluated (`on_light_plane`). Shared with the backs of thin faces
/// (`back`), which have no relations.
#[allow(clippy::too_many_arguments)]
pub(crate) fn light_irradiance(
    scene: &Scene,
    light: &crate::scene::Light,
    p: DVec3,
    area_at: DVec3,
    n: DVec3,
    relation: Relation,
    polys: &[&[DVec3]],
    simple_polys: &[&[DVec3]],
    disc: Option<&crate::scene::disc::Disc>,
) -> DVec3 {
    match &light.kind {
        LightKind::Area {
            verts,
            plane,
            radiance,
        } => exact::area_light(
            area_at,
            n,
            verts,
            plane,
            *radiance,
            relation,
            simple_polys,
            scene.settings.penumbra_visibility,
            scene.settings.penumbra_samples,
        ),
        LightKind::Point {
            position,
            intensity,
            spot,
            ..
        } => match disc {
            Some(d) => match spot {
                Some(s) => round::round_spot(
                    p,
                    n,
                    &light.kind,
                    d,
                    s,
                    *position,
                    relation,
                    simple_polys,
                    scene.settings.penumbra_visibility,
                    scene.settings.penumbra_samples,
                ),
                None => round_light(p, n, &light.kind, d, relation, simple_polys, scene),
            },
            None => exact::point_light(p, n, *position, *intensity, spot.as_ref(), relation, polys),
        },
        LightKind::Sun {
            direction,
            irradiance,
            ..
        } => match disc {
            Some(d) => round_light(p, n, &light.kind, d, relation, simple_polys, scene),
            None => exact::sun_light(p, n, *direction, *irradiance, relation, polys),
        },
    }
}

/// [`round::round_light`] with the scene's penumbra settings.
fn round_light(
    p: DVec3,
    n: DVec3,
    kind: &LightKind,
    disc: &crate::scene::disc::Disc,
    relation: Relation,
    blockers: &[&[DVec3]],
    scene: &Scene,
) -> DVec3 {
    round::round_light(
        p,
        n,
        kind,
        disc,
        relation,
        blockers,
        scene.settings.penumbra_visibility,
        scene.settings.penumbra_samples,
    )
}

/// The outline of a convex solid seen from `p`, as a convex polygon in a plane parallel to
/// the light halfway between p and the light: a segment from p to a light point crosses it
/// exactly when it crosses the solid. `None` when the outline does not reach that plane
/// (part of the solid is no nearer the light than p).
fn solid_outline(p: DVec3, s: &Solid, lplane: &Plane) -> Option<Vec<DVec3>> {
    let dp = lplane.dist(p);
    if !(dp > 0.0) {
        return None;
    }
    let front: Vec<bool> = s.planes.iter().map(|f| f.dist(p) > 0.0).collect();
    if !front.iter().any(|&f| f) {
        return None;
    }
    // A solid reaching through the light's plane: only its part in front of the light
    // blocks, which its outline does not tell.
    if s.verts.iter().any(|v| !(lplane.dist(*v) > 0.0)) {
        return None;
    }
    let h = 0.5 * dp;
    let frame = Frame::new(p - lplane.n * (dp - h), lplane.n);
    let mut pts = Vec::new();
    for (e, fp) in s.edges.iter().zip(&s.edge_planes) {
        if front[fp[0] as usize] == front[fp[1] as usize] {
            continue;
        }
        for &vi in e {
            let v = s.verts[vi as usize];
            let dv = lplane.dist(v);
            if dv >= dp * (1.0 - 1e-9) {
                return None;
            }
            let t = (dp - h) / (dp - dv);
            pts.push(frame.to_2d(p + (v - p) * t));
        }
    }
    let hull = convex_hull_2d(&pts);
    (hull.len() >= 3).then(|| hull.into_iter().map(|q| frame.to_3d(q)).collect())
}
