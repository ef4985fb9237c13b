//! Planar regions given as soups of directed boundary edges (counter-clockwise about the
//! region's normal, holes clockwise, in any order), as the hierarchy keeps its leaves: a group
//! of triangles needs no convex split, and contour integrals (`polygon_factor::edges_coupling`)
//! take the soup as it is.

use glam::DVec3;

/// The part of the region `edges` (normal `normal`) lying in front of the plane through `c`
/// with normal `n`, as a soup: the edges' parts in front, and the stretches of the cut line
/// inside the region. Points within `tol` of the plane count as behind it, so a region that
/// touches the plane only along an edge loses that edge, and one lying wholly behind it comes
/// back empty.
///
/// Along the cut line the region's boundary is crossed in turns, in and out (the soup's loops
/// are closed): the crossings sorted along the line pair up into the stretches inside.
pub fn clip_front(
    edges: &[[DVec3; 2]],
    normal: DVec3,
    c: DVec3,
    n: DVec3,
    tol: f64,
    out: &mut Vec<[DVec3; 2]>,
) {
    // Along `d` the region's inside lies on the left (towards `n`): the cut's new edges run
    // that way.
    let d = n.cross(normal);
    let mut cuts: Vec<(f64, DVec3)> = Vec::new();
    for &[a, b] in edges {
        let (da, db) = ((a - c).dot(n), (b - c).dot(n));
        let (fa, fb) = (da > tol, db > tol);
        match (fa, fb) {
            (true, true) => out.push([a, b]),
            (false, false) => {}
            _ => {
                let x = a + (b - a) * (da / (da - db));
                cuts.push((x.dot(d), x));
                out.push(if fa { [a, x] } else { [x, b] });
            }
        }
    }
    cuts.sort_by(|p, q| p.0.total_cmp(&q.0));
    for pair in cuts.chunks_exact(2) {
        if pair[1].0 > pair[0].0 {
            out.push([pair[0].1, pair[1].1]);
        }
    }
}

/// Area of the region `edges` about its normal `normal` (the shoelace formula in 3-D).
pub fn area(edges: &[[DVec3; 2]], normal: DVec3) -> f64 {
    0.5 * edges
        .iter()
        .map(|[a, b]| a.cross(*b).dot(normal))
        .sum::<f64>()
}

#[cfg(test)]
mod test {
    use super::*;
    use crate::geom::polygon_factor::{edges_coupling, polygon_coupling};

    fn ring(p: &[DVec3]) -> Vec<[DVec3; 2]> {
        (0..p.len()).map(|i| [p[i], p[(i + 1) % p.len()]]).collect()
    }

    fn v(x: f64, y: f64, z: f64) -> DVec3 {
        DVec3::new(x, y, z)
    }

    #[test]
    fn an_l_shape_cut_through_both_arms_keeps_the_part_in_front() {
        // The L: [0,2]×[0,1] ∪ [0,1]×[1,2], area 3; in front of x ≥ 0.5 lies 1.5 + 0.5 = 2.
        let l = ring(&[
            v(0., 0., 0.),
            v(2., 0., 0.),
            v(2., 1., 0.),
            v(1., 1., 0.),
            v(1., 2., 0.),
            v(0., 2., 0.),
        ]);
        assert!((area(&l, DVec3::Z) - 3.0).abs() < 1e-12);
        let mut out = Vec::new();
        clip_front(&l, DVec3::Z, v(0.5, 0., 0.), DVec3::X, 1e-12, &mut out);
        assert!(
            (area(&out, DVec3::Z) - 2.0).abs() < 1e-12,
            "{}",
            area(&out, DVec3::Z)
        );
        // A cut that leaves one arm: y ≥ 1.5 keeps [0,1]×[1.5,2].
        out.clear();
        clip_front(&l, DVec3::Z, v(0., 1.5, 0.), DVec3::Y, 1e-12, &mut out);
        assert!((area(&out, DVec3::Z) - 0.5).abs() < 1e-12);
        // Wholly behind, or touching only along an edge: nothing.
        out.clear();
        clip_front(&l, DVec3::Z, v(0., 2., 0.), DVec3::Y, 1e-12, &mut out);
        assert!(out.is_empty());
        // Wholly in front: all of it.
        clip_front(&l, DVec3::Z, v(0., 0., 0.), DVec3::Y, 1e-12, &mut out);
        assert!((area(&out, DVec3::Z) - 3.0).abs() < 1e-12);
    }

    #[test]
    fn a_straddling_pair_couples_as_its_parts_in_front() {
        // A floor square reaching under a wall's plane (x = 0.4), and a wall square facing
        // −x: only the floor's part at x < 0.4 sees the wall, and only the wall's part above
        // the floor.
        let floor = ring(&[v(0., 0., 0.), v(1., 0., 0.), v(1., 1., 0.), v(0., 1., 0.)]);
        let wall = ring(&[
            v(0.4, 0., -0.5),
            v(0.4, 0., 0.5),
            v(0.4, 1., 0.5),
            v(0.4, 1., -0.5),
        ]);
        let nw = -DVec3::X;
        assert!((area(&wall, nw) - 1.0).abs() < 1e-12);
        let (mut f, mut w) = (Vec::new(), Vec::new());
        clip_front(&floor, DVec3::Z, wall[0][0], nw, 1e-12, &mut f);
        clip_front(&wall, nw, floor[0][0], DVec3::Z, 1e-12, &mut w);
        let got = edges_coupling(&f, &w);
        let want = polygon_coupling(
            &[v(0., 0., 0.), v(0.4, 0., 0.), v(0.4, 1., 0.), v(0., 1., 0.)],
            &[
                v(0.4, 0., 0.),
                v(0.4, 0., 0.5),
                v(0.4, 1., 0.5),
                v(0.4, 1., 0.),
            ],
        );
        assert!(want > 0.0);
        assert!((got - want).abs() < 1e-9 * want, "{got} vs {want}");
    }
}
