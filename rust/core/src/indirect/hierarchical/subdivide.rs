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
//! rays, at the midpoint and at both ends, so a curve is told from the noise of rays; where
//! links seen in part bring much of the light it gives up, and the edge stays. A new vertex
//! takes the smooth value plus the mean of what its ends' own looks added to theirs, and the
//! exact direct light (`direct::light_at`, in the regions around the edge). Splits are
//! longest-edge bisections (Rivara), closed over neighbours so the mesh stays conforming and
//! its angles bounded.

use std::collections::HashMap;

use glam::DVec3;
use rayon::prelude::*;

use super::hierarchy::{Hierarchy, NONE};
use super::vertices::{Gather, Point};
use crate::mesh::elements::Elements;
use crate::progress::Progress;
use crate::scene::{Face, Scene};
use crate::BakeError;

/// Passes of splitting at most; each halves the edges it splits.
const MAX_PASSES: usize = 6;
/// An edge is gathered again at its midpoint when its ends' indirect light differs by more
/// than this times the allowed error: a curve whose ends agree has little room to sag.
const SCREEN: f64 = 2.0;
/// Edges shorter than this share of their face's extent are not split.
const MIN_EDGE: f64 = 1.0 / 512.0;
/// Vertices the splits may add, per vertex of the mesh (a bound on memory and time).
const MAX_ADDED_PER_VERTEX: usize = 1;
/// The floor under the local light against which an error is judged: this share of the
/// mean light over the vertices (so that nearly black corners do not split forever).
const FLOOR: f64 = 0.05;

/// What the splits add to the element mesh: vertices after the old ones (same ids for
/// those), with their direct light, and the whole new triangle list.
#[derive(Debug, Clone, PartialEq)]
pub struct Subdivided {
    pub positions: Vec<DVec3>,
    pub eval: Vec<DVec3>,
    pub normals: Vec<DVec3>,
    pub vertex_face: Vec<u32>,
    /// Direct irradiance at the added vertices.
    pub direct: Vec<DVec3>,
    /// Indirect irradiance at every vertex, old and added.
    pub indirect: Vec<DVec3>,
    pub triangles: Vec<[u32; 3]>,
    pub tri_face: Vec<u32>,
    pub tri_region: Vec<u32>,
    pub passes: u64,
}

/// A midpoint lit and judged, kept whether or not its edge was split.
#[derive(Clone, Copy)]
struct Mid {
    p: DVec3,
    eval: DVec3,
    direct: DVec3,
    /// How far the indirect light there lies from the edge's interpolant, with the leaf's
    /// visibilities (`Gather::smooth`), channels summed.
    err: f64,
    /// Indirect irradiance there: the smooth value, plus the ends' own visibilities'
    /// share interpolated.
    indirect: DVec3,
    /// Its smooth value, on `leaf` (NONE: in none).
    smooth: DVec3,
    leaf: u32,
    /// Vertex id once the edge is split.
    vertex: u32,
}

/// Splits the elements of `el` where the indirect light `indirect` (per vertex, from
/// `gather`) is not linear to within `tol` of the local light (`direct` per vertex plus
/// indirect, plus a floor); `None` when nothing needed it.
#[allow(clippy::too_many_arguments)]
pub fn subdivide(
    scene: &Scene,
    h: &Hierarchy,
    faces: &[Face],
    el: &Elements,
    gather: &Gather,
    direct: &[DVec3],
    indirect: &[DVec3],
    tol: f64,
    progress: &Progress,
) -> Result<Option<Subdivided>, BakeError> {
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
        positions: el.positions.clone(),
        eval: el.eval.clone(),
        normals: el.normals.clone(),
        vertex_face: el.vertex_face.clone(),
        direct: Vec::new(),
        indirect: indirect.to_vec(),
        triangles: el.triangles.clone(),
        tri_face: el.tri_face.clone(),
        tri_region: el.tri_region.clone(),
        passes: 0,
    };
    let mut dir: Vec<DVec3> = direct.to_vec();
    // Triangles by origin: the element triangle each one came from.
    let mut origin: Vec<u32> = (0..el.triangles.len() as u32).collect();
    let mut mids: HashMap<(u32, u32), Mid> = HashMap::new();
    // Smooth values of vertices on a leaf (`Gather::smooth`).
    let mut ends: HashMap<(u32, u32), DVec3> = HashMap::new();
    let max_vertices = nv + MAX_ADDED_PER_VERTEX * nv;
    let key = |a: u32, b: u32| (a.min(b), a.max(b));

    // Evaluates the midpoints of `edges` (with a triangle holding each) not yet known.
    let evaluate = |edges: &[((u32, u32), u32)],
                    out: &Subdivided,
                    origin: &[u32],
                    mids: &mut HashMap<(u32, u32), Mid>,
                    ends: &mut HashMap<(u32, u32), DVec3>| {
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
        let mut sides: HashMap<(u32, u32), (Vec<u32>, u32)> = HashMap::new();
        for &(k, _) in &todo {
            sides.insert(k, (Vec::new(), NONE));
        }
        for (t, tri) in out.triangles.iter().enumerate() {
            for i in 0..3 {
                if let Some((r, leaf)) = sides.get_mut(&key(tri[i], tri[(i + 1) % 3])) {
                    let o = origin[t] as usize;
                    if !r.contains(&el.tri_region[o]) {
                        r.push(el.tri_region[o]);
                    }
                    if *leaf == NONE {
                        *leaf = tri_leaf[o];
                    }
                }
            }
        }
        let lit: Vec<(DVec3, DVec3, DVec3)> = todo
            .par_iter()
            .map(|&((a, b), t)| {
                let (a, b) = (a as usize, b as usize);
                let p = (out.positions[a] + out.positions[b]) * 0.5;
                let eval = (out.eval[a] + out.eval[b]) * 0.5;
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
                    out.normals[a],
                    &regions,
                    &outlines,
                );
                (p, eval, e)
            })
            .collect();
        // Each midpoint and the edge's two ends, gathered smooth on the midpoint's leaf.
        let nudge = |q: DVec3, leaf: u32| q + (h.nodes[leaf as usize].centroid - q) * 1e-6;
        // Each midpoint, and each edge end not yet known on that leaf, gathered smooth on
        // the midpoint's leaf (an end serves the several edges around it).
        let mut which = Vec::new();
        let mut points: Vec<Point> = Vec::new();
        let mut asked: HashMap<(u32, u32), usize> = HashMap::new();
        let mut slots: Vec<[usize; 3]> = Vec::new();
        for (i, (&((a, b), t), &(_, eval, _))) in todo.iter().zip(&lit).enumerate() {
            let leaf = sides[&(a, b)].1;
            if leaf == NONE {
                continue;
            }
            which.push(i);
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
                slot[k] = *asked.entry((v, leaf)).or_insert_with(|| {
                    points.push(point(out.eval[v as usize]));
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
        let mut g = vec![DVec3::ZERO; todo.len()];
        let mut leaf_of = vec![NONE; todo.len()];
        // In no leaf (under a cover, buried), the interpolant, as its ends had.
        let mut value: Vec<DVec3> = todo
            .iter()
            .map(|&((a, b), _)| 0.5 * (out.indirect[a as usize] + out.indirect[b as usize]))
            .collect();
        for (&i, slot) in which.iter().zip(&slots) {
            let ((a, b), _) = todo[i];
            let leaf = sides[&(a, b)].1;
            // Where means say little, the interpolant stays (`Gather::smooth`).
            let (Some(m), Some(&ga), Some(&gb)) =
                (smooth[slot[0]], ends.get(&(a, leaf)), ends.get(&(b, leaf)))
            else {
                continue;
            };
            err[i] = (m - 0.5 * (ga + gb)).abs().element_sum();
            // The smooth value's curve, plus what the ends' own rays added to theirs,
            // interpolated (as the mesh did before).
            let own = (out.indirect[a as usize] - ga) + (out.indirect[b as usize] - gb);
            value[i] = m + 0.5 * own;
            g[i] = m;
            leaf_of[i] = leaf;
        }
        for (i, (&((a, b), _), &(p, eval, e))) in todo.iter().zip(&lit).enumerate() {
            mids.insert(
                (a, b),
                Mid {
                    p,
                    eval,
                    direct: e,
                    err: err[i],
                    indirect: value[i],
                    smooth: g[i],
                    leaf: leaf_of[i],
                    vertex: NONE,
                },
            );
        }
    };

    let mut any = false;
    for _ in 0..MAX_PASSES {
        progress.check()?;
        // Edges whose ends differ, on triangles of a leaf, long enough to split.
        let mut cand: Vec<((u32, u32), u32)> = Vec::new();
        for (t, tri) in out.triangles.iter().enumerate() {
            let o = origin[t] as usize;
            if tri_leaf[o] == NONE {
                continue;
            }
            let min_len = MIN_EDGE * extent[el.tri_face[o] as usize];
            for i in 0..3 {
                let (a, b) = (tri[i], tri[(i + 1) % 3]);
                let k = key(a, b);
                if mids.contains_key(&k) {
                    continue;
                }
                let (ua, ub) = (a as usize, b as usize);
                if (out.positions[ua] - out.positions[ub]).length() < 2.0 * min_len {
                    continue;
                }
                let d = (out.indirect[ua] - out.indirect[ub]).abs().element_sum();
                let base = 0.5 * (dir[ua] + out.indirect[ua] + dir[ub] + out.indirect[ub]);
                if d > SCREEN * tol * (base.element_sum() + floor) {
                    cand.push((k, t as u32));
                }
            }
        }
        cand.sort_unstable();
        cand.dedup_by_key(|x| x.0);
        if cand.is_empty() {
            break;
        }
        evaluate(&cand, &out, &origin, &mut mids, &mut ends);
        let mut split: Vec<(u32, u32)> = cand
            .iter()
            .filter(|&&(k, _)| {
                let m = &mids[&k];
                let (a, b) = (k.0 as usize, k.1 as usize);
                let lin = 0.5 * (out.indirect[a] + out.indirect[b]);
                m.err > tol * ((m.direct + lin).element_sum() + floor)
            })
            .map(|&(k, _)| k)
            .collect();
        if split.is_empty() {
            break;
        }
        // Closure: a triangle with a split edge splits its longest edge too (Rivara), and
        // that may mark its neighbour's.
        let mut marked: std::collections::HashSet<(u32, u32)> = split.iter().copied().collect();
        loop {
            progress.check()?;
            let mut more: Vec<((u32, u32), u32)> = Vec::new();
            for (t, tri) in out.triangles.iter().enumerate() {
                let ks = [0, 1, 2].map(|i| key(tri[i], tri[(i + 1) % 3]));
                if !ks.iter().any(|k| marked.contains(k)) {
                    continue;
                }
                let l = longest(&out.positions, tri);
                if !marked.contains(&ks[l]) {
                    more.push((ks[l], t as u32));
                }
            }
            if more.is_empty() {
                break;
            }
            more.sort_unstable();
            more.dedup_by_key(|x| x.0);
            evaluate(&more, &out, &origin, &mut mids, &mut ends);
            for (k, _) in more {
                marked.insert(k);
                split.push(k);
            }
        }
        if out.positions.len() + split.len() > max_vertices {
            break;
        }
        split.sort_unstable();
        for k in &split {
            let m = mids.get_mut(k).expect("evaluated above");
            m.vertex = out.positions.len() as u32;
            let a = k.0 as usize;
            out.positions.push(m.p);
            out.eval.push(m.eval);
            out.normals.push(out.normals[a]);
            out.vertex_face.push(out.vertex_face[a]);
            out.indirect.push(m.indirect);
            if m.leaf != NONE {
                ends.insert((m.vertex, m.leaf), m.smooth);
            }
            out.direct.push(m.direct);
            dir.push(m.direct);
        }
        let vertex_of = |a: u32, b: u32| -> Option<u32> {
            mids.get(&key(a, b))
                .map(|m| m.vertex)
                .filter(|&v| v != NONE && marked.contains(&key(a, b)))
        };
        let mut tris = Vec::with_capacity(out.triangles.len() + 2 * split.len());
        let mut orig = Vec::with_capacity(tris.capacity());
        for (t, tri) in out.triangles.iter().enumerate() {
            for c in bisect(&out.positions, *tri, &vertex_of) {
                tris.push(c);
                orig.push(origin[t]);
            }
        }
        out.triangles = tris;
        origin = orig;
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

/// Index i of the longest edge (tri[i], tri[i + 1]).
fn longest(pos: &[DVec3], tri: &[u32; 3]) -> usize {
    let len = |i: usize| (pos[tri[i] as usize] - pos[tri[(i + 1) % 3] as usize]).length_squared();
    let mut l = 0;
    for i in 1..3 {
        if len(i) > len(l) {
            l = i;
        }
    }
    l
}

/// `tri` cut at the midpoints `mid` gives of its edges, its longest edge first (which
/// the closure has split whenever any is): 1, 2, 3 or 4 triangles, same orientation.
fn bisect(pos: &[DVec3], tri: [u32; 3], mid: &impl Fn(u32, u32) -> Option<u32>) -> Vec<[u32; 3]> {
    let l = longest(pos, &tri);
    let (a, b, c) = (tri[l], tri[(l + 1) % 3], tri[(l + 2) % 3]);
    let Some(m) = mid(a, b) else {
        return vec![tri];
    };
    let mut out = Vec::with_capacity(4);
    match mid(a, c) {
        Some(mca) => out.extend([[a, m, mca], [m, c, mca]]),
        None => out.push([a, m, c]),
    }
    match mid(b, c) {
        Some(mbc) => out.extend([[m, b, mbc], [m, mbc, c]]),
        None => out.push([m, b, c]),
    }
    out
}

#[cfg(test)]
mod test {
    use super::*;

    #[test]
    fn bisection_keeps_area_and_orientation() {
        let pos = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(4.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(0.5, 0.5, 0.0),
            DVec3::new(2.5, 0.5, 0.0),
        ];
        let area = |t: &[u32; 3]| {
            let [a, b, c] = t.map(|v| pos[v as usize]);
            (b - a).cross(c - a).z * 0.5
        };
        let whole = area(&[0, 1, 2]);
        for (with_ca, with_bc) in [(false, false), (true, false), (false, true), (true, true)] {
            let mid = |a: u32, b: u32| match (a.min(b), a.max(b)) {
                (0, 1) => Some(3),
                (0, 2) if with_ca => Some(4),
                (1, 2) if with_bc => Some(5),
                _ => None,
            };
            let parts = bisect(&pos, [0, 1, 2], &mid);
            assert_eq!(parts.len(), 2 + with_ca as usize + with_bc as usize);
            let sum: f64 = parts.iter().map(area).sum();
            assert!((sum - whole).abs() < 1e-12, "{sum} vs {whole}");
            assert!(parts.iter().all(|t| area(t) > 0.0), "{parts:?}");
        }
    }
}
