//! Overlapping UVs: two parts of the surface sharing texels would mix their light, so a
//! lightmap refuses them. Candidate pairs come from a uniform grid over the UV triangles;
//! a pair overlaps when their intersection has area (shared edges and corners do not count).

use glam::{DVec2, DVec3};
use rayon::prelude::*;

use super::raster::{clip, integrate, Attr};
use crate::geom::polygon::orient;

/// Fraction of the smaller triangle's area above which an intersection is an overlap; below
/// it is rounding along a shared edge.
const OVERLAP_FRACTION: f64 = 1e-6;

/// The first pair of overlapping UV triangles found, as `(polygon, polygon)` (the lower index
/// first), or `None`. `tris` are `(polygon, corner UVs)`; zero-area triangles are ignored.
pub(crate) fn find_overlap(tris: &[(u32, [DVec2; 3])]) -> Option<(u32, u32)> {
    let tris: Vec<(u32, [DVec2; 3], f64)> = tris
        .iter()
        .filter_map(|&(p, t)| {
            let a = 0.5 * (t[1] - t[0]).perp_dot(t[2] - t[0]);
            (a != 0.0).then_some((p, t, a.abs()))
        })
        .collect();
    if tris.len() < 2 {
        return None;
    }
    let (lo, hi) = tris.iter().flat_map(|t| t.1).fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(p), hi.max(p)),
    );
    let n = ((tris.len() as f64).sqrt().ceil() as usize).clamp(1, 1024);
    let size = (hi - lo).max(DVec2::splat(1e-300));
    let cell = |p: DVec2| {
        let c = ((p - lo) / size * n as f64).floor();
        (
            (c.x.max(0.0) as usize).min(n - 1),
            (c.y.max(0.0) as usize).min(n - 1),
        )
    };
    let mut grid: Vec<Vec<u32>> = vec![Vec::new(); n * n];
    for (k, (_, t, _)) in tris.iter().enumerate() {
        let (a, b) = (t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2]));
        let ((x0, y0), (x1, y1)) = (cell(a), cell(b));
        for y in y0..=y1 {
            for x in x0..=x1 {
                grid[y * n + x].push(k as u32);
            }
        }
    }
    grid.par_iter().find_map_any(|list| {
        for (i, &a) in list.iter().enumerate() {
            for &b in &list[i + 1..] {
                let (ta, tb) = (&tris[a as usize], &tris[b as usize]);
                if ta.0 != tb.0 && overlap_area(&ta.1, &tb.1) > OVERLAP_FRACTION * ta.2.min(tb.2) {
                    return Some((ta.0.min(tb.0), ta.0.max(tb.0)));
                }
            }
        }
        None
    })
}

/// Area of the intersection of two triangles (either winding).
fn overlap_area(a: &[DVec2; 3], b: &[DVec2; 3]) -> f64 {
    let mut p: Vec<Attr> = a.iter().map(|&p| Attr { p, c: DVec3::ZERO }).collect();
    let mut q = Vec::with_capacity(8);
    let s = orient(b[0], b[1], b[2]).signum();
    for e in 0..3 {
        let (p0, p1) = (b[e], b[(e + 1) % 3]);
        clip(&p, |x| s * (p1 - p0).perp_dot(x - p0), &mut q);
        std::mem::swap(&mut p, &mut q);
        if p.len() < 3 {
            return 0.0;
        }
    }
    integrate(&p).1
}

#[cfg(test)]
mod test {
    use super::*;

    fn t(a: (f64, f64), b: (f64, f64), c: (f64, f64)) -> [DVec2; 3] {
        [a, b, c].map(|(x, y)| DVec2::new(x, y))
    }

    #[test]
    fn shared_edges_are_not_overlaps_but_shared_area_is() {
        let a = t((0., 0.), (1., 0.), (1., 1.));
        let b = t((0., 0.), (1., 1.), (0., 1.));
        assert_eq!(find_overlap(&[(0, a), (1, b)]), None);
        // Two triangles of the same polygon may touch in any way.
        let c = t((0.5, 0.1), (0.9, 0.1), (0.9, 0.5));
        assert_eq!(find_overlap(&[(0, a), (0, c)]), None);
        assert_eq!(find_overlap(&[(3, a), (1, b), (2, c)]), Some((2, 3)));
        // Mirrored (clockwise) islands are still checked.
        let cw = t((0.6, 0.2), (0.6, 0.9), (1.2, 0.2));
        assert_eq!(find_overlap(&[(5, b), (7, cw)]), Some((5, 7)));
    }

    #[test]
    fn many_disjoint_cells_pass() {
        let mut tris = Vec::new();
        for j in 0..40 {
            for i in 0..40 {
                let (x, y) = (i as f64 / 40.0, j as f64 / 40.0);
                let d = 1.0 / 40.0;
                tris.push((tris.len() as u32, t((x, y), (x + d, y), (x + d, y + d))));
                tris.push((tris.len() as u32, t((x, y), (x + d, y + d), (x, y + d))));
            }
        }
        assert_eq!(find_overlap(&tris), None);
        tris.push((9999, t((0.3, 0.3), (0.31, 0.3), (0.3, 0.31))));
        assert!(find_overlap(&tris).is_some());
    }
}
