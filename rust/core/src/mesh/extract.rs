//! From the triangulation to the element mesh: triangles, their regions, the D0 vertex rows
//! split apart, the frame's and flat triangles left out.

use glam::{DVec2, DVec3};
use rayon::prelude::*;
use spade::handles::FixedUndirectedEdgeHandle;
use spade::Triangulation;

use super::sides::{nudge, sides, D0Test, Edge, Face};
use super::{Cdt, ReceiverMesh};
use crate::geom::Frame;
use crate::regions::{ReceiverRegions, Region};
use crate::scene::Tolerances;

/// Connected components of a triangulation's inner faces across edges that are not
/// constraints, each classified once: `comp` per inner face (spade's face index − 1).
pub(super) struct Components {
    pub comp: Vec<u32>,
    pub regions: Vec<Region>,
    /// Components that reach the hull across an edge that is not a constraint lie outside
    /// the receiver, between its boundary and the frame refinement puts around it.
    pub outside: Vec<bool>,
}

/// The components of `cdt`, each classified at the centre of its largest triangle.
pub(super) fn components(cdt: &Cdt, shift: DVec2, rr: &ReceiverRegions) -> Components {
    let faces: Vec<_> = cdt.inner_faces().collect();
    let mut comp = vec![u32::MAX; faces.len()];
    // The largest triangle of each component, whose centre is classified.
    let mut largest: Vec<usize> = Vec::new();
    let mut outside: Vec<bool> = Vec::new();
    for start in 0..faces.len() {
        if comp[start] != u32::MAX {
            continue;
        }
        let id = largest.len() as u32;
        let mut stack = vec![start];
        comp[start] = id;
        let mut best = (0.0f64, start);
        let mut out = false;
        while let Some(i) = stack.pop() {
            let area = faces[i].area();
            if area > best.0 {
                best = (area, i);
            }
            for e in faces[i].adjacent_edges() {
                if e.is_constraint_edge() {
                    continue;
                }
                if e.rev().face().is_outer() {
                    out = true;
                }
                if let Some(nb) = e.rev().face().as_inner() {
                    let j = face_index(nb.fix());
                    if comp[j] == u32::MAX {
                        comp[j] = id;
                        stack.push(j);
                    }
                }
            }
        }
        largest.push(best.1);
        outside.push(out);
    }
    // A dense receiver has hundreds of thousands of components, each classified on its own.
    let centres: Vec<DVec2> = largest
        .iter()
        .map(|&t| {
            let c = faces[t].center();
            DVec2::new(c.x, c.y) - shift
        })
        .collect();
    let regions: Vec<Region> = centres
        .par_iter()
        .zip(&outside)
        .map(|(&c, &out)| {
            if out {
                Region::default()
            } else {
                rr.classify(c)
            }
        })
        .collect();
    Components {
        comp,
        regions,
        outside,
    }
}

/// Spade numbers the outer face 0 and the inner faces from 1, in the order `inner_faces`
/// visits them; a hash map from handle to position cost quads2000's floor (800k triangles) a
/// second.
pub(super) fn face_index(f: Face) -> usize {
    f.index() - 1
}

/// The largest coordinate of the triangulation's points (in the receiver's frame), the
/// scale of its "same place" distances.
pub(super) fn scale(cdt: &Cdt, shift: DVec2) -> f64 {
    cdt.vertices()
        .map(|v| DVec2::new(v.position().x, v.position().y) - shift)
        .fold(0.0f64, |m, p| m.max(p.abs().max_element()))
        .max(1e-300)
}

/// Triangles, their regions (connected components across non-constraint edges, classified
/// once each), and the D0 vertex split.
pub(super) fn extract(
    cdt: &Cdt,
    shift: DVec2,
    rr: &ReceiverRegions,
    frame: &Frame,
    uniform: bool,
    tol: &Tolerances,
) -> ReceiverMesh {
    if uniform {
        let (positions, mut triangles) = vertices_and_triangles(cdt, shift);
        let mut tri_region = vec![0; triangles.len()];
        drop_flat(&positions, frame, &mut triangles, &mut tri_region, tol);
        return ReceiverMesh {
            eval: positions.clone(),
            positions,
            triangles,
            tri_region,
            regions: Vec::new(),
            ..ReceiverMesh::default()
        };
    }
    extract_with(cdt, shift, rr, frame, tol, components(cdt, shift, rr))
}

fn vertices_and_triangles(cdt: &Cdt, shift: DVec2) -> (Vec<DVec2>, Vec<[u32; 3]>) {
    let positions: Vec<DVec2> = cdt
        .vertices()
        .map(|v| DVec2::new(v.position().x, v.position().y) - shift)
        .collect();
    debug_assert!(cdt
        .inner_faces()
        .enumerate()
        .all(|(i, f)| face_index(f.fix()) == i));
    let triangles: Vec<[u32; 3]> = cdt
        .inner_faces()
        .map(|f| f.vertices().map(|v| v.fix().index() as u32))
        .collect();
    (positions, triangles)
}

/// `extract` with the components known (refinement keeps them on the faces).
pub(super) fn extract_with(
    cdt: &Cdt,
    shift: DVec2,
    rr: &ReceiverRegions,
    frame: &Frame,
    tol: &Tolerances,
    c: Components,
) -> ReceiverMesh {
    let (mut positions, mut triangles) = vertices_and_triangles(cdt, shift);
    let Components {
        comp,
        regions,
        outside,
    } = c;
    // D0 split: group the triangles around each vertex into sectors that do not cross a
    // D0 edge; every sector but the first gets its own copy of the vertex.
    let test = D0Test::new(rr, scale(cdt, shift), shift);
    let inside = |f: Face| !outside[comp[face_index(f)] as usize];
    let is_d0_uncached = |e: Edge<'_>| -> bool {
        let (Some(fa), Some(fb)) = (e.face().as_inner(), e.rev().face().as_inner()) else {
            return false;
        };
        let (ca, cb) = (comp[face_index(fa.fix())], comp[face_index(fb.fix())]);
        if outside[ca as usize] || outside[cb as usize] {
            return false;
        }
        test.is_d0(e, ca, cb, &regions)
    };
    // Asked again for every edge around each D0 vertex: decided once per edge, on all
    // threads (a receiver under thousands of shadows holds one thread for its whole mesh
    // but for what it splits itself: room-8328's table top).
    let edges: Vec<FixedUndirectedEdgeHandle> = cdt.fixed_undirected_edges().collect();
    let d0_flag: Vec<bool> = edges
        .into_par_iter()
        .map(|h| {
            let e = cdt.undirected_edge(h);
            e.is_constraint_edge() && is_d0_uncached(e.as_directed())
        })
        .collect();
    let is_d0_edge = |e: Edge<'_>| -> bool { d0_flag[e.as_undirected().index()] };
    let mut d0_vertices = Vec::new();
    for e in cdt.undirected_edges() {
        if d0_flag[e.index()] {
            let d = e.as_directed();
            d0_vertices.push(d.from().fix());
            d0_vertices.push(d.to().fix());
        }
    }
    let mut eval = positions.clone();
    let mut d0_corners = Vec::new();
    d0_vertices.sort_unstable();
    d0_vertices.dedup();
    let found: Vec<_> = d0_vertices
        .par_iter()
        .map(|&vh| sides(cdt, vh, shift, &is_d0_edge, &inside))
        .collect();
    for (vh, s) in d0_vertices.into_iter().zip(found) {
        let Some(s) = s else {
            continue;
        };
        if !s.straight {
            d0_corners.push(positions[vh.index()]);
        }
        for (k, sector) in s.sectors.iter().enumerate() {
            let id = if k == 0 {
                vh.index() as u32
            } else {
                positions.push(positions[vh.index()]);
                eval.push(positions[vh.index()]);
                positions.len() as u32 - 1
            };
            // The evaluation point moves towards the sector's triangles.
            let p = positions[vh.index()];
            let tris = sector
                .iter()
                .map(|&f| triangles[face_index(f)].map(|i| positions[i as usize]));
            if let Some(q) = nudge(p, tris, tol) {
                eval[id as usize] = q;
            }
            if k > 0 {
                for &f in sector {
                    for x in triangles[face_index(f)].iter_mut() {
                        if *x == vh.index() as u32 {
                            *x = id;
                        }
                    }
                }
            }
        }
    }
    let mut tri_region = comp;
    if outside.iter().any(|&o| o) {
        drop_outside(
            &outside,
            &mut positions,
            &mut eval,
            &mut triangles,
            &mut tri_region,
        );
    }
    drop_flat(&positions, frame, &mut triangles, &mut tri_region, tol);
    ReceiverMesh {
        positions,
        eval,
        triangles,
        tri_region,
        regions,
        d0_corners,
        ..ReceiverMesh::default()
    }
}

/// Removes the triangles of components outside the receiver, and the vertices only they
/// used (the frame's corners).
fn drop_outside(
    outside: &[bool],
    positions: &mut Vec<DVec2>,
    eval: &mut Vec<DVec2>,
    triangles: &mut Vec<[u32; 3]>,
    tri_region: &mut Vec<u32>,
) {
    let keep: Vec<bool> = tri_region.iter().map(|&r| !outside[r as usize]).collect();
    let mut k = keep.iter();
    triangles.retain(|_| *k.next().unwrap_or(&true));
    let mut k = keep.iter();
    tri_region.retain(|_| *k.next().unwrap_or(&true));
    let mut new_id = vec![u32::MAX; positions.len()];
    for t in triangles.iter() {
        for &v in t {
            new_id[v as usize] = 0;
        }
    }
    let mut n = 0u32;
    for (v, id) in new_id.iter_mut().enumerate() {
        if *id == 0 {
            *id = n;
            positions[n as usize] = positions[v];
            eval[n as usize] = eval[v];
            n += 1;
        }
    }
    positions.truncate(n as usize);
    eval.truncate(n as usize);
    for t in triangles.iter_mut() {
        for v in t.iter_mut() {
            *v = new_id[*v as usize];
        }
    }
}

/// Removes triangles narrower than 1e-12 of the scene size (twice the area over the longest
/// side). Spade splits constraint edges at computed points (midpoints when refining) that
/// lie an ulp or so off the exact line; its exact predicates then see a kink there, keep
/// triangles spanned by three points of one line (e.g. filling the dent the kink makes in
/// the hull), and refinement near a kink can run away, halving ever thinner triangles. Such
/// a triangle is a thousand times narrower than the distance below which the arrangement
/// merges points (~1e-9 of the scene), so it stands for no discontinuity; it carries no
/// light (area under 1e-12 × scene × its length), and its facing is decided by rounding,
/// so in 3-D it may point against its polygon. Dropping it leaves a slit of that width. It
/// is done after the D0 split so that, while sectors and regions are formed, it still joins
/// its neighbours.
fn drop_flat(
    positions: &[DVec2],
    frame: &Frame,
    triangles: &mut Vec<[u32; 3]>,
    tri_region: &mut Vec<u32>,
    tol: &Tolerances,
) {
    // Judged in 3-D: far from the origin, points apart in the receiver's frame can round
    // to one point in the scene.
    let p3: Vec<DVec3> = positions.iter().map(|p| frame.to_3d(*p)).collect();
    let scale = p3.iter().fold(0.0f64, |m, p| m.max(p.abs().max_element()));
    // Rounding alone moves a point off a line by a few ulps of the coordinates.
    let tol = (64.0 * f64::EPSILON * scale).max(tol.flat);
    let keep: Vec<bool> = triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| p3[i as usize]);
            let longest = (b - a).length().max((c - b).length()).max((a - c).length());
            (b - a).cross(c - a).length() > tol * longest
        })
        .collect();
    if keep.iter().all(|&k| k) {
        return;
    }
    let mut k = keep.iter();
    triangles.retain(|_| *k.next().unwrap_or(&true));
    let mut k = keep.iter();
    tri_region.retain(|_| *k.next().unwrap_or(&true));
}
