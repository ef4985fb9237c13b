//! Exact factors between near leaves (`link::Ends::link`), by the double contour integral
//! over their boundaries (`geom::polygon_factor`), each cut to the part in front of the
//! other's plane. Near leaves (a wall's strip by a corner, a leg's top under a seat, a floor
//! reaching past a box's side) are where a quadrature over the receiver errs most, and
//! always high or low for every source alike.
//!
//! The integral is the pair's coupling `A_r·F_rs = A_s·F_sr`, the same both ways, and
//! refinement links most near leaf pairs in both directions (cornell: 35.5k exact links,
//! 17.8k pairs): refinement leaves their factors to `fill`, which takes each pair once, in
//! one order, so both links share the same bits and give back exactly what they take.

use glam::DVec3;
use rayon::prelude::*;

use super::hierarchy::Hierarchy;
use super::link::Link;
use crate::geom::edge_soup::clip_front;
use crate::geom::polygon_factor::edges_coupling;
use crate::scene::Face;

/// The coupling `∫∫ cosθr·cosθs / (π·d²)` of leaves `r` and `s` (normals `nr`, `ns`);
/// `None` when either is not a leaf or `r` has no area.
pub fn coupling(h: &Hierarchy, r: u32, s: u32, nr: DVec3, ns: DVec3) -> Option<f64> {
    let (rn, sn) = (&h.nodes[r as usize], &h.nodes[s as usize]);
    if !rn.is_leaf() || !sn.is_leaf() || !(rn.area > 0.0) {
        return None;
    }
    let (re, se) = (h.leaf_edges(r as usize), h.leaf_edges(s as usize));
    let tol = 1e-9 * (rn.radius() + sn.radius());
    let in_front =
        |e: &[[DVec3; 2]], c: DVec3, n: DVec3| e.iter().all(|[a, _]| (*a - c).dot(n) >= -tol);
    if in_front(re, sn.centroid, ns) && in_front(se, rn.centroid, nr) {
        return Some(edges_coupling(re, se));
    }
    let (mut rc, mut sc) = (Vec::new(), Vec::new());
    clip_front(re, nr, sn.centroid, ns, tol, &mut rc);
    clip_front(se, ns, rn.centroid, nr, tol, &mut sc);
    Some(edges_coupling(&rc, &sc))
}

/// The factors refinement left to this (`k` NaN), each pair's coupling taken once with the
/// lower node first, over the receiver's area and times the link's visibility.
pub fn fill(h: &Hierarchy, faces: &[Face], links: &mut [Link]) {
    let mut todo: Vec<(u32, u32, u32)> = links
        .iter()
        .enumerate()
        .filter(|(_, l)| l.k.is_nan())
        .map(|(i, l)| (l.receiver.min(l.source), l.receiver.max(l.source), i as u32))
        .collect();
    todo.sort_unstable();
    let pairs: Vec<&[(u32, u32, u32)]> = todo.chunk_by(|x, y| x.0 == y.0 && x.1 == y.1).collect();
    let normal = |n: u32| faces[h.nodes[n as usize].face as usize].plane.n;
    let values: Vec<f64> = pairs
        .par_iter()
        .with_min_len(64)
        .map(|p| {
            let (a, b) = (p[0].0, p[0].1);
            coupling(h, a, b, normal(a), normal(b)).unwrap_or(0.0)
        })
        .collect();
    for (p, c) in pairs.iter().zip(values) {
        for &(_, _, i) in p.iter() {
            let l = &mut links[i as usize];
            let area = h.nodes[l.receiver as usize].area;
            l.k = (c / area * l.v as f64) as f32;
        }
    }
}

#[cfg(test)]
mod test {
    use super::*;
    use crate::indirect::patches::test::grid_elements;
    use crate::scene::test::face;

    #[test]
    fn both_directions_share_one_coupling_and_sum_to_the_corner_factor() {
        let v = DVec3::new;
        // Two unit squares meeting at a right angle along x (a floor and a wall).
        let floor = face(
            &[v(0., 0., 0.), v(1., 0., 0.), v(1., 1., 0.), v(0., 1., 0.)],
            DVec3::ONE,
            DVec3::ZERO,
        );
        let wall = face(
            &[v(0., 0., 0.), v(0., 0., 1.), v(1., 0., 1.), v(1., 0., 0.)],
            DVec3::ONE,
            DVec3::ZERO,
        );
        let faces = [floor, wall];
        let el = grid_elements(&faces, 3);
        let mut h = Hierarchy::build(&faces, &el, |_| true, 0.0);
        h.set_boxes(&faces, &el);
        let leaves: Vec<u32> = (0..h.nodes.len() as u32)
            .filter(|&i| h.nodes[i as usize].is_leaf())
            .collect();
        let on = |f: u32| -> Vec<u32> {
            leaves
                .iter()
                .copied()
                .filter(|&i| h.nodes[i as usize].face == f)
                .collect()
        };
        let mut links = Vec::new();
        for a in on(0) {
            for b in on(1) {
                for (r, s) in [(a, b), (b, a)] {
                    let mut ends = super::super::link::Ends::new(&h, &faces, r, s);
                    ends.defer_exact = true;
                    let l = ends.link(
                        &h,
                        &el,
                        r,
                        s,
                        0.5,
                        false,
                        super::super::link::Factor::Sampled,
                    );
                    links.push(l);
                }
            }
        }
        let deferred = links.iter().filter(|l| l.k.is_nan()).count();
        // The pairs near each other (by the edge they share) are left to `fill`.
        assert!(
            deferred > 8 && deferred < links.len(),
            "{deferred} of {}",
            links.len()
        );
        fill(&h, &faces, &mut links);
        let area = |n: u32| h.nodes[n as usize].area;
        let (mut floor_to_wall, mut wall_to_floor) = (0.0, 0.0);
        for pair in links.chunks(2) {
            let (x, y) = (pair[0], pair[1]);
            // A_r·k over v is the coupling, the same both ways to f32's precision.
            let (cx, cy) = (area(x.receiver) * x.k as f64, area(y.receiver) * y.k as f64);
            assert!((cx - cy).abs() <= 1e-6 * cx.max(cy), "{cx} {cy}");
            floor_to_wall += 2.0 * cx;
            wall_to_floor += 2.0 * cy;
        }
        // F between unit squares at a right angle along a shared edge: 0.2000438.
        assert!((floor_to_wall - 0.2000438).abs() < 1e-5, "{floor_to_wall}");
        assert!((wall_to_floor - 0.2000438).abs() < 1e-5, "{wall_to_floor}");
    }
}
