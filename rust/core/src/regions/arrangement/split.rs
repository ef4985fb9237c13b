//! Splitting edges at crossings, touches and collinear overlaps until no two edges meet
//! except at shared end vertices.
//!
//! Candidate pairs come from a uniform grid (each edge registered in the cells it passes
//! through), so edges far apart are never compared: near-linear for the usual receiver with
//! hundreds of short, mostly disjoint shadow edges, instead of the paper's all-pairs T_idd.

use glam::DVec2;
use rayon::prelude::*;

use super::int_hash::IntMap;
use super::snap::VertexPool;
use super::CHECK_EVERY;
use crate::geom::polygon::orient;
use crate::geom::union_find::UnionFind;
use crate::{BakeError, Progress};

/// Snapping a crossing point moves an edge by up to `snap`, which can make it meet an edge
/// it did not meet before; each round fixes those. Ordinary inputs settle in one or two
/// rounds, the bundles of near-duplicate edges in the stress tests in at most nine. Should
/// the cap be reached, the edges are traced as they are: faces may then be wrong locally,
/// but nothing panics.
const MAX_ROUNDS: usize = 16;

/// More cells than this per axis buys nothing for the sizes we see and costs memory.
const MAX_GRID: usize = 1024;

#[derive(Debug, Clone)]
pub(super) struct Edge {
    pub v: [u32; 2],
    pub tags: Vec<u32>,
}

impl Edge {
    pub(super) fn new(a: u32, b: u32, tag: u32) -> Self {
        Self {
            v: [a, b],
            tags: vec![tag],
        }
    }
}

/// Splits and merges until no pair of edges crosses, touches in an interior point or overlaps.
pub(super) fn split_all(
    pool: &mut VertexPool,
    edges: Vec<Edge>,
    snap: f64,
    progress: &Progress,
) -> Result<Vec<Edge>, BakeError> {
    let mut edges = merge(edges);
    // Vertices merged into others; the older vertex represents the set, so the receiver
    // corners, inserted first, never move.
    let mut alias = UnionFind::default();
    for _ in 0..MAX_ROUNDS {
        progress.check()?;
        let pairs = candidate_pairs(pool.points(), &edges, snap);
        progress.check()?;
        let mut found = Found {
            splits: vec![Vec::new(); edges.len()],
            merges: Vec::new(),
        };
        // The pair tests read only the edges and the vertices made before this round, so
        // they run in parallel; what they find is applied in pair order, crossing points
        // inserted into the pool in that order too, so the result does not depend on the
        // number of threads.
        let pts = pool.points();
        let outcomes: Vec<Vec<Outcome>> = pairs
            .par_chunks(CHECK_EVERY)
            .map(|chunk| {
                progress.check()?;
                Ok(chunk
                    .iter()
                    .filter_map(|&(i, j)| test_pair(pts, &edges, (i as usize, j as usize), snap))
                    .collect())
            })
            .collect::<Result<_, BakeError>>()?;
        for o in outcomes.into_iter().flatten() {
            apply_outcome(pool, &alias, &edges, o, &mut found);
        }
        if !found.merges.is_empty() {
            // Splits found this round may name merged vertices; the next round finds them
            // again on the contracted edges.
            for (p, q) in found.merges {
                alias.union(p, q);
            }
            edges = merge(
                edges
                    .into_iter()
                    .map(|e| Edge {
                        v: e.v.map(|v| alias.root(v)),
                        tags: e.tags,
                    })
                    .collect(),
            );
            continue;
        }
        if found.splits.iter().all(Vec::is_empty) {
            break;
        }
        edges = apply_splits(pool.points(), edges, &found.splits);
    }
    Ok(edges)
}

/// What one round of pair tests asks for.
struct Found {
    /// Vertices at which each edge must be split.
    splits: Vec<Vec<u32>>,
    /// Vertex pairs to be made one.
    merges: Vec<(u32, u32)>,
}

/// One edge per vertex pair, carrying the tags of everything that landed on it.
fn merge(edges: Vec<Edge>) -> Vec<Edge> {
    let mut index: IntMap<(u32, u32), usize> =
        IntMap::with_capacity_and_hasher(edges.len(), Default::default());
    let mut out: Vec<Edge> = Vec::with_capacity(edges.len());
    for e in edges {
        let [a, b] = e.v;
        if a == b {
            continue;
        }
        let key = (a.min(b), a.max(b));
        match index.get(&key) {
            Some(&i) => out[i].tags.extend_from_slice(&e.tags),
            None => {
                index.insert(key, out.len());
                out.push(Edge {
                    v: [key.0, key.1],
                    tags: e.tags,
                });
            }
        }
    }
    for e in &mut out {
        e.tags.sort_unstable();
        e.tags.dedup();
    }
    out
}

/// Pairs of edges (i < j) that share at least one grid cell, with each edge dilated by
/// `snap` plus a rounding margin so that edges within `snap` of each other always share one.
pub(super) fn candidate_pairs(pts: &[DVec2], edges: &[Edge], snap: f64) -> Vec<(u32, u32)> {
    if edges.len() < 2 {
        return Vec::new();
    }
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    for e in edges {
        for &v in &e.v {
            lo = lo.min(pts[v as usize]);
            hi = hi.max(pts[v as usize]);
        }
    }
    let size = (hi - lo).max_element().max(f64::MIN_POSITIVE);
    let margin = snap + size * 1e-12;
    let k = ((edges.len() as f64).sqrt().ceil() as usize).clamp(1, MAX_GRID);
    let cw = ((hi.x - lo.x) / k as f64).max(size / MAX_GRID as f64);
    let ch = ((hi.y - lo.y) / k as f64).max(size / MAX_GRID as f64);
    let col = |x: f64| (((x - lo.x) / cw).floor().max(0.0) as usize).min(k - 1);
    let row = |y: f64| (((y - lo.y) / ch).floor().max(0.0) as usize).min(k - 1);

    let mut cells: Vec<(u32, u32)> = Vec::with_capacity(edges.len() * 4);
    for (ei, e) in edges.iter().enumerate() {
        let (a, b) = (pts[e.v[0] as usize], pts[e.v[1] as usize]);
        let (xmin, xmax) = (a.x.min(b.x), a.x.max(b.x));
        let (ymin, ymax) = (a.y.min(b.y), a.y.max(b.y));
        for c in col(xmin - margin)..=col(xmax + margin) {
            // The part of the edge whose x is within `margin` of this column.
            let s0 = (lo.x + c as f64 * cw - margin).clamp(xmin, xmax);
            let s1 = (lo.x + (c + 1) as f64 * cw + margin).clamp(xmin, xmax);
            let (y0, y1) = if b.x == a.x {
                (ymin, ymax)
            } else {
                let slope = (b.y - a.y) / (b.x - a.x);
                let ya = (a.y + (s0 - a.x) * slope).clamp(ymin, ymax);
                let yb = (a.y + (s1 - a.x) * slope).clamp(ymin, ymax);
                (ya.min(yb), ya.max(yb))
            };
            for r in row(y0 - margin)..=row(y1 + margin) {
                cells.push(((r * k + c) as u32, ei as u32));
            }
        }
    }
    cells.par_sort_unstable();
    let mut pairs = Vec::new();
    let mut start = 0;
    while start < cells.len() {
        let mut end = start + 1;
        while end < cells.len() && cells[end].0 == cells[start].0 {
            end += 1;
        }
        for i in start..end {
            for j in i + 1..end {
                pairs.push((cells[i].1, cells[j].1));
            }
        }
        start = end;
    }
    pairs.par_sort_unstable();
    pairs.dedup();
    pairs
}

/// What the test of one pair of edges found: touches (a vertex of one on the other),
/// or else a proper crossing, not yet a vertex.
enum Outcome {
    Touches(Vec<(Touch, u32, usize)>),
    Crossing { i: usize, j: usize, at: DVec2 },
}

/// How edges `i` and `j` meet, if they meet other than at a shared end vertex.
fn test_pair(pts: &[DVec2], edges: &[Edge], (i, j): (usize, usize), snap: f64) -> Option<Outcome> {
    let [a, b] = edges[i].v;
    let [c, d] = edges[j].v;
    // An end vertex of one lying on (or within `snap` of) the other's interior splits it:
    // T-junctions, collinear overlaps and endpoints on the boundary all come through here.
    // Such a touch also settles any crossing of the two: once split at the touching vertex
    // they share it. Computing the crossing as well would give a second, ill-conditioned
    // point when they are nearly collinear, and the two points would keep splitting the
    // pieces round after round.
    let mut touches = Vec::new();
    for (p, (u, w), target) in [
        (c, (a, b), i),
        (d, (a, b), i),
        (a, (c, d), j),
        (b, (c, d), j),
    ] {
        if p == u || p == w {
            continue;
        }
        match touch(pts, u, w, p, snap) {
            Touch::Apart => continue,
            t => touches.push((t, p, target)),
        }
    }
    if !touches.is_empty() {
        return Some(Outcome::Touches(touches));
    }
    if a == c || a == d || b == c || b == d {
        return None;
    }
    let (pa, pb, pc, pd) = (
        pts[a as usize],
        pts[b as usize],
        pts[c as usize],
        pts[d as usize],
    );
    let (o1, o2) = (orient(pa, pb, pc), orient(pa, pb, pd));
    let (o3, o4) = (orient(pc, pd, pa), orient(pc, pd, pb));
    let proper = opposite(o1, o2) && opposite(o3, o4);
    if !proper {
        return None;
    }
    // o3, o4 are twice the signed areas of c-d-a and c-d-b, so they weigh the split of a→b.
    let t = (o3 / (o3 - o4)).clamp(0.0, 1.0);
    Some(Outcome::Crossing {
        i,
        j,
        at: pa + (pb - pa) * t,
    })
}

/// Records where edges must be split, or which vertices must merge, so that a pair meets
/// only at end vertices.
fn apply_outcome(
    pool: &mut VertexPool,
    alias: &UnionFind,
    edges: &[Edge],
    outcome: Outcome,
    found: &mut Found,
) {
    match outcome {
        Outcome::Touches(touches) => {
            for (t, p, target) in touches {
                match t {
                    Touch::Apart => {}
                    Touch::Split => found.splits[target].push(p),
                    Touch::Merge(q) => found.merges.push((p, q)),
                }
            }
        }
        Outcome::Crossing { i, j, at } => {
            let ([a, b], [c, d]) = (edges[i].v, edges[j].v);
            let v = alias.root(pool.insert(at));
            if v != a && v != b {
                found.splits[i].push(v);
            }
            if v != c && v != d {
                found.splits[j].push(v);
            }
        }
    }
}

fn opposite(x: f64, y: f64) -> bool {
    (x > 0.0 && y < 0.0) || (x < 0.0 && y > 0.0)
}

/// A vertex seen from an edge.
enum Touch {
    Apart,
    /// On the edge's interior, or within `snap` of it: the edge is split there.
    Split,
    /// Within `snap` of the edge but also within [`CLUSTER`] × `snap` of this end of it:
    /// merged with that end instead.
    Merge(u32),
}

/// Splitting an edge at a vertex this close to one of its ends leaves pieces so short that,
/// in a cluster of near-duplicate edges, they can go on splitting each other round after
/// round (every piece already exists); merging the vertices ends it.
const CLUSTER: f64 = 4.0;

/// How vertex `p` relates to the segment `u`–`w` (`p` being neither end).
fn touch(pts: &[DVec2], u: u32, w: u32, p: u32, snap: f64) -> Touch {
    let (a, b, q) = (pts[u as usize], pts[w as usize], pts[p as usize]);
    let ab = b - a;
    let o = orient(a, b, q);
    if o == 0.0 {
        // Exactly collinear: order along the dominant axis is the order along the line.
        let inside = if ab.x.abs() >= ab.y.abs() {
            q.x > a.x.min(b.x) && q.x < a.x.max(b.x)
        } else {
            q.y > a.y.min(b.y) && q.y < a.y.max(b.y)
        };
        return if inside { Touch::Split } else { Touch::Apart };
    }
    if snap <= 0.0 {
        return Touch::Apart;
    }
    let len2 = ab.length_squared();
    let t = (q - a).dot(ab) / len2;
    if !(t > 0.0 && t < 1.0) || ab.perp_dot(q - a).abs() / len2.sqrt() > snap {
        return Touch::Apart;
    }
    let (da, db) = ((q - a).length(), (q - b).length());
    if da.min(db) <= CLUSTER * snap {
        Touch::Merge(if da <= db { u } else { w })
    } else {
        Touch::Split
    }
}

/// Replaces every edge with splits by the chain through its split vertices, in order along it.
fn apply_splits(pts: &[DVec2], edges: Vec<Edge>, splits: &[Vec<u32>]) -> Vec<Edge> {
    let mut out: Vec<Edge> = Vec::with_capacity(edges.len() + splits.len());
    for (e, s) in edges.into_iter().zip(splits) {
        if s.is_empty() {
            out.push(e);
            continue;
        }
        let [a, b] = e.v;
        let (pa, pb) = (pts[a as usize], pts[b as usize]);
        let dir = pb - pa;
        let mut inner: Vec<(f64, u32)> = s
            .iter()
            .filter(|&&v| v != a && v != b)
            .map(|&v| ((pts[v as usize] - pa).dot(dir), v))
            .collect();
        inner.sort_unstable_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        inner.dedup_by_key(|x| x.1);
        let mut prev = a;
        for v in inner.iter().map(|x| x.1).chain(std::iter::once(b)) {
            if v != prev {
                out.push(Edge {
                    v: [prev, v],
                    tags: e.tags.clone(),
                });
            }
            prev = v;
        }
    }
    merge(out)
}
