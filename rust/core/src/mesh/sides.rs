//! The two sides of a D0 edge (a contact line, a plane cut, a point light's shadow edge): the
//! light jumps across it, so the triangles around a vertex on it fall into sectors, one per
//! side, each reading the light a hair inside itself. Shared by refinement, which reads the
//! values element corners will carry, and extraction, which gives each sector its own vertex:
//! both place the reading points with the same arithmetic, so values computed while refining
//! are found again by position.

use glam::DVec2;
use spade::handles::{FixedFaceHandle, FixedVertexHandle, InnerTag};
use spade::{CdtEdge, Point2, Triangulation};

use super::{Cdt, Label};
use crate::geom::polygon::segment_distance as seg_dist;
use crate::regions::relation::Relation;
use crate::regions::{ReceiverRegions, Region};
use crate::scene::Tolerances;

pub(super) type Edge<'a> =
    spade::handles::DirectedEdgeHandle<'a, Point2<f64>, (), CdtEdge<()>, Label>;
pub(super) type Face = FixedFaceHandle<InnerTag>;

/// Which constraint edges are D0: between a region lit by some light and one in its umbra,
/// or along a contact line or plane cut (an occluder meets the receiver there, so light
/// jumps even where both sides are in penumbra).
pub(super) struct D0Test<'a> {
    d0_lines: &'a [[DVec2; 2]],
    grid: LineGrid,
    eps: f64,
    shift: DVec2,
}

impl<'a> D0Test<'a> {
    /// `scale`: the largest coordinate of the mesh (its frame included).
    pub(super) fn new(rr: &'a ReceiverRegions, scale: f64, shift: DVec2) -> Self {
        let eps = 1e-9 * scale;
        D0Test {
            d0_lines: &rr.d0_lines,
            grid: LineGrid::new(&rr.d0_lines, eps),
            eps,
            shift,
        }
    }

    /// Whether the constraint edge `e` between faces labelled `ca` and `cb` is D0.
    pub(super) fn is_d0(&self, e: Edge<'_>, ca: u32, cb: u32, regions: &[Region]) -> bool {
        if ca == cb {
            return false;
        }
        let lit_umbra = regions[ca as usize]
            .relations
            .iter()
            .zip(&regions[cb as usize].relations)
            .any(|(x, y)| {
                matches!(
                    (x, y),
                    (Relation::Lit, Relation::Umbra) | (Relation::Umbra, Relation::Lit)
                )
            });
        if lit_umbra {
            return true;
        }
        let (p, q) = (e.from().position(), e.to().position());
        let (p, q) = (
            DVec2::new(p.x, p.y) - self.shift,
            DVec2::new(q.x, q.y) - self.shift,
        );
        // Boxes first: on a floor under hundreds of objects each constraint edge meets as
        // many contact lines (room-245: two fifths of a direct-only bake in the distances).
        let eps = self.eps;
        let near = |a: DVec2, b: DVec2, p: DVec2| {
            p.x >= a.x.min(b.x) - eps
                && p.x <= a.x.max(b.x) + eps
                && p.y >= a.y.min(b.y) - eps
                && p.y <= a.y.max(b.y) + eps
                && seg_dist(a, b, p) <= eps
        };
        self.grid.at(p).iter().any(|&l| {
            let [a, b] = self.d0_lines[l as usize];
            near(a, b, p) && near(a, b, q)
        })
    }
}

/// The sides of a vertex on D0 edges.
pub(super) struct Sides {
    /// Two D0 edges in a straight line through the vertex: a row, not a corner.
    pub straight: bool,
    /// Faces between consecutive D0 edges (or the receiver's boundary), in order around
    /// the vertex.
    pub sectors: Vec<Vec<Face>>,
}

/// The sides of `v`, or `None` when no D0 edge meets it. `d0` answers for constraint
/// edges; `inside` says which faces belong to the receiver (not to the frame around it).
pub(super) fn sides(
    cdt: &Cdt,
    v: FixedVertexHandle,
    shift: DVec2,
    d0: &dyn Fn(Edge<'_>) -> bool,
    inside: &dyn Fn(Face) -> bool,
) -> Option<Sides> {
    let v = cdt.vertex(v);
    let out: Vec<Edge<'_>> = v.out_edges().collect();
    let n = out.len();
    let cut: Vec<bool> = out
        .iter()
        .map(|e| e.is_constraint_edge() && d0(*e))
        .collect();
    // Start the walk just after a D0 edge so sectors do not wrap.
    let first_cut = (0..n).find(|&k| cut[k])?;
    let p = v.position();
    let p = DVec2::new(p.x, p.y) - shift;
    let cuts: Vec<DVec2> = (0..n)
        .filter(|&k| cut[k])
        .map(|k| {
            let q = out[k].to().position();
            DVec2::new(q.x, q.y) - shift - p
        })
        .collect();
    let straight = cuts.len() == 2
        && cuts[0].dot(cuts[1]) < 0.0
        && cuts[0].perp_dot(cuts[1]).abs() <= 1e-9 * cuts[0].length() * cuts[1].length();
    let mut sectors: Vec<Vec<Face>> = Vec::new();
    let mut current: Vec<Face> = Vec::new();
    for s in 0..n {
        let k = (first_cut + s) % n;
        if s > 0 && cut[k] && !current.is_empty() {
            sectors.push(std::mem::take(&mut current));
        }
        match out[k]
            .face()
            .as_inner()
            .map(|f| f.fix())
            .filter(|f| inside(*f))
        {
            Some(f) => current.push(f),
            // The receiver's boundary ends a sector too: on a boundary vertex the two
            // sides of a D0 line meet again only across the outside.
            None => {
                if !current.is_empty() {
                    sectors.push(std::mem::take(&mut current));
                }
            }
        }
    }
    if !current.is_empty() {
        sectors.push(current);
    }
    Some(Sides { straight, sectors })
}

/// Where a vertex at `p` reads the light for the triangles `tris` around it on its side:
/// moved towards them by at least `tol.d0_offset`, so that the exact side tests of the
/// light stages see it on that side, and by at most a quarter of the nearest vertex.
pub(super) fn nudge(
    p: DVec2,
    tris: impl Iterator<Item = [DVec2; 3]>,
    tol: &Tolerances,
) -> Option<DVec2> {
    let mut dir = DVec2::ZERO;
    let mut shortest = f64::INFINITY;
    for t in tris {
        let c = (t[0] + t[1] + t[2]) / 3.0;
        dir += (c - p).normalize_or_zero();
        for q in t {
            let d = (q - p).length();
            if d > 0.0 {
                shortest = shortest.min(d);
            }
        }
    }
    if dir == DVec2::ZERO || !shortest.is_finite() {
        return None;
    }
    let step = (shortest * 1e-6).max(tol.d0_offset).min(0.25 * shortest);
    Some(p + dir.normalize() * step)
}

/// Segments by the cells of a grid their boxes (grown by `eps`) cover, for point queries.
struct LineGrid {
    lo: DVec2,
    cell: f64,
    n: usize,
    cells: Vec<Vec<u32>>,
}

impl LineGrid {
    /// Cells along each axis at most.
    const SIDE: usize = 64;

    fn new(lines: &[[DVec2; 2]], eps: f64) -> Self {
        let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
        for [a, b] in lines {
            lo = lo.min(a.min(*b));
            hi = hi.max(a.max(*b));
        }
        let n = if lines.len() < 16 { 1 } else { Self::SIDE };
        if !(lo.x <= hi.x && lo.y <= hi.y) {
            return LineGrid {
                lo: DVec2::ZERO,
                cell: 1.0,
                n: 1,
                cells: vec![Vec::new()],
            };
        }
        let lo = lo - DVec2::splat(2.0 * eps);
        let cell = ((hi - lo).max_element() + 4.0 * eps) / n as f64;
        let cell = if cell > 0.0 { cell } else { 1.0 };
        let mut grid = LineGrid {
            lo,
            cell,
            n,
            cells: vec![Vec::new(); n * n],
        };
        for (l, [a, b]) in lines.iter().enumerate() {
            let (i0, j0) = grid.index(a.min(*b) - DVec2::splat(eps));
            let (i1, j1) = grid.index(a.max(*b) + DVec2::splat(eps));
            for j in j0..=j1 {
                for i in i0..=i1 {
                    grid.cells[j * n + i].push(l as u32);
                }
            }
        }
        grid
    }

    fn index(&self, p: DVec2) -> (usize, usize) {
        let f = (p - self.lo) / self.cell;
        let clamp = |x: f64| (x.max(0.0) as usize).min(self.n - 1);
        (clamp(f.x), clamp(f.y))
    }

    /// The segments whose grown boxes may hold `p` (and others).
    fn at(&self, p: DVec2) -> &[u32] {
        let (i, j) = self.index(p);
        &self.cells[j * self.n + i]
    }
}
