//! Loop tracing (paper §2.3): every edge gives two half-edges (the paper's forward and
//! backward flags); walking from an unwalked half-edge and turning at each vertex onto the
//! next edge with the smallest left turn closes a loop around one face. Loops that wind
//! counter-clockwise are outer loops of bounded faces; clockwise ones are holes (or the
//! outside of the receiver, which is discarded).

use std::cmp::Ordering;

use glam::DVec2;
use rayon::prelude::*;

use super::{interior, winding, ArrEdge, ArrFace, CHECK_EVERY};
use crate::geom::polygon::orient;
use crate::geom::union_find::UnionFind;
use crate::{BakeError, Progress};

/// Half-edge `h` runs along edge `h / 2`, from `v[0]` to `v[1]` when `h` is even.
#[inline]
fn origin(edges: &[ArrEdge], h: u32) -> u32 {
    edges[(h / 2) as usize].v[(h & 1) as usize]
}

#[inline]
fn dest(edges: &[ArrEdge], h: u32) -> u32 {
    edges[(h / 2) as usize].v[1 - (h & 1) as usize]
}

/// 0 for directions in [0°, 180°), 1 for [180°, 360°), decided exactly by comparisons.
fn half(c: DVec2, p: DVec2) -> u8 {
    if p.y > c.y || (p.y == c.y && p.x > c.x) {
        0
    } else {
        1
    }
}

/// Counter-clockwise order of the directions c→p and c→q, starting at the +x axis.
/// Within one half-plane the span is below 180°, so the exact orientation is a total order.
fn angle_cmp(c: DVec2, p: DVec2, q: DVec2) -> Ordering {
    half(c, p).cmp(&half(c, q)).then_with(|| {
        let o = orient(c, p, q);
        if o > 0.0 {
            Ordering::Less
        } else if o < 0.0 {
            Ordering::Greater
        } else {
            Ordering::Equal
        }
    })
}

/// A number in [0, 4) increasing with the angle of `d` from the +x axis, like `atan2`
/// but cheaper; only used as a first guess before the exact order.
fn pseudo_angle(d: DVec2) -> f64 {
    let s = d.x.abs() + d.y.abs();
    if s <= 0.0 || s.is_nan() {
        return 0.0;
    }
    let r = d.x / s;
    if d.y >= 0.0 {
        1.0 - r
    } else {
        3.0 + r
    }
}

#[derive(Clone, Copy, PartialEq, Debug)]
enum Kind {
    /// Counter-clockwise: the outer loop of a bounded face.
    Outer,
    /// Clockwise: a hole in some face, or the outside of everything.
    Hole,
    /// No area at all: a floating tree of edges, walked once down each side.
    Tree,
}

struct Loop {
    /// Half-edges as walked, dangling edges included.
    walk: Vec<u32>,
    /// The walk with every out-and-back along a dangling edge cancelled.
    reduced: Vec<u32>,
    kind: Kind,
    area: f64,
}

/// The bounded faces of a planar graph whose edges meet only at shared end vertices.
pub(super) fn faces(
    pts: &[DVec2],
    edges: &[ArrEdge],
    progress: &Progress,
) -> Result<Vec<ArrFace>, BakeError> {
    let loops = trace_loops(pts, edges, progress)?;
    let comp = components(pts.len(), edges);

    let outer: Vec<usize> = (0..loops.len())
        .filter(|&i| loops[i].kind == Kind::Outer)
        .collect();
    let outer_box: Vec<(DVec2, DVec2)> = outer
        .iter()
        .map(|&i| bbox(pts, edges, &loops[i].reduced))
        .collect();

    // Each hole (and floating tree) goes to the smallest outer loop of another component
    // around it; components are disjoint, so any one vertex of the hole decides.
    let mut members: Vec<Vec<usize>> = vec![Vec::new(); outer.len()];
    for (li, l) in loops.iter().enumerate() {
        // Each hole is tested against every outer loop around it.
        if li % (CHECK_EVERY / 16) == 0 {
            progress.check()?;
        }
        if l.kind == Kind::Outer {
            continue;
        }
        let v = origin(edges, l.walk[0]);
        let p = pts[v as usize];
        let mut best: Option<usize> = None;
        for (oi, &ol) in outer.iter().enumerate() {
            let o = &loops[ol];
            let (lo, hi) = outer_box[oi];
            if comp[origin(edges, o.walk[0]) as usize] == comp[v as usize]
                || p.x < lo.x
                || p.y < lo.y
                || p.x > hi.x
                || p.y > hi.y
                || best.is_some_and(|b| loops[outer[b]].area <= o.area)
            {
                continue;
            }
            let w = winding(pts, o.reduced.iter().map(|&h| half_edge(edges, h)), p);
            if w != 0 {
                best = Some(oi);
            }
        }
        // Nothing around it: the outside of the receiver.
        if let Some(b) = best {
            members[b].push(li);
        }
    }

    // Faces are built independently: in parallel, in order.
    let face = |(oi, &ol): (usize, &usize)| -> ArrFace {
        let o = &loops[ol];
        let mut area = o.area;
        let mut holes = Vec::new();
        let mut walk: Vec<(u32, u32)> = o.walk.iter().map(|&h| half_edge(edges, h)).collect();
        let mut boundary_edges: Vec<u32> = o.walk.iter().map(|&h| h / 2).collect();
        for &hi in &members[oi] {
            let h = &loops[hi];
            if !h.reduced.is_empty() {
                holes.push(h.reduced.iter().map(|&x| origin(edges, x)).collect());
                area -= h.area.abs();
            }
            walk.extend(h.walk.iter().map(|&x| half_edge(edges, x)));
            boundary_edges.extend(h.walk.iter().map(|&x| x / 2));
        }
        boundary_edges.sort_unstable();
        boundary_edges.dedup();
        ArrFace {
            outer: o.reduced.iter().map(|&h| origin(edges, h)).collect(),
            holes,
            interior: interior::point(pts, &walk),
            area,
            boundary_edges,
        }
    };
    let chunks: Vec<Vec<ArrFace>> = outer
        .par_chunks(CHECK_EVERY)
        .enumerate()
        .map(|(c, chunk)| {
            progress.check()?;
            Ok(chunk
                .iter()
                .enumerate()
                .map(|(k, ol)| face((c * CHECK_EVERY + k, ol)))
                .collect())
        })
        .collect::<Result<_, BakeError>>()?;
    Ok(chunks.into_iter().flatten().collect())
}

#[inline]
fn half_edge(edges: &[ArrEdge], h: u32) -> (u32, u32) {
    (origin(edges, h), dest(edges, h))
}

fn trace_loops(
    pts: &[DVec2],
    edges: &[ArrEdge],
    progress: &Progress,
) -> Result<Vec<Loop>, BakeError> {
    let nh = edges.len() * 2;
    // Outgoing half-edges of every vertex, counter-clockwise: those of vertex v are
    // `around[first[v]..first[v + 1]]`.
    let mut first = vec![0usize; pts.len() + 1];
    for h in 0..nh as u32 {
        first[origin(edges, h) as usize + 1] += 1;
    }
    for v in 0..pts.len() {
        first[v + 1] += first[v];
    }
    let mut around = vec![0u32; nh];
    let mut fill = first.clone();
    for h in 0..nh as u32 {
        let o = origin(edges, h) as usize;
        around[fill[o]] = h;
        fill[o] += 1;
    }
    let mut slot = vec![0u32; nh];
    for (v, &c) in pts.iter().enumerate() {
        if v % CHECK_EVERY == 0 {
            progress.check()?;
        }
        let hs = &mut around[first[v]..first[v + 1]];
        let to = |h: u32| pts[dest(edges, h) as usize];
        // A rounded key sorts nearly right, and insertion with the exact comparison then
        // fixes the neighbours rounding swapped. Insertion (unlike `sort_by`) cannot panic
        // should a degenerate input ever make the comparison inconsistent.
        hs.sort_by(|&x, &y| pseudo_angle(to(x) - c).total_cmp(&pseudo_angle(to(y) - c)));
        for i in 1..hs.len() {
            let mut j = i;
            while j > 0 && angle_cmp(c, to(hs[j - 1]), to(hs[j])) == Ordering::Greater {
                hs.swap(j - 1, j);
                j -= 1;
            }
        }
        for (i, &h) in hs.iter().enumerate() {
            slot[h as usize] = i as u32;
        }
    }
    // Arriving along h, the face on our left continues along the first edge clockwise from
    // the way back: of all edges leaving the vertex, the one with the smallest left turn
    // measured from the reversed arrival direction (the paper's rule). A dangling end has
    // only the way back, so the walk turns around there and goes down the other side.
    let next = |h: u32| -> u32 {
        let back = h ^ 1;
        let v = origin(edges, back) as usize;
        let hs = &around[first[v]..first[v + 1]];
        let i = slot[back as usize] as usize;
        hs[(i + hs.len() - 1) % hs.len()]
    };

    let mut walked = vec![false; nh];
    let mut loops = Vec::new();
    for start in 0..nh as u32 {
        if start as usize % CHECK_EVERY == 0 {
            progress.check()?;
        }
        if walked[start as usize] {
            continue;
        }
        let mut walk = Vec::new();
        let mut h = start;
        // `next` is a permutation of the half-edges, so the walk returns to `start`.
        while !walked[h as usize] {
            walked[h as usize] = true;
            walk.push(h);
            h = next(h);
        }
        let reduced = cancel_spikes(&walk);
        let (kind, area) = classify(pts, edges, &reduced);
        loops.push(Loop {
            walk,
            reduced,
            kind,
            area,
        });
    }
    Ok(loops)
}

/// Removes every half-edge immediately followed by its twin, cyclically (free reduction).
fn cancel_spikes(walk: &[u32]) -> Vec<u32> {
    let mut st: Vec<u32> = Vec::with_capacity(walk.len());
    for &h in walk {
        if st.last() == Some(&(h ^ 1)) {
            st.pop();
        } else {
            st.push(h);
        }
    }
    let (mut i, mut j) = (0, st.len());
    while j - i >= 2 && st[i] == st[j - 1] ^ 1 {
        i += 1;
        j -= 1;
    }
    st[i..j].to_vec()
}

/// Winding of a reduced loop, decided exactly at its lowest (then leftmost) vertex: the face
/// of an outer loop lies above that vertex, so every visit there turns strictly left; the
/// face of a hole wraps below it, so some visit turns right.
fn classify(pts: &[DVec2], edges: &[ArrEdge], reduced: &[u32]) -> (Kind, f64) {
    if reduced.is_empty() {
        return (Kind::Tree, 0.0);
    }
    let key = |v: u32| (pts[v as usize].y, pts[v as usize].x);
    let low = reduced
        .iter()
        .map(|&h| origin(edges, h))
        .min_by(|&a, &b| key(a).partial_cmp(&key(b)).unwrap_or(Ordering::Equal))
        .unwrap_or(0);
    let n = reduced.len();
    let p0 = pts[low as usize];
    let area = loop_area(pts, edges, reduced, p0);
    let mut straight = false;
    for i in 0..n {
        if origin(edges, reduced[i]) != low {
            continue;
        }
        let prev = origin(edges, reduced[(i + n - 1) % n]);
        let next = dest(edges, reduced[i]);
        let o = orient(pts[prev as usize], p0, pts[next as usize]);
        if o < 0.0 {
            return (Kind::Hole, area);
        }
        straight |= o == 0.0;
    }
    // Only overlapping edges that splitting missed can leave a straight visit; fall back to
    // the sign of the area.
    if !straight || area > 0.0 {
        (Kind::Outer, area)
    } else if area < 0.0 {
        (Kind::Hole, area)
    } else {
        (Kind::Tree, 0.0)
    }
}

/// Signed area (shoelace, relative to `p0` to keep the products small).
fn loop_area(pts: &[DVec2], edges: &[ArrEdge], reduced: &[u32], p0: DVec2) -> f64 {
    0.5 * reduced
        .iter()
        .map(|&h| {
            let (a, b) = half_edge(edges, h);
            (pts[a as usize] - p0).perp_dot(pts[b as usize] - p0)
        })
        .sum::<f64>()
}

fn bbox(pts: &[DVec2], edges: &[ArrEdge], hs: &[u32]) -> (DVec2, DVec2) {
    hs.iter().fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), &h| {
            let p = pts[origin(edges, h) as usize];
            (lo.min(p), hi.max(p))
        },
    )
}

/// Connected component of every vertex (union–find).
fn components(n: usize, edges: &[ArrEdge]) -> Vec<u32> {
    let mut sets = UnionFind::new(n);
    for e in edges {
        sets.union(e.v[0], e.v[1]);
    }
    (0..n as u32).map(|v| sets.find(v)).collect()
}
