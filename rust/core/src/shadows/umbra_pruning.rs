//! What lies inside another occluder's umbra on a receiver is no discontinuity: every point
//! there is in umbra of that light whatever else hides it, so both sides of an edge there
//! are umbra (the redundancy rule of `regions` would drop the edge after paying for its
//! crossings), and a shadow polygon wholly inside an umbra polygon decides nothing. Among
//! many small occluders (clutter on a table, a table over a floor) most shadow edges lie in
//! such umbrae and their crossings grow with the square of their number; taking them out
//! first keeps the arrangement near the size of the visible shadow boundaries.
//!
//! Exactness: a polygon is dropped only when an exact predicate puts all its vertices on or
//! inside a kept umbra polygon of the same light. A segment loses the part inside an umbra
//! polygon of its light (cut where it crosses the boundary, so the pieces left end on it),
//! and only when some of it lies inside by more than `margin` (distance to every edge line):
//! rounding can never remove a piece of edge that runs along an umbra boundary.
//!
//! The parts of a receiver inside closed solids (`ReceiverShadows::inside`) are umbra of
//! every light, so they cover like an umbra of each light. Lines that belong to every light
//! (plane cuts, contacts) are covered by them, and, for a bake of direct light only, by the
//! umbrae of the one light that reaches the receiver when only one does. (Indirect light
//! still jumps across a contact in umbra: zero under the box, bounced light beside it.)
//! Where solids interpenetrate (clutter heaped on a table) these are most of the lines.

use glam::DVec2;

use crate::geom::box_grid::{bounds, BoxGrid};
use crate::geom::polygon::{clip_segment_deep, convex_edges_into, inside_convex, signed_area_2d};
use crate::shadows::polygons::{Exposure, ShadowPolygon};

/// Removes from `polys` every polygon that lies inside another (kept) umbra polygon of the
/// same light, or inside one of `inside` (parts of the receiver inside solids). Of several
/// equal umbra polygons the first is kept.
pub fn drop_covered(polys: &mut Vec<ShadowPolygon>, inside: &[Vec<DVec2>]) {
    let umbrae: Vec<u32> = (0..polys.len() as u32)
        .filter(|&i| polys[i as usize].umbra)
        .collect();
    if (umbrae.is_empty() || polys.len() < 2) && inside.is_empty() {
        return;
    }
    let boxes: Vec<(DVec2, DVec2)> = umbrae
        .iter()
        .map(|&i| bounds(&polys[i as usize].poly))
        .collect();
    let area: Vec<f64> = polys.iter().map(|p| signed_area_2d(&p.poly)).collect();
    let grid = BoxGrid::new(&boxes);
    let inside_boxes: Vec<(DVec2, DVec2)> = inside.iter().map(|p| bounds(p)).collect();
    let inside_grid = BoxGrid::new(&inside_boxes);
    let mut cand = Vec::new();
    let keep: Vec<bool> = (0..polys.len())
        .map(|i| {
            let p = &polys[i];
            let (lo, hi) = bounds(&p.poly);
            let holds = |(ulo, uhi): (DVec2, DVec2), q: &[DVec2]| {
                ulo.x <= lo.x
                    && ulo.y <= lo.y
                    && uhi.x >= hi.x
                    && uhi.y >= hi.y
                    && p.poly.iter().all(|&v| inside_convex(q, v))
            };
            inside_grid.meeting(lo, hi, &mut cand);
            if cand
                .iter()
                .any(|&k| holds(inside_boxes[k as usize], &inside[k as usize]))
            {
                return false;
            }
            grid.meeting(lo, hi, &mut cand);
            !cand.iter().any(|&u| {
                let j = umbrae[u as usize] as usize;
                let q = &polys[j];
                // A larger umbra, or an equal one earlier in the list (equal areas and
                // mutual containment mean the same polygon: one of them must stay).
                j != i
                    && q.light == p.light
                    && (area[j] > area[i] || (area[j] == area[i] && j < i))
                    && holds(boxes[u as usize], &q.poly)
            })
        })
        .collect();
    let mut k = 0;
    polys.retain(|_| {
        k += 1;
        keep[k - 1]
    });
}

/// Cuts the lines that belong to every light on one receiver (plane cuts, contacts) where
/// they lie deep inside a part `cover` covers for every light, and critical lines where they
/// lie deep inside an umbra of their light. `sh` must be the receiver `cover` was built from.
pub fn trim_lines(
    cover: &UmbraCover,
    plane_cuts: &mut Vec<[DVec2; 2]>,
    contacts: &mut Vec<[DVec2; 2]>,
    events: &mut Vec<(u32, [DVec2; 2])>,
) {
    if cover.covers.is_empty() {
        return;
    }
    let (mut scratch, mut pieces) = (Vec::new(), Vec::new());
    let mut cut = |lines: &[[DVec2; 2]], light: Option<u32>| -> Vec<[DVec2; 2]> {
        let mut out = Vec::with_capacity(lines.len());
        for &[a, b] in lines {
            pieces.clear();
            cover.uncovered(a, b, light, None, &mut scratch, &mut pieces);
            out.extend(pieces.iter().map(|&(a, b)| [a, b]));
        }
        out
    };
    *plane_cuts = cut(plane_cuts, None);
    *contacts = cut(contacts, None);
    let mut trimmed = Vec::with_capacity(events.len());
    for &(l, e) in events.iter() {
        trimmed.extend(cut(&[e], Some(l)).into_iter().map(|e| (l, e)));
    }
    *events = trimmed;
}

/// The covers of one receiver, for cutting segments: the umbra polygons of each light, and
/// the parts inside solids, which cover for every light. Built once per receiver by the
/// region stage, which cuts with it first the lines of every light (`trim_lines`: plane
/// cuts, contacts, critical lines), then the shadow polygons' edges. One rule serves both:
/// `only_light` decides only for lines that belong to every light, and the polygon edges
/// always name their light.
pub struct UmbraCover<'a> {
    /// Polygon, the light it covers (`None`: every light) and the shadow polygon it is.
    covers: Vec<(&'a [DVec2], Option<u32>, Option<u32>)>,
    /// The one light that reaches the receiver, when only one does: its umbrae then cover
    /// the lines that belong to every light too.
    only_light: Option<u32>,
    /// The covers' bounding boxes, and the grid that holds them.
    boxes: Vec<(DVec2, DVec2)>,
    grid: BoxGrid,
    /// Each cover's edges (`convex_edges`), `lines[spans[i]]`: made once, as `uncovered`
    /// tests a segment against many covers.
    lines: Vec<(DVec2, DVec2, f64)>,
    spans: Vec<(u32, u32)>,
    margin: f64,
}

impl<'a> UmbraCover<'a> {
    pub fn new(
        polys: &'a [ShadowPolygon],
        inside: &'a [Vec<DVec2>],
        exposure: &[Exposure],
        margin: f64,
        only_light_covers_lines: bool,
    ) -> Self {
        let covers: Vec<(&[DVec2], Option<u32>, Option<u32>)> = (0..polys.len() as u32)
            .filter(|&i| polys[i as usize].umbra && polys[i as usize].poly.len() >= 3)
            .map(|i| {
                let p = &polys[i as usize];
                (p.poly.as_slice(), Some(p.light), Some(i))
            })
            .chain(
                inside
                    .iter()
                    .filter(|p| p.len() >= 3)
                    .map(|p| (p.as_slice(), None, None)),
            )
            .collect();
        let boxes: Vec<(DVec2, DVec2)> = covers.iter().map(|c| bounds(c.0)).collect();
        let mut reaching =
            (0..exposure.len() as u32).filter(|&l| exposure[l as usize] != Exposure::Hidden);
        let only_light = match (reaching.next(), reaching.next()) {
            (Some(l), None) if only_light_covers_lines => Some(l),
            _ => None,
        };
        let mut lines = Vec::new();
        let mut spans = Vec::with_capacity(covers.len());
        for (q, _, _) in &covers {
            let start = lines.len() as u32;
            convex_edges_into(q, &mut lines);
            spans.push((start, lines.len() as u32));
        }
        UmbraCover {
            covers,
            only_light,
            grid: BoxGrid::new(&boxes),
            boxes,
            lines,
            spans,
            margin,
        }
    }

    /// The pieces of segment `a`–`b` (an edge made by `light`, or by every light when
    /// `None`; from polygon `own` if any) that are not deep inside a cover of that light,
    /// appended to `out`.
    pub fn uncovered(
        &self,
        a: DVec2,
        b: DVec2,
        light: Option<u32>,
        own: Option<u32>,
        scratch: &mut Vec<u32>,
        out: &mut Vec<(DVec2, DVec2)>,
    ) {
        if self.covers.is_empty() {
            out.push((a, b));
            return;
        }
        let light = light.or(self.only_light);
        let (lo, hi) = (a.min(b), a.max(b));
        self.grid.meeting(lo, hi, scratch);
        let mut cut: Vec<(f64, f64)> = Vec::new();
        let d = b - a;
        for &u in scratch.iter() {
            let (_, l, j) = self.covers[u as usize];
            if (l.is_some() && l != light) || (j.is_some() && j == own) {
                continue;
            }
            // The grid's cells are coarse: most covers they give lie clear of the segment's
            // box, and nothing of it is inside them (a sixth of room-8328's direct-only
            // bake went to clipping against those).
            let (clo, chi) = self.boxes[u as usize];
            if clo.x > hi.x || clo.y > hi.y || chi.x < lo.x || chi.y < lo.y {
                continue;
            }
            // Decided with the margin, cut where the segment crosses the boundary: the
            // pieces left then end on the cover's edges (the arrangement snaps them there)
            // instead of leaving stubs inside that would stay as dangling edges.
            let (s0, s1) = self.spans[u as usize];
            if let Some(deep) =
                clip_segment_deep(&self.lines[s0 as usize..s1 as usize], a, b, self.margin)
            {
                cut.push(deep);
                if deep.0 <= 0.0 && deep.1 >= 1.0 {
                    // All of it is covered: no other cover can leave a piece.
                    return;
                }
            }
        }
        if cut.is_empty() {
            out.push((a, b));
            return;
        }
        cut.sort_by(|x, y| x.0.total_cmp(&y.0));
        let at = |t: f64| if t >= 1.0 { b } else { a + d * t };
        let mut t = 0.0;
        for (t0, t1) in cut {
            if t0 > t {
                out.push((at(t), at(t0)));
            }
            t = t.max(t1);
        }
        if t < 1.0 {
            out.push((at(t), b));
        }
    }
}

#[cfg(test)]
mod test {
    use super::*;

    fn sq(x0: f64, y0: f64, x1: f64, y1: f64, umbra: bool, occluder: u32) -> ShadowPolygon {
        ShadowPolygon {
            light: 0,
            occluder,
            umbra,
            hard: false,
            poly: vec![
                DVec2::new(x0, y0),
                DVec2::new(x1, y0),
                DVec2::new(x1, y1),
                DVec2::new(x0, y1),
            ],
        }
    }

    #[test]
    fn drops_only_polygons_inside_a_kept_umbra_of_the_same_light() {
        let mut other_light = sq(0.2, 0.2, 0.4, 0.4, false, 3);
        other_light.light = 1;
        let mut polys = vec![
            sq(0.0, 0.0, 1.0, 1.0, true, 0),
            sq(0.1, 0.1, 0.5, 0.5, false, 1),
            sq(0.5, 0.5, 1.5, 1.5, false, 2),
            other_light,
            // The same umbra twice: one copy stays.
            sq(0.0, 0.0, 1.0, 1.0, true, 4),
            // Touching the boundary from inside is inside.
            sq(0.0, 0.0, 1.0, 0.5, false, 5),
        ];
        drop_covered(&mut polys, &[]);
        let left: Vec<u32> = polys.iter().map(|p| p.occluder).collect();
        assert_eq!(left, vec![0, 2, 3]);
    }

    #[test]
    fn cuts_segments_deep_inside_and_keeps_edges_along_boundaries() {
        let polys = vec![
            sq(0.0, 0.0, 1.0, 1.0, true, 0),
            sq(2.0, 0.0, 3.0, 1.0, true, 1),
        ];
        let cover = UmbraCover::new(&polys, &[], &[Exposure::Regions; 2], 1e-9, false);
        let (mut s, mut out) = (Vec::new(), Vec::new());
        // Through both squares: the three pieces outside them, ending on their boundaries.
        let (a, b) = (DVec2::new(-1.0, 0.5), DVec2::new(4.0, 0.5));
        cover.uncovered(a, b, Some(0), None, &mut s, &mut out);
        assert_eq!(out.len(), 3);
        assert!(out[0].1.x.abs() < 1e-15 && (out[1].0.x - 1.0).abs() < 1e-15);
        // Along the square's edge, or from another light: untouched.
        for (a, b, l) in [
            (DVec2::new(0.0, -1.0), DVec2::new(0.0, 2.0), 0),
            (DVec2::new(-1.0, 0.5), DVec2::new(4.0, 0.5), 1),
        ] {
            out.clear();
            cover.uncovered(a, b, Some(l), None, &mut s, &mut out);
            assert_eq!(out, vec![(a, b)]);
        }
        // Wholly inside: nothing left.
        out.clear();
        cover.uncovered(
            DVec2::new(0.2, 0.2),
            DVec2::new(0.8, 0.3),
            Some(0),
            None,
            &mut s,
            &mut out,
        );
        assert!(out.is_empty());
    }
}
