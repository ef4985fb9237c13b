//! Stage `shadows` (paper 2.1–2.2; T_sdw, T_isr): discontinuity edges. Every shadow volume is intersected with the
//! receivers it can reach (found through a box tree, never all pairs); on a receiver the
//! intersection is a convex polygon in the receiver's 2-D frame, whose edges are the
//! discontinuity edges.

pub mod buried;
pub mod critical_lines;
pub mod culling;
pub mod gaps;
pub mod plane_cuts;
pub mod polygons;
pub mod round;
pub mod spot_cone;
pub mod umbra_pruning;
pub mod volume;

use glam::{DVec2, DVec3};
use rayon::prelude::*;

use crate::geom::bvh::{Aabb, BoxTree};
use crate::geom::polygon::{clip_polygon_3d, inside_convex, signed_area_2d};
use crate::scene::solids::Occluder;
use crate::scene::{Face, LightKind, Scene, Tolerances};
use crate::shadows::critical_lines::critical_segments;
use crate::shadows::culling::{screen_faces, screened};
use crate::shadows::plane_cuts::{solid_lines, unlit_solid_lines};
use crate::shadows::volume::{
    clip_to_volume, shadow_volumes, solid_volumes, ShadowVolumes, SolidShadow, Volume,
};
pub use polygons::{Exposure, ReceiverShadows, ShadowPolygon, BEHIND_LIGHT};

/// The light as the receiver's front half-space sees it: `None` when it is wholly behind.
fn light_in_front(kind: &LightKind, r: &Face, eps: f64) -> Option<Option<Vec<DVec3>>> {
    match kind {
        LightKind::Area { verts, .. } => {
            let clipped = clip_polygon_3d(verts, &r.plane, eps);
            if clipped.len() < 3 || clipped.iter().all(|v| r.plane.dist(*v) <= eps) {
                return None;
            }
            if clipped.len() == verts.len() && clipped.iter().zip(verts).all(|(a, b)| a == b) {
                Some(None)
            } else {
                Some(Some(clipped))
            }
        }
        LightKind::Point {
            position, radius, ..
        } => (r.plane.dist(*position) > eps - radius).then_some(None),
        LightKind::Sun {
            direction,
            half_angle,
            ..
        } => (r.plane.n.dot(*direction) < half_angle.sin()).then_some(None),
    }
}

/// Stage timings and counts for `Stats`.
#[derive(Debug, Clone, Default)]
pub struct EdgeStats {
    pub shadow_pairs: u64,
    pub culled_pairs: u64,
    pub t_sdw: f64,
    pub t_isr: f64,
}

/// Shadow volumes of occluder `oi` under one light (a solid that cannot be treated whole
/// falls back to its faces, all under the solid's index).
fn occluder_volumes(
    kind: &LightKind,
    lv: Option<&[DVec3]>,
    oi: u32,
    occ: &Occluder,
    faces: &[Face],
    eps: f64,
) -> Vec<ShadowVolumes> {
    match occ {
        Occluder::Face(f) => shadow_volumes(kind, lv, oi, &faces[*f as usize], eps)
            .into_iter()
            .collect(),
        Occluder::Solid { faces: fs, solid } => match solid_volumes(kind, lv, oi, solid, eps) {
            SolidShadow::Culled => Vec::new(),
            SolidShadow::Volumes(v) => vec![v],
            SolidShadow::Faces => fs
                .iter()
                .filter_map(|f| shadow_volumes(kind, lv, oi, &faces[*f as usize], eps))
                .collect(),
        },
    }
}

/// Vertices and edges of an occluder (for culling against a receiver and finding contacts).
fn occluder_outline(occ: &Occluder, faces: &[Face]) -> (Vec<DVec3>, Vec<[DVec3; 2]>) {
    match occ {
        Occluder::Face(f) => {
            let v = &faces[*f as usize].verts;
            (
                v.clone(),
                (0..v.len()).map(|i| [v[i], v[(i + 1) % v.len()]]).collect(),
            )
        }
        Occluder::Solid { solid, .. } => (
            solid.verts.clone(),
            solid
                .edges
                .iter()
                .map(|e| [solid.verts[e[0] as usize], solid.verts[e[1] as usize]])
                .collect(),
        ),
    }
}

/// The faces with many-edged ones replaced by their simplified outlines (`geom::simplify`),
/// or `None` when no face has one.
fn simplified_occluders(faces: &[Face]) -> Option<Vec<Face>> {
    let simple: Vec<Option<Vec<DVec3>>> = faces
        .par_iter()
        .map(|f| crate::geom::simplify::simplified(&f.verts))
        .collect();
    if simple.iter().all(Option::is_none) {
        return None;
    }
    Some(
        faces
            .iter()
            .zip(simple)
            .map(|(f, s)| match s {
                Some(verts) => {
                    let poly2 = verts.iter().map(|v| f.frame.to_2d(*v)).collect();
                    Face {
                        verts,
                        poly2,
                        ..f.clone()
                    }
                }
                None => f.clone(),
            })
            .collect(),
    )
}

/// Shadow polygons on every receiver for every light.
pub fn shadow_polygons(
    scene: &Scene,
    tol: &Tolerances,
    progress: &crate::Progress,
) -> Result<(Vec<ReceiverShadows>, EdgeStats), crate::BakeError> {
    let eps = tol.eps;
    let faces = &scene.faces;
    let occs = &scene.occluders;
    let tree = BoxTree::new(faces.iter().map(|f| Aabb::from_points(&f.verts)).collect());
    let outlines: Vec<(Vec<DVec3>, Vec<[DVec3; 2]>)> =
        occs.iter().map(|o| occluder_outline(o, faces)).collect();
    let buried = crate::shadows::buried::burial(scene, eps);
    let simple_faces = simplified_occluders(faces);
    let mut stats = EdgeStats::default();
    let mut per_receiver: Vec<ReceiverShadows> = (0..faces.len())
        .map(|i| ReceiverShadows {
            face: i as u32,
            exposure: vec![Exposure::Regions; scene.lights.len()],
            polys: Vec::new(),
            contacts: Vec::new(),
            plane_cuts: Vec::new(),
            inside: Vec::new(),
            events: Vec::new(),
            gaps: Vec::new(),
            gap_parts: Vec::new(),
        })
        .collect();

    for (li, light) in scene.lights.iter().enumerate() {
        progress.check()?;
        progress.set_fraction(li as f64 / scene.lights.len() as f64);
        let t0 = std::time::Instant::now();
        // Under an area light a many-edged occluder casts its simplified outline's shadow
        // (`geom::simplify`): the same outline the direct stage subtracts from the light, so
        // the mesh follows the field that is computed. A hard shadow stays exact: there the
        // outline is the D0 edge itself.
        let occ_faces: &[Face] = match (&light.kind, &simple_faces) {
            (LightKind::Area { .. }, Some(f)) => f,
            _ => faces,
        };
        let verts: Vec<Vec<DVec3>> = outlines.iter().map(|o| o.0.clone()).collect();
        let proxies = round::Proxies::new(scene, &light.kind, &verts);
        let volumes: Vec<Vec<ShadowVolumes>> = occs
            .par_iter()
            .enumerate()
            .map(|(oi, o)| {
                if buried.occluders[oi] || progress.is_cancelled() {
                    return Vec::new();
                }
                match proxies.as_ref().map(|p| p.get(oi as u32)) {
                    Some(round::Stand::Disc(k)) => {
                        occluder_volumes(k, None, oi as u32, o, faces, eps)
                    }
                    Some(round::Stand::Cube(ks)) => ks
                        .iter()
                        .flat_map(|k| occluder_volumes(k, None, oi as u32, o, faces, eps))
                        .map(|v| ShadowVolumes { umbra: None, ..v })
                        .collect(),
                    // Too near a round light for a proxy: its penumbra may be anywhere.
                    Some(round::Stand::Everywhere) => vec![ShadowVolumes {
                        occluder: oi as u32,
                        penumbra: vec![Volume::default()],
                        umbra: None,
                        hard: false,
                    }],
                    None => occluder_volumes(&light.kind, None, oi as u32, o, occ_faces, eps),
                }
            })
            .collect();
        stats.shadow_pairs += volumes.iter().filter(|v| !v.is_empty()).count() as u64;
        stats.culled_pairs += volumes.iter().filter(|v| v.is_empty()).count() as u64;
        // Which receivers each volume can reach, inverted to receiver → occluders.
        let mut hits: Vec<Vec<u32>> = vec![Vec::new(); faces.len()];
        let found: Vec<Vec<u32>> = volumes
            .par_iter()
            .map(|vs| {
                let mut out = Vec::new();
                for v in vs {
                    for p in &v.penumbra {
                        tree.query_volume(p.query_planes(), eps, &mut out);
                    }
                }
                out.sort_unstable();
                out.dedup();
                out
            })
            .collect();
        let light_points: Vec<DVec3> = match &light.kind {
            LightKind::Area { verts, .. } => verts.clone(),
            LightKind::Point { position, .. } => vec![*position],
            LightKind::Sun { .. } => Vec::new(),
        };
        let screens: Vec<Vec<u32>> = found
            .par_iter()
            .enumerate()
            .map(|(oi, rs)| {
                let own = |f: u32| scene.face_occluder[f as usize] as usize == oi;
                let light_points = match proxies.as_ref().map(|p| p.get(oi as u32)) {
                    Some(round::Stand::Disc(LightKind::Area { verts, .. })) => verts.as_slice(),
                    Some(_) => &[],
                    None => light_points.as_slice(),
                };
                screen_faces(light_points, &outlines[oi].0, rs, faces, own, eps)
            })
            .collect();
        for (oi, rs) in found.iter().enumerate() {
            for &r in rs {
                if scene.face_occluder[r as usize] as usize != oi
                    && !screened(&faces[r as usize], &screens[oi], faces, eps)
                {
                    hits[r as usize].push(oi as u32);
                }
            }
        }
        stats.t_sdw += t0.elapsed().as_secs_f64();

        let t1 = std::time::Instant::now();
        let results: Vec<OnReceiver> = faces
            .par_iter()
            .enumerate()
            .map(|(ri, r)| {
                // A cancelled bake skips the rest of the receivers (checked after the loop).
                if buried.faces[ri] || progress.is_cancelled() {
                    return OnReceiver::hidden();
                }
                receiver_polygons(
                    li as u32,
                    &light.kind,
                    r,
                    scene,
                    occ_faces,
                    &outlines,
                    &volumes,
                    &hits[ri],
                    tol,
                    proxies.as_ref(),
                )
            })
            .collect();
        progress.check()?;
        for (ri, res) in results.into_iter().enumerate() {
            per_receiver[ri].exposure[li] = res.exposure;
            per_receiver[ri].polys.extend(res.polys);
            per_receiver[ri]
                .events
                .extend(res.events.into_iter().map(|e| (li as u32, e)));
            let pr = &mut per_receiver[ri];
            for c in res.contacts {
                if !pr.contacts.contains(&c) {
                    pr.contacts.push(c);
                }
            }
            // Cuts are the same under every light; a light only decides which are found.
            for c in res.plane_cuts {
                if !pr.plane_cuts.contains(&c) {
                    pr.plane_cuts.push(c);
                }
            }
            for p in res.inside {
                if !pr.inside.contains(&p) {
                    pr.inside.push(p);
                }
            }
        }
        stats.t_isr += t1.elapsed().as_secs_f64();
    }
    let t2 = std::time::Instant::now();
    if scene.settings.indirect {
        unlit_solid_lines(
            scene,
            &tree,
            &outlines,
            tol,
            &buried.faces,
            &mut per_receiver,
        );
        crate::shadows::gaps::gap_lines(scene, &tree, tol, &buried.faces, &mut per_receiver);
    }
    per_receiver.par_iter_mut().for_each(|r| {
        if progress.is_cancelled() {
            return;
        }
        crate::shadows::umbra_pruning::drop_covered(&mut r.polys, &r.inside);
    });
    stats.t_isr += t2.elapsed().as_secs_f64();
    progress.check()?;
    Ok((per_receiver, stats))
}

/// What one light leaves on one receiver.
struct OnReceiver {
    exposure: Exposure,
    polys: Vec<ShadowPolygon>,
    contacts: Vec<[DVec2; 2]>,
    plane_cuts: Vec<[DVec2; 2]>,
    inside: Vec<Vec<DVec2>>,
    events: Vec<[DVec2; 2]>,
}

impl OnReceiver {
    fn hidden() -> Self {
        OnReceiver {
            exposure: Exposure::Hidden,
            polys: Vec::new(),
            contacts: Vec::new(),
            plane_cuts: Vec::new(),
            inside: Vec::new(),
            events: Vec::new(),
        }
    }
}

#[allow(clippy::too_many_arguments)]
fn receiver_polygons(
    li: u32,
    kind: &LightKind,
    r: &Face,
    scene: &Scene,
    occ_faces: &[Face],
    outlines: &[(Vec<DVec3>, Vec<[DVec3; 2]>)],
    volumes: &[Vec<ShadowVolumes>],
    hits: &[u32],
    tol: &Tolerances,
    proxies: Option<&round::Proxies>,
) -> OnReceiver {
    let eps = tol.eps;
    let Some(clipped_light) = light_in_front(kind, r, eps) else {
        return OnReceiver::hidden();
    };
    let mut out = Vec::new();
    let mut contacts = Vec::new();
    let mut plane_cuts = Vec::new();
    let mut inside = Vec::new();
    let mut events = Vec::new();
    if let LightKind::Area { plane, .. } = kind {
        // Points of the receiver behind the light's plane get nothing from it.
        if let Some(poly) = clip_to_volume(
            r,
            &Volume {
                planes: vec![plane.flipped()],
                cap: 0,
            },
            eps,
        ) {
            if (signed_area_2d(&poly) - r.area).abs() <= 1e-12 * r.area {
                return OnReceiver::hidden();
            }
            out.push(ShadowPolygon {
                light: li,
                occluder: BEHIND_LIGHT,
                umbra: true,
                hard: false,
                poly,
            });
        }
    }
    for &oi in hits {
        solid_lines(
            r,
            oi,
            scene,
            outlines,
            tol,
            &mut contacts,
            &mut plane_cuts,
            &mut inside,
        );
    }
    for &oi in hits {
        if outlines[oi as usize]
            .0
            .iter()
            .all(|v| r.plane.dist(*v) <= eps)
        {
            continue;
        }
        // A shadow that falls wholly inside solids on this receiver decides nothing
        // (`umbra_cover::drop_covered` would drop it); nor do the critical lines in it. The
        // shadow under the light cut down to the receiver's front lies inside it.
        let whole = volumes[oi as usize]
            .iter()
            .flat_map(|sv| &sv.penumbra)
            .filter_map(|p| clip_to_volume(r, p, eps));
        if whole.into_iter().all(|p| {
            inside
                .iter()
                .any(|q: &Vec<DVec2>| p.iter().all(|&v| inside_convex(q, v)))
        }) {
            continue;
        }
        let recomputed;
        // A round light's proxy disc (`round`), cut to this receiver's front like an area
        // light: the part behind holds no ray from the receiver to the round light.
        let (kind, clipped_light) = match proxies.map(|p| p.get(oi)) {
            Some(round::Stand::Disc(pk)) => match light_in_front(pk, r, eps) {
                None => continue,
                Some(c) => (pk, c),
            },
            _ => (kind, clipped_light.clone()),
        };
        let svs: &[ShadowVolumes] = match &clipped_light {
            None => &volumes[oi as usize],
            Some(lv) => {
                recomputed = occluder_volumes(
                    kind,
                    Some(lv),
                    oi,
                    &scene.occluders[oi as usize],
                    occ_faces,
                    eps,
                );
                &recomputed
            }
        };
        for sv in svs {
            for p in &sv.penumbra {
                if let Some(poly) = clip_to_volume(r, p, eps) {
                    if let (LightKind::Area { verts, plane, .. }, false, None) =
                        (kind, sv.hard, proxies)
                    {
                        let lv = clipped_light.as_deref().unwrap_or(verts);
                        let occ = &scene.occluders[oi as usize];
                        critical_segments(lv, plane, occ, occ_faces, r, &poly, tol, &mut events);
                    }
                    // Point/sun: the one volume is umbra and penumbra at once.
                    out.push(ShadowPolygon {
                        light: li,
                        occluder: oi,
                        umbra: sv.hard,
                        hard: sv.hard,
                        poly,
                    });
                }
            }
            if let (Some(u), false) = (&sv.umbra, sv.hard) {
                if let Some(poly) = clip_to_volume(r, u, eps) {
                    out.push(ShadowPolygon {
                        light: li,
                        occluder: oi,
                        umbra: true,
                        hard: false,
                        poly,
                    });
                }
            }
        }
    }
    if let LightKind::Point {
        position,
        spot: Some(spot),
        radius,
        ..
    } = kind
    {
        let band = scene.settings.penumbra_element_size;
        spot_cone::cone_edges(*position, spot, *radius, r, band, &mut events);
    }
    OnReceiver {
        exposure: Exposure::Regions,
        polys: out,
        contacts,
        plane_cuts,
        inside,
        events,
    }
}
