//! Elements where indirect light curves: after the final gather, an element edge whose ends'
//! indirect light differs is judged at its midpoint, and split where the linear
//! interpolant misses the light there by more than the tolerance.
//!
//! Direct light's refinement (`mesh::refine`) cannot see this: beside a box standing on a
//! lit table, the box's side is in umbra, so its elements span its whole height, but the
//! light it takes from the table rises within millimetres of the contact (the box's own
//! penumbra on the table), and the linear interpolant between the side's bottom and top
//! rows lay 13 % under Cycles over such a side in room-78's clutter (36 % on the flat box
//! of tests/test_contact_side_cycles.py).
//!
//! The judgement uses `Gather::smooth`: the gather with the links' mean visibilities, no
//! rays, at the midpoint and at both ends, so a curve is told from the noise of rays. Where
//! links seen in part bring much of the light (between boxes, under a shelf) means say
//! little of a point, and the leaf's own look judges instead (`Gather::looked`): the rays
//! the final gather cast from the leaf and its anchors, kept from it (`LeafLook`), and their
//! visibilities interpolated to the point; its noise asks `LOOK_SCALE` times the
//! tolerance. Without it such edges stayed whole, and room-78 was 3.66 % from Cycles
//! (2.98 % with it). A new vertex takes the value of whichever judged it plus the mean of
//! what its ends' own looks added to theirs, and the exact direct light
//! (`direct::light_at`, in the regions around the edge). Splits are
//! longest-edge bisections (Rivara), closed over neighbours so the mesh stays conforming and
//! its angles bounded.

use glam::DVec3;
use rayon::prelude::*;

use super::bisect::{bisect_all, longest, EdgeTris};
use super::hierarchy::{Hierarchy, NONE};
use super::vertices::{AtVertices, Gather, Point};
use crate::geom::hash::{IdMap, IdSet};
use crate::mesh::elements::Elements;
use crate::progress::Progress;
use crate::scene::{Face, Scene};
use crate::BakeError;

/// Passes of splitting at most; each halves the edges it splits. Each pass adds about as
/// many vertices as the one before (room-78: 2.7k, 3.3k, 3.7k, 3.9k, 4.1k, 3.5k), but the
/// error from Cycles (`per_mesh.py`) settles after three: room-78 3.75 % with none, 3.01 %
/// after 2, 2.99 % after 3, 2.98 % after 4 and 6; room-245 5.24 / 5.20 / 5.20 % after 2 / 3
/// / 6; cornell, chair and data1 the same after 2 as after 6.
const MAX_PASSES: usize = 3;
/// An edge is gathered again at its midpoint when its ends' indirect light differs by more
/// than this times the allowed error: a curve whose ends agree has little room to sag.
const SCREEN: f64 = 2.0;
/// Edges shorter than this share of their face's extent are not split.
const MIN_EDGE: f64 = 1.0 / 512.0;
/// Edges judged by the leaf's own look (where means say little) split only past this
/// times the tolerance: its anchors' rays make it noisier than the smooth value. room-78
/// (bench probes): 1 → 2.95 % from Cycles with 29.3k vertices added, 2 → 2.98 % with
/// 21.2k, 4 → 3.07 % with 14.0k.
const LOOK_SCALE: f64 = 2.0;
/// Vertices the splits may add, per vertex of the mesh (a bound on memory and time).
const MAX_ADDED_PER_VERTEX: usize = 1;
/// The floor under the local light against which an error is judged: this share of the
/// mean light over the vertices (so that nearly black corners do not split forever).
const FLOOR: f64 = 0.05;

/// What the splits add to the element mesh: vertices after the old ones (same ids for
/// those), with their direct light, and the whole new triangle list. The added vertices'
/// attributes are kept apart from the old ones' (room-8328 has 5.8M vertices: a copy of
/// each array is 20–140 MB, and copies of the positions, the indirect light and the
/// triangles' faces and regions were about 0.3 GB of its peak).
#[derive(Debug, Clone, PartialEq)]
pub struct Subdivided {
    /// The added vertices'.
    pub positions: Vec<DVec3>,
    pub eval: Vec<DVec3>,
    pub normals: Vec<DVec3>,
    pub vertex_face: Vec<u32>,
    /// Direct irradiance at the added vertices.
    pub direct: Vec<DVec3>,
    /// Indirect irradiance at the added vertices.
    pub indirect: Vec<DVec3>,
    pub triangles: Vec<[u32; 3]>,
    pub tri_face: Vec<u32>,
    pub tri_region: Vec<u32>,
    pub passes: u64,
}

/// A midpoint lit and judged, kept while its edge is whole (where and how it is evaluated
/// are its ends' means: the edge is the key).
#[derive(Clone, Copy)]
struct Mid {
    direct: DVec3,
    /// How far the indirect light there lies from the edge's interpolant, with the leaf's
    /// visibilities (`Gather::smooth`), channels summed.
    err: f64,
    /// Indirect irradiance there: the smooth value, plus the ends' own visibilities'
    /// share interpolated.
    indirect: DVec3,
    /// What judged it, on `leaf` (NONE: in none).
    judged: Judged,
    leaf: u32,
    /// Vertex id once the edge is split.
    vertex: u32,
}

/// The value a midpoint was judged by.
#[derive(Clone, Copy)]
enum Judged {
    /// In no leaf: not judged.
    Not,
    /// The smooth value (`Gather::smooth`), where the means say enough.
    Smooth(DVec3),
    /// The value by the leaf's look (`Gather::looked`).
    Look(DVec3),
}

/// What the passes learn and keep: each edge's midpoint, and values at edge ends.
#[derive(Default)]
struct Known {
    mids: IdMap<(u32, u32), Mid>,
    /// Smooth values of vertices on a leaf (`Gather::smooth`).
    ends: IdMap<(u32, u32), DVec3>,
    /// Values at vertices on a leaf by its look (`Gather::looked`).
    seen_ends: IdMap<(u32, u32), DVec3>,
    /// Whether the means cannot judge a leaf's centre (`Gather::partly_seen`).
    partly: IdMap<u32, bool>,
}

/// Splits the elements of `el` where the indirect light `at_vertices.irradiance` (per
/// vertex, from `gather`) is not linear to within `tol` of the local light (`direct` per vertex plus
/// indirect, plus a floor); `None` when nothing needed it.
#[allow(clippy::too_many_arguments)]
pub fn subdivide(
    scene: &Scene,
    h: &Hierarchy,
    faces: &[Face],
    el: &Elements,
    gather: &Gather,
    at_vertices: &AtVertices,
    direct: &[DVec3],
    tol: f64,
    progress: &Progress,
) -> Result<Option<Subdivided>, BakeError> {
    let (indirect, looks) = (&at_vertices.irradiance[..], &at_vertices.looks);
    let nv = el.positions.len();
    // Elements made without regions (unit tests' grids) have no direct light to split by.
    if nv == 0 || el.tri_region.len() != el.triangles.len() || el.regions.is_empty() {
        return Ok(None);
    }
    // Each element triangle's leaf node (its front's), or NONE where it is in none.
    let mut tri_leaf = vec![NONE; el.triangles.len()];
    for (pos, &t) in h.order.iter().enumerate() {
        if !h.is_back(h.nodes[h.leaf_node[pos] as usize].face) {
            tri_leaf[t as usize] = h.leaf_node[pos];
        }
    }
    let floor = FLOOR
        * (0..nv)
            .map(|v| (direct[v] + indirect[v]).element_sum())
            .sum::<f64>()
        / nv as f64;
    if !(floor > 0.0) {
        return Ok(None);
    }
    let extent: Vec<f64> = scene
        .faces
        .iter()
        .map(|f| {
            let (lo, hi) = f.verts.iter().fold(
                (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
                |(lo, hi), &p| (lo.min(p), hi.max(p)),
            );
            (hi - lo).length()
        })
        .collect();
    let tolerances = scene.tolerances();
    let outlines = crate::direct::outlines(scene);

    let mut out = Subdivided {
        positions: Vec::new(),
        eval: Vec::new(),
        normals: Vec::new(),
        vertex_face: Vec::new(),
        direct: Vec::new(),
        indirect: Vec::new(),
        triangles: par_copy(&el.triangles),
        // Made from the triangles' origins at the end.
        tri_face: Vec::new(),
        tri_region: Vec::new(),
        passes: 0,
    };
    // Old vertices' attributes from `el` (and `direct`), added ones' from `out`.
    let position_at = |out: &Subdivided, v: usize| either(&el.positions, &out.positions, nv, v);
    let eval_at = |out: &Subdivided, v: usize| either(&el.eval, &out.eval, nv, v);
    let normal_at = |out: &Subdivided, v: usize| either(&el.normals, &out.normals, nv, v);
    let face_at = |out: &Subdivided, v: usize| either(&el.vertex_face, &out.vertex_face, nv, v);
    let direct_at = |out: &Subdivided, v: usize| either(direct, &out.direct, nv, v);
    let indirect_at = |out: &Subdivided, v: usize| either(indirect, &out.indirect, nv, v);
    // Triangles by origin: the element triangle each one came from.
    let mut origin: Vec<u32> = (0..el.triangles.len() as u32).collect();
    let mut known = Known::default();
    let gathered_on = gather.leaf_of();
    // Whether vertex `v` is an old one, gathered on `leaf` and on `face`: the final gather
    // found its values at the very point that `leaf` and `face` place it.
    let gathered_here = |v: u32, leaf: u32, face: u32| {
        let u = v as usize;
        u < nv && gathered_on[u] == leaf && el.vertex_face[u] == face
    };
    // What the rays of edge end `v` added to its value, given `g`, its value on `leaf` and
    // `face` without them (smooth or by the leaf's look). An old vertex gathered on another
    // leaf (where leaves meet) took its value from that leaf's links, so the difference from
    // `g` would also carry how the two leaves' links disagree there, and a midpoint would
    // take half of that: in a 7 mm slot between two boxes of room-245, a corner vertex
    // gathered beside the slot's lit end (irradiance 8.5) lifted the midpoints of the leaf
    // across the slot, which was 0.85 at Cycles' 0.43. For such an end, what its rays added
    // on its own leaf; nothing where that leaf's means said too little to tell.
    let own_rays = |v: u32, g: DVec3, leaf: u32, face: u32, out: &Subdivided| {
        let u = v as usize;
        if u >= nv || gathered_here(v, leaf, face) {
            return indirect_at(out, u) - g;
        }
        let m = at_vertices.smooth[u];
        if m.x.is_nan() {
            DVec3::ZERO
        } else {
            indirect[u] - m
        }
    };
    let max_vertices = nv + MAX_ADDED_PER_VERTEX * nv;
    let key = |a: u32, b: u32| (a.min(b), a.max(b));

    // Evaluates the midpoints of `edges` (with a triangle holding each) not yet known.
    let evaluate = |edges: &[((u32, u32), u32)],
                    out: &Subdivided,
                    origin: &[u32],
                    adj: &EdgeTris,
                    known: &mut Known| {
        let Known {
            mids,
            ends,
            seen_ends,
            partly,
        } = known;
        let todo: Vec<((u32, u32), u32)> = edges
            .iter()
            .filter(|(k, _)| !mids.contains_key(k))
            .copied()
            .collect();
        if todo.is_empty() {
            return;
        }
        // Regions of the triangles on either side of each edge, from their origins, and a
        // leaf that holds one of them (the closure may reach triangles in no leaf).
        let mut sides: IdMap<(u32, u32), (Vec<u32>, u32)> = IdMap::default();
        for &(k, _) in &todo {
            let (mut r, mut leaf) = (Vec::new(), NONE);
            for &t in adj.of(k) {
                let o = origin[t as usize] as usize;
                if !r.contains(&el.tri_region[o]) {
                    r.push(el.tri_region[o]);
                }
                if leaf == NONE {
                    leaf = tri_leaf[o];
                }
            }
            sides.insert(k, (r, leaf));
        }
        let lit: Vec<(DVec3, DVec3)> = todo
            .par_iter()
            .map(|&((a, b), t)| {
                let (a, b) = (a as usize, b as usize);
                let eval = (eval_at(out, a) + eval_at(out, b)) * 0.5;
                let o = origin[t as usize] as usize;
                let regions: Vec<&crate::regions::Region> = sides[&key(a as u32, b as u32)]
                    .0
                    .iter()
                    .map(|&r| &el.regions[r as usize])
                    .collect();
                let (e, _) = crate::direct::light_at(
                    scene,
                    &tolerances,
                    el.tri_face[o],
                    eval,
                    normal_at(out, a),
                    &regions,
                    &outlines,
                );
                (eval, e)
            })
            .collect();
        // A point a hair towards its leaf's centre, as the final gather places vertices.
        let nudge = |q: DVec3, leaf: u32| q + (h.nodes[leaf as usize].centroid - q) * 1e-6;
        // Each midpoint, and each edge end not yet known on that leaf, gathered smooth on
        // the midpoint's leaf (an end serves the several edges around it). Leaves where links seen in part carry much of the light go to their own look
        // straight away: most of their edges' smooth values would give up.
        let mut new_leaves: Vec<u32> = todo
            .iter()
            .map(|(k, _)| sides[k].1)
            .filter(|&l| l != NONE && !partly.contains_key(&l))
            .collect();
        new_leaves.par_sort_unstable();
        new_leaves.dedup();
        let found: Vec<(u32, bool)> = new_leaves
            .par_iter()
            .map(|&l| {
                let known = looks.get(&l).and_then(|k| k.partly);
                (l, known.unwrap_or_else(|| gather.partly_seen(l)))
            })
            .collect();
        partly.extend(found);
        let mut which = Vec::new();
        let mut points: Vec<Point> = Vec::new();
        let mut asked: IdMap<(u32, u32), usize> = IdMap::default();
        let mut slots: Vec<[usize; 3]> = Vec::new();
        for (i, (&((a, b), t), &(eval, _))) in todo.iter().zip(&lit).enumerate() {
            let leaf = sides[&(a, b)].1;
            if leaf == NONE {
                continue;
            }
            which.push(i);
            if partly[&leaf] {
                slots.push([usize::MAX; 3]);
                continue;
            }
            let face = el.tri_face[origin[t as usize] as usize];
            let point = |q: DVec3| Point {
                p: nudge(q, leaf),
                n: faces[face as usize].plane.n,
                leaf,
            };
            let mut slot = [points.len(), usize::MAX, usize::MAX];
            points.push(point(eval));
            for (k, v) in [(1, a), (2, b)] {
                if ends.contains_key(&(v, leaf)) {
                    continue;
                }
                if gathered_here(v, leaf, face) {
                    let m = at_vertices.smooth[v as usize];
                    if !m.x.is_nan() {
                        ends.insert((v, leaf), m);
                    }
                    continue;
                }
                slot[k] = *asked.entry((v, leaf)).or_insert_with(|| {
                    points.push(point(eval_at(out, v as usize)));
                    points.len() - 1
                });
            }
            slots.push(slot);
        }
        let smooth = gather.smooth(&points);
        for (&(v, leaf), &j) in &asked {
            if let Some(g) = smooth[j] {
                ends.insert((v, leaf), g);
            }
        }
        let mut err = vec![0.0; todo.len()];
        let mut judged = vec![Judged::Not; todo.len()];
        let mut leaf_of = vec![NONE; todo.len()];
        // In no leaf (under a cover, buried), the interpolant, as its ends had.
        let mut value: Vec<DVec3> = todo
            .iter()
            .map(|&((a, b), _)| 0.5 * (indirect_at(out, a as usize) + indirect_at(out, b as usize)))
            .collect();
        let mut looked = Vec::new();
        for (&i, slot) in which.iter().zip(&slots) {
            let ((a, b), t) = todo[i];
            let leaf = sides[&(a, b)].1;
            leaf_of[i] = leaf;
            // Where means say little (`Gather::smooth`), the leaf's own look judges.
            let (Some(m), Some(&ga), Some(&gb)) = (
                smooth.get(slot[0]).copied().flatten(),
                ends.get(&(a, leaf)),
                ends.get(&(b, leaf)),
            ) else {
                looked.push((i, t));
                continue;
            };
            err[i] = (m - 0.5 * (ga + gb)).abs().element_sum();
            // The smooth value's curve, plus what the ends' own rays added to theirs,
            // interpolated (as the mesh did before).
            let face = el.tri_face[origin[t as usize] as usize];
            let own = own_rays(a, ga, leaf, face, out) + own_rays(b, gb, leaf, face, out);
            value[i] = m + 0.5 * own;
            judged[i] = Judged::Smooth(m);
        }
        let point = |q: DVec3, leaf: u32, t: u32| {
            let face = el.tri_face[origin[t as usize] as usize];
            Point {
                p: nudge(q, leaf),
                n: faces[face as usize].plane.n,
                leaf,
            }
        };
        // The ends first, each once per leaf (an end serves the edges around it).
        let mut end_todo: Vec<(u32, u32, u32)> = Vec::new();
        for &(i, t) in &looked {
            let ((a, b), _) = todo[i];
            for v in [a, b] {
                if !seen_ends.contains_key(&(v, leaf_of[i])) {
                    end_todo.push((v, leaf_of[i], t));
                }
            }
        }
        end_todo.par_sort_unstable();
        end_todo.dedup_by_key(|x| (x.0, x.1));
        // An old vertex on the leaf and face it was gathered on has that value already: the
        // final gather's, by the same look (a pass's first `looked` calls were half of them).
        let (known_ends, fresh): (Vec<_>, Vec<_>) = end_todo.iter().partition(|&&(v, leaf, t)| {
            gathered_here(v, leaf, el.tri_face[origin[t as usize] as usize])
        });
        seen_ends.extend(
            known_ends
                .iter()
                .map(|&(v, leaf, _)| ((v, leaf), indirect[v as usize])),
        );
        let fresh_at: Vec<Point> = fresh
            .iter()
            .map(|&(v, leaf, t)| point(eval_at(out, v as usize), leaf, t))
            .collect();
        let vals = gather.looked(looks, &fresh_at);
        seen_ends.extend(
            fresh
                .iter()
                .zip(vals)
                .map(|(&(v, leaf, _), e)| ((v, leaf), e)),
        );
        let seen_ends = &*seen_ends;
        let mids_at: Vec<Point> = looked
            .iter()
            .map(|&(i, t)| point(lit[i].0, leaf_of[i], t))
            .collect();
        let at_mids = gather.looked(looks, &mids_at);
        let by_look: Vec<(usize, f64, DVec3, DVec3)> = looked
            .iter()
            .zip(at_mids)
            .map(|(&(i, t), m)| {
                let ((a, b), _) = todo[i];
                let leaf = leaf_of[i];
                let la = seen_ends[&(a, leaf)];
                let lb = seen_ends[&(b, leaf)];
                let err = (m - 0.5 * (la + lb)).abs().element_sum();
                let face = el.tri_face[origin[t as usize] as usize];
                let own = own_rays(a, la, leaf, face, out) + own_rays(b, lb, leaf, face, out);
                (i, err, m + 0.5 * own, m)
            })
            .collect();
        for (i, e, v, m) in by_look {
            err[i] = e;
            value[i] = v;
            judged[i] = Judged::Look(m);
        }
        for (i, (&((a, b), _), &(_, e))) in todo.iter().zip(&lit).enumerate() {
            mids.insert(
                (a, b),
                Mid {
                    direct: e,
                    err: err[i],
                    indirect: value[i],
                    judged: judged[i],
                    leaf: leaf_of[i],
                    vertex: NONE,
                },
            );
        }
    };

    let mut any = false;
    for _ in 0..MAX_PASSES {
        progress.check()?;
        let adj = EdgeTris::new(&out.triangles);
        // Edges whose ends differ, on triangles of a leaf, long enough to split (on all
        // threads: a scan of every triangle's edges each pass, room-245's 0.1 s of one).
        let out_ref = &out;
        let known_ref = &known;
        let mut cand: Vec<((u32, u32), u32)> = out
            .triangles
            .par_iter()
            .enumerate()
            .flat_map_iter(|(t, tri)| {
                let o = origin[t] as usize;
                let min_len = MIN_EDGE * extent[el.tri_face[o] as usize];
                let on_leaf = tri_leaf[o] != NONE;
                (0..3).filter_map(move |i| {
                    let (a, b) = (tri[i], tri[(i + 1) % 3]);
                    let k = key(a, b);
                    if !on_leaf || known_ref.mids.contains_key(&k) {
                        return None;
                    }
                    let (ua, ub) = (a as usize, b as usize);
                    let (pa, pb) = (position_at(out_ref, ua), position_at(out_ref, ub));
                    if (pa - pb).length() < 2.0 * min_len {
                        return None;
                    }
                    let (ia, ib) = (indirect_at(out_ref, ua), indirect_at(out_ref, ub));
                    let d = (ia - ib).abs().element_sum();
                    let base = 0.5 * (direct_at(out_ref, ua) + ia + direct_at(out_ref, ub) + ib);
                    (d > SCREEN * tol * (base.element_sum() + floor)).then_some((k, t as u32))
                })
            })
            .collect();
        cand.par_sort_unstable();
        cand.dedup_by_key(|x| x.0);
        if cand.is_empty() {
            break;
        }
        evaluate(&cand, &out, &origin, &adj, &mut known);
        let mut split: Vec<(u32, u32)> = cand
            .iter()
            .filter(|&&(k, _)| {
                let m = &known.mids[&k];
                let (a, b) = (k.0 as usize, k.1 as usize);
                let lin = 0.5 * (indirect_at(&out, a) + indirect_at(&out, b));
                let k = match m.judged {
                    Judged::Smooth(_) => 1.0,
                    _ => LOOK_SCALE,
                };
                m.err > k * tol * ((m.direct + lin).element_sum() + floor)
            })
            .map(|&(k, _)| k)
            .collect();
        if split.is_empty() {
            break;
        }
        // Closure: a triangle with a split edge splits its longest edge too (Rivara), and
        // that may mark its neighbour's.
        // Only triangles beside the edges marked last can have new work.
        let mut marked: IdSet<(u32, u32)> = split.iter().copied().collect();
        let mut frontier = split.clone();
        loop {
            progress.check()?;
            let mut more: Vec<((u32, u32), u32)> = Vec::new();
            for k in &frontier {
                for &t in adj.of(*k) {
                    let tri = &out.triangles[t as usize];
                    let l = longest(&|v| position_at(&out, v as usize), tri);
                    let kl = key(tri[l], tri[(l + 1) % 3]);
                    if !marked.contains(&kl) {
                        more.push((kl, t));
                    }
                }
            }
            if more.is_empty() {
                break;
            }
            more.par_sort_unstable();
            more.dedup_by_key(|x| x.0);
            evaluate(&more, &out, &origin, &adj, &mut known);
            frontier.clear();
            for (k, _) in more {
                marked.insert(k);
                split.push(k);
                frontier.push(k);
            }
        }
        if nv + out.positions.len() + split.len() > max_vertices {
            break;
        }
        split.par_sort_unstable();
        for k in &split {
            let m = known.mids.get_mut(k).expect("evaluated above");
            m.vertex = (nv + out.positions.len()) as u32;
            let (a, b) = (k.0 as usize, k.1 as usize);
            let p = (position_at(&out, a) + position_at(&out, b)) * 0.5;
            let eval = (eval_at(&out, a) + eval_at(&out, b)) * 0.5;
            let (normal, face) = (normal_at(&out, a), face_at(&out, a));
            out.positions.push(p);
            out.eval.push(eval);
            out.normals.push(normal);
            out.vertex_face.push(face);
            out.indirect.push(m.indirect);
            // A new vertex is an end of the next pass's edges: its value there is known.
            match m.judged {
                Judged::Smooth(g) => _ = known.ends.insert((m.vertex, m.leaf), g),
                Judged::Look(g) => _ = known.seen_ends.insert((m.vertex, m.leaf), g),
                Judged::Not => {}
            }
            out.direct.push(m.direct);
        }
        let vertex_of = |a: u32, b: u32| -> Option<u32> {
            known
                .mids
                .get(&key(a, b))
                .map(|m| m.vertex)
                .filter(|&v| v != NONE && marked.contains(&key(a, b)))
        };
        let pos = |v: u32| position_at(&out, v as usize);
        let (tris, orig) = bisect_all(&pos, &out.triangles, &origin, &vertex_of);
        out.triangles = tris;
        origin = orig;
        // Split edges are gone from the mesh: their midpoints are vertices now.
        for k in &split {
            known.mids.remove(k);
        }
        out.passes += 1;
        any = true;
    }
    if !any {
        return Ok(None);
    }
    out.tri_face = origin.iter().map(|&o| el.tri_face[o as usize]).collect();
    out.tri_region = origin.iter().map(|&o| el.tri_region[o as usize]).collect();
    Ok(Some(out))
}

/// A copy made on all threads: each of room-8328's arrays is 20–140 MB of fresh pages.
/// Made on one thread, the copies fell in 2.5 s with one core busy after its final gather,
/// most of it the kernel clearing fresh pages (a 50 Hz timeline).
fn par_copy<T: Copy + Send + Sync>(x: &[T]) -> Vec<T> {
    x.par_iter().copied().collect()
}

/// Vertex `v`'s value: of `old` for the `nv` old vertices, else of `added` after them. The
/// split is by the vertex count, not by `old`'s length: an array shorter than the vertices
/// must fail on its index, not hand an old vertex an added one's value.
fn either<T: Copy>(old: &[T], added: &[T], nv: usize, v: usize) -> T {
    if v < nv {
        old[v]
    } else {
        added[v - nv]
    }
}
