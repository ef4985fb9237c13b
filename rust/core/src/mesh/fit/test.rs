//! The fit against a quadratic light, whose error integrals are known in closed form on
//! each triangle.

use glam::{DVec2, DVec3};

use super::*;
use crate::regions::Region;

/// A grid of n × n squares on [0, 1]², each cut into two triangles along alternating
/// diagonals, lit by `f` (channel x; y and z zero).
fn grid(n: usize, f: &dyn Fn(DVec2) -> f64) -> ReceiverMesh {
    let mut positions = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            positions.push(DVec2::new(i as f64, j as f64) / n as f64);
        }
    }
    let at = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    let mut triangles = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let [a, b, c, d] = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
            if (i + j) % 2 == 0 {
                triangles.extend([[a, b, c], [a, c, d]]);
            } else {
                triangles.extend([[a, b, d], [b, c, d]]);
            }
        }
    }
    let known_direct = positions
        .iter()
        .map(|p| Some((DVec3::new(f(*p), 0.0, 0.0), [0, 1, 0])))
        .collect();
    ReceiverMesh {
        eval: positions.clone(),
        tri_region: vec![0; triangles.len()],
        regions: vec![Region {
            relations: vec![Relation::Lit],
            ..Region::default()
        }],
        positions,
        triangles,
        known_direct,
        ..ReceiverMesh::default()
    }
}

/// The L2 norm over the mesh of f − interpolant and its largest value, by the midpoint
/// rule on 144 sub-triangles of each triangle.
fn squared_error(m: &ReceiverMesh, f: &dyn Fn(DVec2) -> f64) -> (f64, f64) {
    let value = |v: u32| m.known_direct[v as usize].unwrap().0.x;
    let (mut sum, mut worst) = (0.0, 0.0f64);
    let k = 12;
    for tri in &m.triangles {
        let p = tri.map(|v| m.positions[v as usize]);
        let area = 0.5 * (p[1] - p[0]).perp_dot(p[2] - p[0]).abs();
        let mut s = 0.0;
        let mut count = 0;
        for a in 0..k {
            for b in 0..k - a {
                for up in [false, true] {
                    if up && a + b + 1 >= k {
                        continue;
                    }
                    let (l1, l2) = if up {
                        (
                            (a as f64 + 2.0 / 3.0) / k as f64,
                            (b as f64 + 2.0 / 3.0) / k as f64,
                        )
                    } else {
                        (
                            (a as f64 + 1.0 / 3.0) / k as f64,
                            (b as f64 + 1.0 / 3.0) / k as f64,
                        )
                    };
                    let l0 = 1.0 - l1 - l2;
                    let q = p[0] * l0 + p[1] * l1 + p[2] * l2;
                    let interp = value(tri[0]) * l0 + value(tri[1]) * l1 + value(tri[2]) * l2;
                    let e = f(q) - interp;
                    s += e * e;
                    worst = worst.max(e.abs());
                    count += 1;
                }
            }
        }
        sum += s / count as f64 * area;
    }
    (sum.sqrt(), worst)
}

fn fitted(n: usize, f: &(dyn Fn(DVec2) -> f64 + Sync)) -> (ReceiverMesh, ReceiverMesh, u64) {
    let nodal = grid(n, f);
    let mut m = nodal.clone();
    let light = |p: DVec2, _: &[&Region]| (DVec3::new(f(p), 0.0, 0.0), [0, 1, 0]);
    let lights = Lights {
        at: &light,
        polygonal: vec![true],
    };
    let evaluated = fit(&mut m, &[], &Cache::default(), &lights, 1.0);
    (nodal, m, evaluated)
}

#[test]
fn a_quadratic_light_is_fitted_closer_than_sampled() {
    // A peak under a lamp: concave, as the light near its brightest point. The fit's L2
    // error is 0.27 of the sampled values', its largest 0.60.
    let f = |p: DVec2| 2.0 - (p - DVec2::new(0.3, 0.6)).length_squared();
    let n = 8;
    let (nodal, m, evaluated) = fitted(n, &f);
    // Every edge's midpoint was read once: 3n² + 2n edges.
    assert_eq!(evaluated, (3 * n * n + 2 * n) as u64);
    let (l2_nodal, max_nodal) = squared_error(&nodal, &f);
    let (l2_fit, max_fit) = squared_error(&m, &f);
    // Sampled values lie on the light, so the interpolant is below it everywhere; the fit
    // lifts every vertex.
    for (a, b) in nodal.known_direct.iter().zip(&m.known_direct) {
        assert!(b.unwrap().0.x > a.unwrap().0.x);
    }
    assert!(
        l2_fit < 0.35 * l2_nodal,
        "L2 error {l2_fit:e} fitted against {l2_nodal:e} sampled"
    );
    assert!(
        max_fit < 0.7 * max_nodal,
        "largest error {max_fit:e} fitted against {max_nodal:e} sampled"
    );
}

#[test]
fn a_linear_light_is_left_as_it_is() {
    let f = |p: DVec2| 1.0 + 0.5 * p.x - 0.25 * p.y;
    let (nodal, m, _) = fitted(5, &f);
    for (a, b) in nodal.known_direct.iter().zip(&m.known_direct) {
        assert!((a.unwrap().0 - b.unwrap().0).abs().max_element() < 1e-14);
    }
}

#[test]
fn shifts_stay_within_the_tolerance_and_dark_edges_are_not_read() {
    let f = |p: DVec2| 2.0 - 4.0 * (p - DVec2::new(0.5, 0.5)).length_squared();
    let mut m = grid(4, &f);
    let nodal = m.clone();
    // The lower-left triangle's region is in umbra: its three edges are not read.
    m.regions.push(Region {
        relations: vec![Relation::Umbra],
        ..Region::default()
    });
    m.tri_region[0] = 1;
    let light = |p: DVec2, _: &[&Region]| (DVec3::new(f(p), 0.0, 0.0), [0, 1, 0]);
    let lights = Lights {
        at: &light,
        polygonal: vec![true],
    };
    let tolerance = 0.01;
    let evaluated = fit(&mut m, &[], &Cache::default(), &lights, tolerance);
    // 56 edges on a 4 × 4 grid; of the umbra triangle's, only the one on the grid's border
    // is dark on both sides.
    assert_eq!(evaluated, 56 - 1);
    let brightest = 2.0;
    for (a, b) in nodal.known_direct.iter().zip(&m.known_direct) {
        let (a, b) = (a.unwrap().0.x, b.unwrap().0.x);
        let most = (a + FLOOR * brightest) * SAFETY * tolerance;
        assert!(
            (b - a).abs() <= most * (1.0 + 1e-12),
            "{a} → {b}, at most {most}"
        );
    }
    // A corner keeps its value.
    let mut c = nodal.clone();
    let mut corner = vec![false; c.positions.len()];
    corner[12] = true;
    fit(&mut c, &corner, &Cache::default(), &lights, 1.0);
    assert_eq!(c.known_direct[12], nodal.known_direct[12]);
    assert_ne!(c.known_direct[11], nodal.known_direct[11]);
}
