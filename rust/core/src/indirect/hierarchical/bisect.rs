//! Longest-edge bisection (Rivara) of element triangles, for `subdivide`: a triangle cut
//! at the midpoints of some of its edges, its longest always among them, so that the mesh
//! stays conforming and its angles bounded however often it is cut. Also the triangles
//! around each edge, which the closure over neighbours walks.

use glam::DVec3;
use rayon::prelude::*;

/// Index i of the longest edge (tri[i], tri[i + 1]), vertex positions by `pos`.
pub(super) fn longest(pos: &impl Fn(u32) -> DVec3, tri: &[u32; 3]) -> usize {
    let len = |i: usize| (pos(tri[i]) - pos(tri[(i + 1) % 3])).length_squared();
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
    pos: &impl Fn(u32) -> DVec3,
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

/// Triangles per chunk of `bisect_all`.
const CHUNK: usize = 4096;

/// Every triangle of `triangles` cut by `bisect` at the midpoints `mid` gives, in order,
/// with the `origin` of each part (its triangle's). On all threads, each chunk of triangles
/// into its own lists, then laid end to end (a pass over room-245's 600k triangles took
/// 0.04-0.07 s of one thread; a list of every triangle's four slots would hold 35 MB).
pub(super) fn bisect_all(
    pos: &(impl Fn(u32) -> DVec3 + Sync),
    triangles: &[[u32; 3]],
    origin: &[u32],
    mid: &(impl Fn(u32, u32) -> Option<u32> + Sync),
) -> (Vec<[u32; 3]>, Vec<u32>) {
    let chunks: Vec<(Vec<[u32; 3]>, Vec<u32>)> = triangles
        .par_chunks(CHUNK)
        .zip(origin.par_chunks(CHUNK))
        .map(|(tri, from)| {
            let (mut t, mut o) = (Vec::with_capacity(2 * tri.len()), Vec::new());
            for (tri, &from) in tri.iter().zip(from) {
                let (parts, n) = bisect(pos, *tri, mid);
                t.extend_from_slice(&parts[..n]);
                o.extend(std::iter::repeat_n(from, n));
            }
            (t, o)
        })
        .collect();
    let total = chunks.iter().map(|(t, _)| t.len()).sum();
    let (mut tris, mut orig) = (Vec::with_capacity(total), Vec::with_capacity(total));
    for (t, o) in chunks {
        tris.extend(t);
        orig.extend(o);
    }
    (tris, orig)
}

/// The triangles around each edge of a mesh, by the edge's ends (smaller first): flat and
/// sorted, as a map of small lists cost room-828 about 100 MB.
pub(super) struct EdgeTris {
    keys: Vec<(u32, u32)>,
    tris: Vec<u32>,
}

impl EdgeTris {
    pub(super) fn new(triangles: &[[u32; 3]]) -> Self {
        let mut all: Vec<((u32, u32), u32)> = Vec::with_capacity(triangles.len() * 3);
        for (t, tri) in triangles.iter().enumerate() {
            for i in 0..3 {
                let (a, b) = (tri[i], tri[(i + 1) % 3]);
                all.push(((a.min(b), a.max(b)), t as u32));
            }
        }
        // By edge, then by triangle: the order a map filled triangle by triangle gave.
        all.par_sort_unstable();
        let (keys, tris) = all.into_iter().unzip();
        EdgeTris { keys, tris }
    }

    /// The triangles around the edge `k`, in index order (none if it is no edge).
    pub(super) fn of(&self, k: (u32, u32)) -> &[u32] {
        let lo = self.keys.partition_point(|x| *x < k);
        let hi = lo + self.keys[lo..].partition_point(|x| *x == k);
        &self.tris[lo..hi]
    }
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
            let (parts, n) = bisect(&|v| pos[v as usize], [0, 1, 2], &mid);
            let parts = &parts[..n];
            assert_eq!(parts.len(), 2 + with_ca as usize + with_bc as usize);
            let sum: f64 = parts.iter().map(area).sum();
            assert!((sum - whole).abs() < 1e-12, "{sum} vs {whole}");
            assert!(parts.iter().all(|t| area(t) > 0.0), "{parts:?}");
        }
    }
}
