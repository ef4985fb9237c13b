//! Which element vertices indirect light is computed at, and how the others get theirs.
//!
//! The element mesh is as fine as direct light needs: small elements across every penumbra
//! and towards every contact corner. Indirect light is smooth there (a penumbra is a
//! feature of one small source; light from the whole room blurs it), so computing it at
//! every vertex spends most of the stage on values its neighbours already imply. Instead
//! a subset of vertices at least `spacing` apart is kept, chosen greedily with the
//! corners and borders of each face's mesh first, and every other vertex takes a
//! moving-least-squares linear fit of the kept vertices around it.
//!
//! "Around" follows the mesh, not the plane: a vertex on a D0 row (a box's foot) has one
//! copy per side and the two sides share no triangle. Where the sides do share triangles
//! (the foot of a box's unlit back face, both sides in umbra) the mesh is cut for this
//! purpose: between the part under a box (`covered::covers`) and the rest, and at vertices
//! where triangles meet only at a point. Vertices on such a cut are all kept and pass
//! nothing on, so light under a box never leaks into the floor beside it, nor back.
//! Each vertex belongs to the kept vertex nearest along the remaining edges (a graph
//! Voronoi cell); two kept vertices are neighbours when an edge joins their cells; a vertex
//! interpolates from its cell's kept vertex and that one's neighbours.

use std::cmp::Reverse;
use std::collections::{BinaryHeap, VecDeque};

use glam::{DVec2, DVec3};

use super::mls::{fit, shepard};
use crate::mesh::elements::Elements;
use crate::scene::Face;

/// Boundary vertices where the border turns by more than this (radians) are always kept:
/// corners of faces and ends of D0 rows, where a fit would have to extrapolate.
const CORNER_TURN: f64 = 0.35;
/// Interpolated values whose two interpolants differ by more than this fraction of the
/// largest value they use are computed instead (`Gather::spread`).
const UNSURE: f64 = 0.03;
/// Near a contact the spacing is at most this times the distance to it (`spacings`).
const GRADE: f64 = 0.5;

pub(super) struct Gather {
    /// Whether each element vertex is evaluated.
    pub(super) kept: Vec<bool>,
    /// For a vertex not kept, its weights over kept vertices (summing to 1):
    /// `weights[start[v]..start[v + 1]]`; empty for kept vertices.
    start: Vec<u32>,
    weights: Vec<(u32, f64)>,
    /// A second, lower-order interpolant of the same vertex (empty where the first is
    /// already low-order): `check[check_start[v]..check_start[v + 1]]`.
    check_start: Vec<u32>,
    check: Vec<(u32, f64)>,
}

impl Gather {
    /// Every vertex kept: what `spacing` 0 gives.
    pub(super) fn all(nv: usize) -> Self {
        Gather {
            kept: vec![true; nv],
            start: vec![0; nv + 1],
            weights: Vec::new(),
            check_start: vec![0; nv + 1],
            check: Vec::new(),
        }
    }

    /// `covers` as from `covered::covers`; `tol`, the distance within which a vertex counts
    /// as on a cover's edge.
    pub(super) fn new(
        faces: &[Face],
        covers: &[Vec<Vec<DVec2>>],
        el: &Elements,
        spacing: f64,
        tol: f64,
    ) -> Self {
        let nv = el.positions.len();
        if !(spacing > 0.0) || nv == 0 {
            return Gather::all(nv);
        }
        let uv: Vec<DVec2> = el
            .positions
            .iter()
            .zip(&el.vertex_face)
            .map(|(x, &f)| faces[f as usize].frame.to_2d(*x))
            .collect();
        let class = classes(faces, covers, el, tol);
        let adj = Adjacency::new(&el.triangles, &class);
        let spacing = spacings(&uv, el, &class, spacing);
        let kept = choose(&uv, &adj, &priorities(&uv, &adj), &spacing);
        // Every vertex with no edge left is kept (`priorities`), and every other is in a
        // component with a kept vertex, so all are reached.
        let (_, cell) = nearest(&uv, &adj, &kept);
        let near = neighbours(&adj, &cell, nv);

        let mut start = Vec::with_capacity(nv + 1);
        let mut weights = Vec::new();
        let mut check_start = Vec::with_capacity(nv + 1);
        let mut check = Vec::new();
        start.push(0);
        check_start.push(0);
        let mut cands = Vec::new();
        for v in 0..nv {
            if !kept[v] {
                // Quadratic over the cell's kept vertex, its neighbours and theirs; linear over
                // the first ring where those do not span a conic; inverse distance where the
                // points lie on a line (a narrow strip).
                let c = cell[v];
                cands.clear();
                cands.push(c);
                cands.extend_from_slice(near.of(c));
                let ring = cands.len();
                for i in 1..ring {
                    cands.extend_from_slice(near.of(cands[i]));
                }
                cands.sort_unstable();
                cands.dedup();
                let quadratic = fit::<6>(uv[v], &cands, &uv, &mut weights);
                cands.clear();
                cands.push(c);
                cands.extend_from_slice(near.of(c));
                // The check: a linear fit over the first ring, or inverse distance. Where
                // it and the quadratic disagree, light is not smooth there.
                let out = if quadratic { &mut check } else { &mut weights };
                if !fit::<3>(uv[v], &cands, &uv, out) {
                    shepard(uv[v], &cands, &uv, out);
                }
            }
            start.push(weights.len() as u32);
            check_start.push(check.len() as u32);
        }
        Gather {
            kept,
            start,
            weights,
            check_start,
            check,
        }
    }

    pub(super) fn kept_count(&self) -> usize {
        self.kept.iter().filter(|&&k| k).count()
    }

    /// A weighted mean over element vertices (`Patch::weights`) as one over kept vertices
    /// only, sorted by vertex.
    pub(super) fn compose(&self, w: &[(u32, f64)]) -> Vec<(u32, f64)> {
        let mut out: Vec<(u32, f64)> = Vec::with_capacity(w.len());
        for &(v, a) in w {
            if self.kept[v as usize] {
                out.push((v, a));
            } else {
                let (s, e) = (self.start[v as usize], self.start[v as usize + 1]);
                out.extend(
                    self.weights[s as usize..e as usize]
                        .iter()
                        .map(|&(k, b)| (k, a * b)),
                );
            }
        }
        out.sort_unstable_by_key(|e| e.0);
        let mut merged: Vec<(u32, f64)> = Vec::with_capacity(out.len());
        for (k, a) in out {
            match merged.last_mut() {
                Some(last) if last.0 == k => last.1 += a,
                _ => merged.push((k, a)),
            }
        }
        merged
    }

    /// Fills the vertices not kept from the kept ones, and returns those where the
    /// interpolants disagree by more than `UNSURE` of the largest value they draw on: light
    /// changes there faster than the kept vertices can show (an emitter's shadow, the
    /// shadow of a bright wall's light beside a box), and the caller computes them.
    /// A linear fit can overshoot; irradiance is never negative.
    pub(super) fn spread(&self, values: &mut [DVec3]) -> Vec<u32> {
        let at = |w: &[(u32, f64)], values: &[DVec3]| -> (DVec3, f64) {
            w.iter().fold((DVec3::ZERO, 0.0f64), |(s, m), &(k, b)| {
                let x = values[k as usize];
                (s + x * b, m.max(x.max_element()))
            })
        };
        let mut unsure = Vec::new();
        for v in 0..values.len() {
            if !self.kept[v] {
                let w = &self.weights[self.start[v] as usize..self.start[v + 1] as usize];
                let c = &self.check[self.check_start[v] as usize..self.check_start[v + 1] as usize];
                let (x, top) = at(w, values);
                if !c.is_empty() {
                    let (y, _) = at(c, values);
                    if (x - y).abs().max_element() > UNSURE * top {
                        unsure.push(v as u32);
                    }
                }
                values[v] = x.max(DVec3::ZERO);
            }
        }
        unsure
    }
}

/// Vertex neighbours along element edges, and which edges are on a border (one triangle).
struct Adjacency {
    start: Vec<u32>,
    next: Vec<u32>,
    /// Per vertex, up to two neighbours across border edges (`u32::MAX` for none), and
    /// whether there were more.
    border: Vec<([u32; 2], bool)>,
}

impl Adjacency {
    /// Edges of `triangles` between vertices of one class, other than `CUT`.
    fn new(triangles: &[[u32; 3]], class: &[u8]) -> Self {
        let nv = class.len();
        let mut edges: Vec<(u32, u32)> = Vec::with_capacity(triangles.len() * 3);
        for t in triangles {
            for i in 0..3 {
                let (a, b) = (t[i], t[(i + 1) % 3]);
                let (ca, cb) = (class[a as usize], class[b as usize]);
                if a != b && ca == cb && ca != CUT {
                    edges.push((a.min(b), a.max(b)));
                }
            }
        }
        edges.sort_unstable();
        let mut border = vec![([u32::MAX; 2], false); nv];
        let mut pairs: Vec<(u32, u32)> = Vec::with_capacity(edges.len() * 2);
        let mut i = 0;
        while i < edges.len() {
            let mut j = i + 1;
            while j < edges.len() && edges[j] == edges[i] {
                j += 1;
            }
            let (a, b) = edges[i];
            if j - i == 1 {
                for (p, q) in [(a, b), (b, a)] {
                    let e = &mut border[p as usize];
                    if e.0[0] == u32::MAX {
                        e.0[0] = q;
                    } else if e.0[1] == u32::MAX {
                        e.0[1] = q;
                    } else {
                        e.1 = true;
                    }
                }
            }
            pairs.push((a, b));
            pairs.push((b, a));
            i = j;
        }
        pairs.sort_unstable();
        let (start, next) = csr(pairs, nv);
        Adjacency {
            start,
            next,
            border,
        }
    }

    fn of(&self, v: u32) -> &[u32] {
        &self.next[self.start[v as usize] as usize..self.start[v as usize + 1] as usize]
    }
}

/// 0 for corners of a border (always kept), 1 for other border vertices, 2 inside. Vertices
/// with no edge (in no triangle, or on a cut) count as corners: nothing could interpolate
/// them.
fn priorities(uv: &[DVec2], adj: &Adjacency) -> Vec<u8> {
    adj.border
        .iter()
        .enumerate()
        .map(|(v, &([a, b], more))| {
            if adj.of(v as u32).is_empty() || more {
                0
            } else if a == u32::MAX {
                2
            } else if b == u32::MAX {
                0
            } else {
                let (p, q) = (uv[v] - uv[a as usize], uv[b as usize] - uv[v]);
                let turn = p.perp_dot(q).atan2(p.dot(q)).abs();
                if turn > CORNER_TURN {
                    0
                } else {
                    1
                }
            }
        })
        .collect()
}

/// Greedy cover: in order of priority, then finest spacing first, a vertex not yet within
/// its spacing (through the mesh) of a kept one is kept.
fn choose(uv: &[DVec2], adj: &Adjacency, prio: &[u8], spacing: &[f64]) -> Vec<bool> {
    let nv = uv.len();
    let mut order: Vec<u32> = (0..nv as u32).collect();
    order.sort_by(|&a, &b| {
        let (a, b) = (a as usize, b as usize);
        (prio[a], spacing[a], a)
            .partial_cmp(&(prio[b], spacing[b], b))
            .expect("spacings are finite")
    });
    let mut kept = vec![false; nv];
    let mut covered = vec![false; nv];
    // Marks which search last visited a vertex, so each search starts clean for free.
    let mut seen = vec![u32::MAX; nv];
    let mut queue = VecDeque::new();
    for &v in &order {
        if covered[v as usize] && prio[v as usize] > 0 {
            continue;
        }
        kept[v as usize] = true;
        covered[v as usize] = true;
        let c = uv[v as usize];
        let r = spacing[v as usize];
        seen[v as usize] = v;
        queue.push_back(v);
        while let Some(u) = queue.pop_front() {
            for &w in adj.of(u) {
                let d = (uv[w as usize] - c).length();
                if seen[w as usize] != v && d < r {
                    seen[w as usize] = v;
                    // A vertex that wants a finer spacing than v's is near only if within it.
                    covered[w as usize] |= d < spacing[w as usize];
                    queue.push_back(w);
                }
            }
        }
    }
    kept
}

/// Each vertex's spacing: `base`, but `GRADE` times its distance to the nearest contact (a
/// D0 row, a cut or the border of the face) where closer, down to `base / 16`. Where two
/// faces meet, light from one onto the other changes on the scale of the smaller (a chair's
/// leg), and where two contacts meet (the corner of a box's foot) it depends on the
/// direction to the corner, not on the distance, as direct light does at D0 ends.
fn spacings(uv: &[DVec2], el: &Elements, class: &[u8], base: f64) -> Vec<f64> {
    let all = Adjacency::new(&el.triangles, &vec![OPEN; uv.len()]);
    // Where the mesh does not follow a box's foot (no light changes across it: umbra on
    // both sides), the vertices beside it are those with a neighbour of another class.
    let contact: Vec<bool> = (0..uv.len())
        .map(|v| {
            class[v] == CUT
                || all.border[v].0[0] != u32::MAX
                || el.eval.get(v).is_some_and(|e| *e != el.positions[v])
                || all
                    .of(v as u32)
                    .iter()
                    .any(|&w| class[w as usize] != class[v])
        })
        .collect();
    let (dist, _) = nearest(uv, &all, &contact);
    dist.iter()
        .map(|&d| (GRADE * d).clamp(base / 16.0, base))
        .collect()
}

/// The `from` vertex nearest to each vertex along mesh edges, and how far (multi-source
/// Dijkstra).
fn nearest(uv: &[DVec2], adj: &Adjacency, from: &[bool]) -> (Vec<f64>, Vec<u32>) {
    let nv = uv.len();
    let mut dist = vec![f64::INFINITY; nv];
    let mut cell = vec![u32::MAX; nv];
    let mut heap = BinaryHeap::new();
    for v in 0..nv {
        if from[v] {
            dist[v] = 0.0;
            cell[v] = v as u32;
            heap.push(Reverse((Key(0.0), v as u32)));
        }
    }
    while let Some(Reverse((Key(d), u))) = heap.pop() {
        if d > dist[u as usize] {
            continue;
        }
        for &w in adj.of(u) {
            let nd = d + (uv[w as usize] - uv[u as usize]).length();
            if nd < dist[w as usize] {
                dist[w as usize] = nd;
                cell[w as usize] = cell[u as usize];
                heap.push(Reverse((Key(nd), w)));
            }
        }
    }
    (dist, cell)
}

const OPEN: u8 = 0;
const COVERED: u8 = 1;
/// On the edge of a cover, or where triangles meet only at this vertex.
const CUT: u8 = 2;

/// Each vertex's class, judged at its evaluation point (a hair into its own side on D0
/// rows).
fn classes(faces: &[Face], covers: &[Vec<Vec<DVec2>>], el: &Elements, tol: f64) -> Vec<u8> {
    let mut class: Vec<u8> = (0..el.positions.len())
        .map(|v| {
            let f = el.vertex_face[v] as usize;
            if covers[f].is_empty() {
                return OPEN;
            }
            let q = faces[f]
                .frame
                .to_2d(*el.eval.get(v).unwrap_or(&el.positions[v]));
            let mut on_edge = false;
            for c in &covers[f] {
                // Signed distance inside the convex cover: its smallest over the edges.
                let d = (0..c.len())
                    .map(|k| {
                        let (a, b) = (c[k], c[(k + 1) % c.len()]);
                        (b - a).perp_dot(q - a) / (b - a).length()
                    })
                    .fold(f64::INFINITY, f64::min);
                if d > tol {
                    return COVERED;
                }
                on_edge |= d >= -tol;
            }
            if on_edge {
                CUT
            } else {
                OPEN
            }
        })
        .collect();
    for v in pinches(el) {
        class[v as usize] = CUT;
    }
    class
}

/// Vertices around which the triangles fall into more than one fan (triangles that reach
/// each other across edges at the vertex): two sides that touch at a point only.
fn pinches(el: &Elements) -> Vec<u32> {
    let nv = el.positions.len();
    let (start, around) = el.corners_by_vertex();
    let mut out = Vec::new();
    let mut parent: Vec<usize> = Vec::new();
    let mut others: Vec<(u32, usize)> = Vec::new();
    for v in 0..nv {
        let ring = &around[start[v] as usize..start[v + 1] as usize];
        parent.clear();
        parent.extend(0..ring.len());
        others.clear();
        for (k, &(t, i)) in ring.iter().enumerate() {
            let tri = el.triangles[t as usize];
            others.push((tri[(i as usize + 1) % 3], k));
            others.push((tri[(i as usize + 2) % 3], k));
        }
        others.sort_unstable();
        let mut fans = ring.len();
        for w in others.windows(2) {
            if w[0].0 == w[1].0 {
                let (a, b) = (root(&mut parent, w[0].1), root(&mut parent, w[1].1));
                if a != b {
                    parent[a.max(b)] = a.min(b);
                    fans -= 1;
                }
            }
        }
        if fans > 1 {
            out.push(v as u32);
        }
    }
    out
}

fn root(parent: &mut [usize], mut k: usize) -> usize {
    while parent[k] != k {
        parent[k] = parent[parent[k]];
        k = parent[k];
    }
    k
}

/// Kept vertices whose cells share an element edge.
struct Neighbours {
    start: Vec<u32>,
    next: Vec<u32>,
}

impl Neighbours {
    fn of(&self, k: u32) -> &[u32] {
        &self.next[self.start[k as usize] as usize..self.start[k as usize + 1] as usize]
    }
}

fn neighbours(adj: &Adjacency, cell: &[u32], nv: usize) -> Neighbours {
    let mut pairs = Vec::new();
    for u in 0..nv as u32 {
        for &w in adj.of(u) {
            let (a, b) = (cell[u as usize], cell[w as usize]);
            if a != b && a != u32::MAX && b != u32::MAX {
                pairs.push((a, b));
            }
        }
    }
    pairs.sort_unstable();
    pairs.dedup();
    let (start, next) = csr(pairs, nv);
    Neighbours { start, next }
}

/// Sorted pairs (a, b) as lists of b per a: `next[start[a]..start[a + 1]]`.
fn csr(pairs: Vec<(u32, u32)>, n: usize) -> (Vec<u32>, Vec<u32>) {
    let mut start = vec![0u32; n + 1];
    for &(a, _) in &pairs {
        start[a as usize + 1] += 1;
    }
    for v in 0..n {
        start[v + 1] += start[v];
    }
    (start, pairs.into_iter().map(|(_, b)| b).collect())
}

/// An `f64` ordered for the heap (distances are never NaN).
#[derive(PartialEq, PartialOrd)]
struct Key(f64);
impl Eq for Key {}
impl Ord for Key {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0)
    }
}
