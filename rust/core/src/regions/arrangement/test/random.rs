//! Seeded random inputs: chords, floating pieces, lattice segments with exact coincidences,
//! bundles of near-duplicate edges.

use glam::DVec2;

use super::{check, point_segment_distance, pts, rect, rect_segments, v};
use crate::regions::arrangement::{build, Arrangement, Segment};

/// splitmix64: a tiny deterministic generator, good enough for test inputs.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A point on the boundary of `poly` at arc parameter `t` ∈ [0, 1) (by edge, not length).
fn on_boundary(poly: &[DVec2], t: f64) -> DVec2 {
    let n = poly.len();
    let s = t * n as f64;
    let i = (s.floor() as usize).min(n - 1);
    poly[i].lerp(poly[(i + 1) % n], s - i as f64)
}

#[test]
fn random_chords_tile_a_convex_polygon() {
    let mut rng = Rng(0x5eed_1234);
    let b: Vec<DVec2> = (0..7)
        .map(|k| {
            let a = k as f64 * std::f64::consts::TAU / 7.0;
            v(3.0 + 2.0 * a.cos(), -1.0 + 1.5 * a.sin())
        })
        .collect();
    let s: Vec<Segment> = (0..200)
        .map(|k| Segment {
            a: on_boundary(&b, rng.unit()),
            b: on_boundary(&b, rng.unit()),
            tag: k,
        })
        .collect();
    let arr = build(&b, &s, 1e-9 * 4.0);
    check(&arr, &b);
    // Euler: one connected component, so bounded faces = E − V + 1.
    assert_eq!(arr.faces.len() + arr.vertices.len(), arr.edges.len() + 1);
    assert!(arr.faces.len() > 2000, "{} faces", arr.faces.len());
    // Faces cut from a convex polygon by chords are convex, and a convex polygon's inradius
    // is at least area / perimeter: the interior point keeps a fair share of that.
    for f in &arr.faces {
        let p = pts(&arr, &f.outer);
        let n = p.len();
        let perimeter: f64 = (0..n).map(|i| (p[(i + 1) % n] - p[i]).length()).sum();
        let clearance = (0..n)
            .map(|i| point_segment_distance(f.interior, p[i], p[(i + 1) % n]))
            .fold(f64::INFINITY, f64::min);
        assert!(clearance >= 0.25 * f.area / perimeter, "{f:?}");
    }
    for e in &arr.edges {
        assert!(!e.tags.is_empty() && e.tags.windows(2).all(|w| w[0] < w[1]));
    }
}

#[test]
fn random_floating_segments_and_squares() {
    let mut rng = Rng(42);
    let b = rect(0., 0., 10., 10.);
    let mut s = Vec::new();
    for k in 0..150 {
        let p = v(0.5 + 9.0 * rng.unit(), 0.5 + 9.0 * rng.unit());
        let d = v(rng.unit() - 0.5, rng.unit() - 0.5) * 2.0;
        if k % 3 == 0 {
            s.extend(rect_segments(p.x, p.y, p.x + d.x.abs(), p.y + d.y.abs(), k));
        } else {
            s.push(Segment {
                a: p,
                b: (p + d).clamp(DVec2::ZERO, DVec2::splat(10.)),
                tag: k,
            });
        }
    }
    let arr = build(&b, &s, 1e-8);
    check(&arr, &b);
}

/// Connected components of the edge graph (vertices without edges not counted).
fn components(arr: &Arrangement) -> usize {
    let mut parent: Vec<usize> = (0..arr.vertices.len()).collect();
    fn find(p: &mut [usize], mut x: usize) -> usize {
        while p[x] != x {
            x = p[x];
        }
        x
    }
    for e in &arr.edges {
        let (a, b) = (
            find(&mut parent, e.v[0] as usize),
            find(&mut parent, e.v[1] as usize),
        );
        parent[a] = b;
    }
    let mut used = vec![false; arr.vertices.len()];
    for e in &arr.edges {
        used[e.v[0] as usize] = true;
        used[e.v[1] as usize] = true;
    }
    (0..arr.vertices.len())
        .filter(|&v| used[v] && find(&mut parent, v) == v)
        .count()
}

/// Segments between random points of a coarse lattice: many exact overlaps, T-junctions and
/// lines through one point. With `noise`, every coordinate is moved by up to that much, so
/// the same coincidences must be found by snapping instead.
fn lattice_case(seed: u64, noise: f64) {
    let mut rng = Rng(seed);
    let b = rect(0., 0., 6., 6.);
    let pick = |rng: &mut Rng| {
        let q = v((rng.next() % 7) as f64, (rng.next() % 7) as f64);
        q + v(rng.unit() - 0.5, rng.unit() - 0.5) * 2.0 * noise
    };
    let s: Vec<Segment> = (0..40)
        .map(|k| Segment {
            a: pick(&mut rng),
            b: pick(&mut rng),
            tag: k,
        })
        .collect();
    let arr = build(&b, &s, 1e-9);
    check(&arr, &b);
    let c = components(&arr);
    assert_eq!(
        arr.faces.len() + arr.vertices.len(),
        arr.edges.len() + c,
        "seed {seed}: Euler"
    );
    // Every vertex is a lattice point or a crossing: none is a near-duplicate of another.
    for (i, p) in arr.vertices.iter().enumerate() {
        for q in &arr.vertices[i + 1..] {
            assert!((*p - *q).length() > 1e-9);
        }
    }
}

#[test]
fn lattice_segments_with_exact_coincidences() {
    for seed in 0..40 {
        lattice_case(seed, 0.0);
    }
}

#[test]
fn lattice_segments_with_rounding_noise() {
    for seed in 0..40 {
        lattice_case(seed, 1e-13);
    }
}

/// Each random chord of a pentagon comes with a copy whose ends are moved by up to `eps`
/// and a partial copy from a point along that copy: bundles of nearly coincident edges,
/// which only snapping can make coincide.
fn near_duplicate_chords_case(seed: u64, eps: f64) {
    let mut rng = Rng(seed + 1000);
    let b: Vec<DVec2> = (0..5)
        .map(|k| {
            let a = k as f64 * std::f64::consts::TAU / 5.0 + 0.1;
            v(2.0 * a.cos(), 2.0 * a.sin())
        })
        .collect();
    let jiggle = |rng: &mut Rng| v(rng.unit() - 0.5, rng.unit() - 0.5) * 2.0 * eps;
    let mut s = Vec::new();
    for k in 0..30u32 {
        let a = on_boundary(&b, rng.unit());
        let c = on_boundary(&b, rng.unit());
        let (a2, c2) = (a + jiggle(&mut rng), c + jiggle(&mut rng));
        let m = a2.lerp(c2, rng.unit());
        s.push(Segment { a, b: c, tag: k });
        s.push(Segment {
            a: a2,
            b: c2,
            tag: 100 + k,
        });
        s.push(Segment {
            a: m,
            b: c + jiggle(&mut rng),
            tag: 200 + k,
        });
    }
    let arr = build(&b, &s, 1e-9);
    check(&arr, &b);
    let c = components(&arr);
    assert_eq!(
        arr.faces.len() + arr.vertices.len(),
        arr.edges.len() + c,
        "seed {seed} eps {eps}: Euler"
    );
}

#[test]
fn near_duplicate_chords_snap_together() {
    for eps in [0.0, 1e-12, 1e-10, 1e-9, 3e-9, 1e-7] {
        for seed in 0..10 {
            near_duplicate_chords_case(seed, eps);
        }
    }
}

/// The long version of the near-degenerate tests (about two minutes):
/// `cargo test -p penumbra arrangement::test::random::stress -- --ignored`.
#[test]
#[ignore]
fn stress_near_degenerate() {
    for noise in [0.0, 1e-13, 1e-11, 3e-10, 2e-9] {
        for seed in 0..400 {
            lattice_case(seed, noise);
        }
    }
    for eps in [
        0.0, 1e-14, 1e-12, 1e-10, 5e-10, 1e-9, 2e-9, 3e-9, 5e-9, 1e-8, 1e-7, 1e-6,
    ] {
        for seed in 0..400 {
            near_duplicate_chords_case(seed, eps);
        }
    }
}

/// Garbage in (segments far outside, repeated, zero-length, huge snap): no panic, and with a
/// sensible snap the faces still tile the receiver.
#[test]
fn random_garbage_does_not_panic() {
    let mut rng = Rng(7);
    let b = rect(0., 0., 1., 1.);
    for round in 0..60 {
        let mut s: Vec<Segment> = (0..40)
            .map(|k| {
                let mut p = || v(rng.unit() * 3.0 - 1.0, rng.unit() * 3.0 - 1.0);
                Segment {
                    a: p(),
                    b: p(),
                    tag: k,
                }
            })
            .collect();
        s.push(s[0]);
        s.push(Segment {
            a: s[1].a,
            b: s[1].a,
            tag: 99,
        });
        let snap = [0.0, 1e-12, 1e-9, 1e-3, 0.3, 5.0][round % 6];
        let arr = build(&b, &s, snap);
        if snap <= 1e-9 {
            check(&arr, &b);
        }
    }
}
