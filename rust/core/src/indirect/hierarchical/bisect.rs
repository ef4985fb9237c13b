//! Longest-edge bisection (Rivara) of element triangles, for `subdivide`: a triangle cut
//! at the midpoints of some of its edges, its longest always among them, so that the mesh
//! stays conforming and its angles bounded however often it is cut.

use glam::DVec3;

/// Index i of the longest edge (tri[i], tri[i + 1]).
pub(super) fn longest(pos: &[DVec3], tri: &[u32; 3]) -> usize {
    let len = |i: usize| (pos[tri[i] as usize] - pos[tri[(i + 1) % 3] as usize]).length_squared();
    let mut l = 0;
    for i in 1..3 {
        if len(i) > len(l) {
            l = i;
        }
    }
    l
}

/// `tri` cut at the midpoints `mid` gives of its edges, its longest edge first (which
/// the closure has split whenever any is): 1, 2, 3 or 4 triangles, same orientation, as
/// the first `n` of the array and `n` (no allocation: every triangle of a pass goes
/// through here).
pub(super) fn bisect(
    pos: &[DVec3],
    tri: [u32; 3],
    mid: &impl Fn(u32, u32) -> Option<u32>,
) -> ([[u32; 3]; 4], usize) {
    let mut out = [tri; 4];
    let l = longest(pos, &tri);
    let (a, b, c) = (tri[l], tri[(l + 1) % 3], tri[(l + 2) % 3]);
    let Some(m) = mid(a, b) else {
        return (out, 1);
    };
    let mut n = 0;
    let mut push = |t: [u32; 3]| {
        out[n] = t;
        n += 1;
    };
    match mid(a, c) {
        Some(mca) => [[a, m, mca], [m, c, mca]].into_iter().for_each(&mut push),
        None => push([a, m, c]),
    }
    match mid(b, c) {
        Some(mbc) => [[m, b, mbc], [m, mbc, c]].into_iter().for_each(&mut push),
        None => push([m, b, c]),
    }
    (out, n)
}

#[cfg(test)]
mod test {
    use super::*;

    #[test]
    fn bisection_keeps_area_and_orientation() {
        let pos = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(4.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(0.5, 0.5, 0.0),
            DVec3::new(2.5, 0.5, 0.0),
        ];
        let area = |t: &[u32; 3]| {
            let [a, b, c] = t.map(|v| pos[v as usize]);
            (b - a).cross(c - a).z * 0.5
        };
        let whole = area(&[0, 1, 2]);
        for (with_ca, with_bc) in [(false, false), (true, false), (false, true), (true, true)] {
            let mid = |a: u32, b: u32| match (a.min(b), a.max(b)) {
                (0, 1) => Some(3),
                (0, 2) if with_ca => Some(4),
                (1, 2) if with_bc => Some(5),
                _ => None,
            };
            let (parts, n) = bisect(&pos, [0, 1, 2], &mid);
            let parts = &parts[..n];
            assert_eq!(parts.len(), 2 + with_ca as usize + with_bc as usize);
            let sum: f64 = parts.iter().map(area).sum();
            assert!((sum - whole).abs() < 1e-12, "{sum} vs {whole}");
            assert!(parts.iter().all(|t| area(t) > 0.0), "{parts:?}");
        }
    }
}
