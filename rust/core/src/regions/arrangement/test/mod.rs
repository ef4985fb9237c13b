use glam::DVec2;

use super::{build, split, Arrangement, Segment, BOUNDARY_TAG};
use crate::geom::polygon::{orient, signed_area_2d};

mod random;

fn v(x: f64, y: f64) -> DVec2 {
    DVec2::new(x, y)
}

fn seg(ax: f64, ay: f64, bx: f64, by: f64, tag: u32) -> Segment {
    Segment {
        a: v(ax, ay),
        b: v(bx, by),
        tag,
    }
}

fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> Vec<DVec2> {
    vec![v(x0, y0), v(x1, y0), v(x1, y1), v(x0, y1)]
}

/// The four sides of a rectangle, tags `tag..tag + 4`.
fn rect_segments(x0: f64, y0: f64, x1: f64, y1: f64, tag: u32) -> Vec<Segment> {
    let r = rect(x0, y0, x1, y1);
    (0..4)
        .map(|i| Segment {
            a: r[i],
            b: r[(i + 1) % 4],
            tag: tag + i as u32,
        })
        .collect()
}

fn pts(arr: &Arrangement, l: &[u32]) -> Vec<DVec2> {
    l.iter().map(|&i| arr.vertices[i as usize]).collect()
}

fn sorted_areas(arr: &Arrangement) -> Vec<f64> {
    let mut a: Vec<f64> = arr.faces.iter().map(|f| f.area).collect();
    a.sort_by(f64::total_cmp);
    a
}

fn assert_close(a: f64, b: f64, tol: f64) {
    assert!((a - b).abs() <= tol, "{a} vs {b} (tol {tol})");
}

fn find_edge(arr: &Arrangement, p: DVec2, q: DVec2) -> Option<&super::ArrEdge> {
    arr.edges.iter().find(|e| {
        let (a, b) = (arr.vertices[e.v[0] as usize], arr.vertices[e.v[1] as usize]);
        (a == p && b == q) || (a == q && b == p)
    })
}

/// What must hold for any arrangement: faces tile the boundary, loops wind the right way,
/// each interior point lies in its own face only, and edges meet only at end vertices.
fn check(arr: &Arrangement, boundary: &[DVec2]) {
    let total: f64 = arr.faces.iter().map(|f| f.area).sum();
    let want = signed_area_2d(boundary);
    assert!(
        (total - want).abs() <= 1e-9 * want,
        "areas sum to {total}, boundary {want}"
    );
    let boxes: Vec<(DVec2, DVec2)> = arr
        .faces
        .iter()
        .map(|f| {
            pts(arr, &f.outer).iter().fold(
                (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
                |(lo, hi), &p| (lo.min(p), hi.max(p)),
            )
        })
        .collect();
    for (i, f) in arr.faces.iter().enumerate() {
        assert!(f.area > 0.0, "face {i} area {}", f.area);
        assert!(local_area(&pts(arr, &f.outer)) > 0.0);
        for h in &f.holes {
            assert!(local_area(&pts(arr, h)) < 0.0);
        }
        assert!(f.contains(&arr.vertices, f.interior), "face {i} interior");
        for &e in &f.boundary_edges {
            let [a, b] = arr.edges[e as usize].v;
            let (a, b) = (arr.vertices[a as usize], arr.vertices[b as usize]);
            assert!(orient(a, b, f.interior) != 0.0 || !in_box(a, b, f.interior));
        }
        for (j, g) in arr.faces.iter().enumerate() {
            let (lo, hi) = boxes[j];
            let p = f.interior;
            if i != j && p.x >= lo.x && p.y >= lo.y && p.x <= hi.x && p.y <= hi.y {
                assert!(
                    !g.contains(&arr.vertices, p),
                    "face {i} interior in face {j}"
                );
            }
        }
    }
    assert_clean(arr);
}

/// Signed area with coordinates taken relative to the first point, so slivers far from the
/// origin keep their sign.
fn local_area(poly: &[DVec2]) -> f64 {
    let local: Vec<DVec2> = poly.iter().map(|p| *p - poly[0]).collect();
    signed_area_2d(&local)
}

fn point_segment_distance(p: DVec2, a: DVec2, b: DVec2) -> f64 {
    let t = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
    (a + (b - a) * t - p).length()
}

fn in_box(a: DVec2, b: DVec2, p: DVec2) -> bool {
    p.x >= a.x.min(b.x) && p.x <= a.x.max(b.x) && p.y >= a.y.min(b.y) && p.y <= a.y.max(b.y)
}

/// No two edges cross or overlap, no vertex lies inside an edge (exact). Pairs come from a
/// plain sweep over x-intervals, independent of the grid under test.
fn assert_clean(arr: &Arrangement) {
    let p = |i: u32| arr.vertices[i as usize];
    let span = |e: &super::ArrEdge| {
        let (a, b) = (p(e.v[0]).x, p(e.v[1]).x);
        (a.min(b), a.max(b))
    };
    let mut order: Vec<&super::ArrEdge> = arr.edges.iter().collect();
    order.sort_by(|e, f| span(e).0.total_cmp(&span(f).0));
    for (i, e) in order.iter().enumerate() {
        assert_ne!(e.v[0], e.v[1]);
        let right = span(e).1;
        for f in order[i + 1..].iter().take_while(|f| span(f).0 <= right) {
            let [a, b] = e.v;
            let [c, d] = f.v;
            for (x, (u, w)) in [(c, (a, b)), (d, (a, b)), (a, (c, d)), (b, (c, d))] {
                if x != u && x != w {
                    let on = orient(p(u), p(w), p(x)) == 0.0 && in_box(p(u), p(w), p(x));
                    assert!(!on, "vertex {x} on edge {u}-{w}");
                }
            }
            let o = |a: u32, b: u32, c: u32| orient(p(a), p(b), p(c)).signum();
            if a != c && a != d && b != c && b != d {
                let cross = o(a, b, c) * o(a, b, d) < 0.0 && o(c, d, a) * o(c, d, b) < 0.0;
                assert!(!cross, "edges {a}-{b} and {c}-{d} cross");
            }
        }
    }
}

#[test]
fn inner_square_is_a_hole_of_the_outer_face() {
    let b = rect(0., 0., 4., 4.);
    let arr = build(&b, &rect_segments(1., 1., 3., 3., 1), 1e-9);
    check(&arr, &b);
    assert_eq!(arr.faces.len(), 2);
    assert_eq!(sorted_areas(&arr), vec![4.0, 12.0]);
    let outer = arr.faces.iter().find(|f| f.area == 12.0).unwrap();
    let inner = arr.faces.iter().find(|f| f.area == 4.0).unwrap();
    assert_eq!(outer.holes.len(), 1);
    assert!(inner.holes.is_empty());
    let mut hole = outer.holes[0].clone();
    let mut ring = inner.outer.clone();
    hole.sort();
    ring.sort();
    assert_eq!(hole, ring);
    assert_eq!(outer.boundary_edges.len(), 8);
    let i = inner.interior;
    assert!(i.x > 1.0 && i.x < 3.0 && i.y > 1.0 && i.y < 3.0);
    let o = outer.interior;
    assert!(!(o.x >= 1.0 && o.x <= 3.0 && o.y >= 1.0 && o.y <= 3.0));
}

#[test]
fn nested_squares_give_a_ring_with_a_hole() {
    let b = rect(0., 0., 10., 10.);
    let mut s = rect_segments(1., 1., 9., 9., 0);
    s.extend(rect_segments(3., 3., 7., 7., 4));
    let arr = build(&b, &s, 1e-9);
    check(&arr, &b);
    assert_eq!(sorted_areas(&arr), vec![16.0, 36.0, 48.0]);
    let ring = arr.faces.iter().find(|f| f.area == 48.0).unwrap();
    assert_eq!(ring.holes.len(), 1);
    assert_eq!(ring.outer.len(), 4);
}

#[test]
fn chord_across_the_receiver_makes_two_faces() {
    let b = rect(0., 0., 4., 4.);
    let arr = build(&b, &[seg(0., 1., 4., 2., 9)], 1e-9);
    check(&arr, &b);
    assert_eq!(sorted_areas(&arr), vec![6.0, 10.0]);
    assert_eq!(arr.vertices.len(), 6);
    assert_eq!(arr.edges.len(), 7);
    assert_eq!(find_edge(&arr, v(0., 1.), v(4., 2.)).unwrap().tags, vec![9]);
    let side = find_edge(&arr, v(0., 0.), v(0., 1.)).unwrap();
    assert_eq!(side.tags, vec![BOUNDARY_TAG]);
}

#[test]
fn overlapping_squares_give_four_faces() {
    let b = rect(-1., -1., 4., 4.);
    let mut s = rect_segments(0., 0., 2., 2., 0);
    s.extend(rect_segments(1., 1., 3., 3., 4));
    let arr = build(&b, &s, 1e-9);
    check(&arr, &b);
    assert_eq!(sorted_areas(&arr), vec![1.0, 3.0, 3.0, 18.0]);
    assert_eq!(arr.vertices.len(), 4 + 8 + 2);
    let lens = {
        let mut l: Vec<usize> = arr.faces.iter().map(|f| f.outer.len()).collect();
        l.sort();
        l
    };
    // Overlap square; the two L-shapes have six corners; the outside face is the frame.
    assert_eq!(lens, vec![4, 4, 6, 6]);
    let frame = arr.faces.iter().find(|f| f.area == 18.0).unwrap();
    assert_eq!(frame.holes.len(), 1);
    assert_eq!(frame.holes[0].len(), 8);
}

#[test]
fn segment_on_the_boundary_shares_the_boundary_edge() {
    let b = rect(0., 0., 4., 4.);
    for y in [0.0, 1e-17, -1e-12] {
        let arr = build(&b, &[seg(1., y, 3., y, 5)], 1e-9);
        check(&arr, &b);
        assert_eq!(arr.faces.len(), 1);
        assert_close(arr.faces[0].area, 16.0, 1e-14);
        let (lo, hi) = (arr.vertices.len() - 2, arr.vertices.len() - 1);
        let e = arr
            .edges
            .iter()
            .find(|e| e.v == [lo as u32, hi as u32])
            .unwrap();
        assert_eq!(e.tags, vec![5, BOUNDARY_TAG], "y = {y}");
        assert_eq!(arr.edges.len(), 6);
    }
}

#[test]
fn collinear_overlaps_merge_tags() {
    let b = rect(0., 0., 4., 4.);
    let s = [
        seg(0., 2., 3., 2., 1),
        seg(4., 2., 1., 2., 2),
        seg(1., 2., 3., 2., 3),
        seg(1., 2., 3., 2., 3),
    ];
    let arr = build(&b, &s, 1e-9);
    check(&arr, &b);
    assert_eq!(sorted_areas(&arr), vec![8.0, 8.0]);
    let tags = |x0: f64, x1: f64| find_edge(&arr, v(x0, 2.), v(x1, 2.)).unwrap().tags.clone();
    assert_eq!(tags(0., 1.), vec![1]);
    assert_eq!(tags(1., 3.), vec![1, 2, 3]);
    assert_eq!(tags(3., 4.), vec![2]);
}

#[test]
fn t_junctions_split_the_crossed_edge() {
    let b = rect(0., 0., 4., 4.);
    let s = [seg(0., 2., 4., 2., 1), seg(2., 0., 2., 2., 2)];
    let arr = build(&b, &s, 1e-9);
    check(&arr, &b);
    assert_eq!(sorted_areas(&arr), vec![4.0, 4.0, 8.0]);
    assert!(find_edge(&arr, v(0., 2.), v(2., 2.)).is_some());
    assert!(find_edge(&arr, v(2., 2.), v(4., 2.)).is_some());
    let top = arr.faces.iter().find(|f| f.area == 8.0).unwrap();
    // The top face sees the horizontal chord as two edges meeting at the T.
    assert_eq!(top.outer.len(), 5);
}

#[test]
fn dangling_segments_leave_the_face_whole() {
    let b = rect(0., 0., 4., 4.);
    let s = [
        seg(0., 2., 1., 2., 1),
        seg(1., 2., 1.5, 3., 2),
        seg(2.5, 0.5, 3.5, 1.5, 3),
    ];
    let arr = build(&b, &s, 1e-9);
    check(&arr, &b);
    assert_eq!(arr.faces.len(), 1);
    let f = &arr.faces[0];
    assert_eq!(f.area, 16.0);
    assert!(f.holes.is_empty());
    assert_eq!(f.outer.len(), 5);
    assert_eq!(f.boundary_edges.len(), arr.edges.len());
    assert_eq!(arr.edges.len(), 5 + 3);
}

#[test]
fn points_a_hair_apart_are_snapped() {
    let b = rect(0., 0., 4., 4.);
    let e = 1e-12;
    let s = [
        seg(1., 1., 3., 1., 1),
        seg(3. + e, 1. - e, 3., 3., 2),
        seg(3., 3. + e, 1., 3., 3),
        seg(1. - e, 3., 1., 1. + e, 4),
        // Ends just short of the boundary and just short of the square.
        seg(e, 2., 1. - e, 2., 5),
    ];
    let arr = build(&b, &s, 1e-9);
    check(&arr, &b);
    assert_eq!(arr.faces.len(), 2);
    let a = sorted_areas(&arr);
    assert_close(a[0], 4.0, 1e-9);
    assert_close(a[1], 12.0, 1e-9);
    assert_eq!(arr.vertices.len(), 4 + 4 + 2);
}

#[test]
fn star_of_chords_through_one_point() {
    let b = rect(0., 0., 4., 4.);
    let n = 32;
    let c = v(2., 2.);
    let s: Vec<Segment> = (0..n)
        .map(|k| {
            let ang = (k as f64 + 0.3) * std::f64::consts::PI / n as f64;
            let d = DVec2::new(ang.cos(), ang.sin());
            let t = 2.0 / d.x.abs().max(d.y.abs());
            Segment {
                a: c - d * t,
                b: c + d * t,
                tag: k,
            }
        })
        .collect();
    let arr = build(&b, &s, 1e-9);
    check(&arr, &b);
    assert_eq!(arr.faces.len(), 2 * n as usize);
    let centre = arr.vertices.iter().filter(|p| (**p - c).length() < 1e-6);
    assert_eq!(centre.count(), 1);
    assert_eq!(arr.vertices.len(), 1 + 2 * n as usize + 4);
}

#[test]
fn same_result_at_any_scale() {
    let config = |k: f64| {
        let b = rect(-k, -k, 4. * k, 4. * k);
        let mut s = rect_segments(0., 0., 2. * k, 2. * k, 0);
        s.extend(rect_segments(k, k, 3. * k, 3. * k, 4));
        s.push(seg(-k, 0.5 * k, 4. * k, 3.7 * k, 8));
        s.push(seg(0.5 * k, 0.5 * k, 1.5 * k, 0.7 * k, 9));
        (b, s)
    };
    let (b1, s1) = config(1.0);
    let base = build(&b1, &s1, 1e-9 * 7.0);
    check(&base, &b1);
    for k in [1e-3, 1e4] {
        let (b, s) = config(k);
        let arr = build(&b, &s, 1e-9 * 7.0 * k);
        check(&arr, &b);
        assert_eq!(arr.vertices.len(), base.vertices.len());
        assert_eq!(arr.edges.len(), base.edges.len());
        assert_eq!(arr.faces.len(), base.faces.len());
        for (x, y) in sorted_areas(&arr).iter().zip(sorted_areas(&base)) {
            assert_close(x / (k * k), y, 1e-9 * y);
        }
    }
}

#[test]
fn bad_input_does_not_panic() {
    let b = rect(0., 0., 4., 4.);
    let mut nb = b.clone();
    nb[2].x = f64::NAN;
    assert_eq!(build(&nb, &[seg(0., 0., 1., 1., 0)], 1e-9).faces.len(), 0);
    let flat = [v(0., 0.), v(1., 1.), v(2., 2.)];
    assert_eq!(build(&flat, &[], 1e-9).vertices.len(), 0);
    assert_eq!(build(&b[..2], &[], 1e-9).vertices.len(), 0);
    let s = [
        seg(f64::NAN, 1., 2., 2., 0),
        seg(1., f64::INFINITY, 2., 2., 1),
        seg(1., 1., 1., 1., 2),
        seg(-5., -5., -3., -3., 3),
    ];
    for snap in [1e-9, 0.0, -1.0, f64::NAN, f64::INFINITY] {
        let arr = build(&b, &s, snap);
        assert_eq!(arr.faces.len(), 1, "snap {snap}");
        assert_eq!(arr.faces[0].area, 16.0);
        assert_eq!(arr.edges.len(), 4);
    }
    let huge = [seg(1e300, 2., 2., 2., 0), seg(-1e200, 1., 1e200, 1., 1)];
    assert_eq!(build(&b, &huge, 1e-9).faces.len(), 1);
    assert!(build(&rect(0., 0., 1e101, 1e101), &[], 1.0)
        .faces
        .is_empty());
    assert!(build(&rect(0., 0., 1e-101, 1e-101), &[], 0.0)
        .faces
        .is_empty());
    // Clockwise boundary is accepted.
    let mut cw = b.clone();
    cw.reverse();
    let arr = build(&cw, &[seg(0., 2., 4., 2., 0)], 1e-9);
    assert_eq!(sorted_areas(&arr), vec![8.0, 8.0]);
}

#[test]
fn segments_beyond_the_boundary_are_clipped() {
    let b = rect(0., 0., 4., 4.);
    let arr = build(&b, &[seg(-1., 2., 5., 2., 1)], 1e-9);
    check(&arr, &b);
    assert_eq!(sorted_areas(&arr), vec![8.0, 8.0]);
}

#[test]
fn grid_keeps_far_apart_segments_out_of_each_other() {
    // 900 short disjoint segments: all pairs would be ~400 000 candidates.
    let s: Vec<split::Edge> = (0..900u32)
        .map(|k| split::Edge::new(2 * k, 2 * k + 1, k))
        .collect();
    let p: Vec<DVec2> = (0..900)
        .flat_map(|k| {
            let c = v((k % 30) as f64, (k / 30) as f64);
            [c, c + v(0.3, 0.2)]
        })
        .collect();
    let pairs = split::candidate_pairs(&p, &s, 1e-9);
    assert!(pairs.len() < 4000, "{} candidate pairs", pairs.len());
    let b = rect(-1., -1., 31., 31.);
    let segs: Vec<Segment> = (0..900)
        .map(|k| Segment {
            a: p[2 * k],
            b: p[2 * k + 1],
            tag: k as u32,
        })
        .collect();
    let arr = build(&b, &segs, 1e-9);
    assert_eq!(arr.faces.len(), 1);
    assert_eq!(arr.faces[0].boundary_edges.len(), 904);
}
