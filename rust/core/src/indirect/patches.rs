//! Patches: the coarse partition of each receiver face that shoots indirect light (paper
//! §2.6; elements receive, patches shoot). A face's convex polygon is cut by a square grid
//! in its frame; a patch's radiosity is the area-weighted mean of the element triangles
//! overlapping it (a triangle's value being the mean of its three vertices). Parts of a face
//! covered by another face lying against it (`covered`) belong to no patch: a cell they cut
//! splits into convex pieces, each its own patch.

use glam::{DVec2, DVec3};

use crate::geom::hash::{mix, unit};
use crate::geom::polygon::{
    clip_polygon_2d, signed_area_2d, simplify_convex, strictly_inside_convex, HalfPlane,
};
use crate::geom::Plane;
use crate::indirect::coplanar_contacts::Open;
use crate::mesh::elements::Elements;
use crate::progress::Progress;
use crate::scene::Face;
use crate::BakeError;

#[derive(Debug, Clone)]
pub struct Patch {
    /// Receiver face (index into `Scene::faces`).
    pub face: u32,
    /// Convex, counter-clockwise seen from the side it shoots from.
    pub poly: Vec<DVec3>,
    /// The plane it shoots from: the face's, or for the back of a thin face (`back`) the
    /// face's turned round.
    pub plane: Plane,
    pub back: bool,
    pub area: f64,
    pub centroid: DVec3,
    /// Largest distance from the centroid to a corner.
    pub radius: f64,
    /// Element vertices with their weight in the patch's area-weighted mean (sum 1),
    /// sorted by vertex.
    pub weights: Vec<(u32, f64)>,
    /// Stratified points on the patch for visibility rays, at three densities: one point
    /// (the centroid), about four, and about the `visibility_rays` setting.
    pub samples: [Vec<DVec3>; 3],
}

/// Patches of all faces, ordered by face, then grid row, then column. Faces without element
/// triangles get none.
///
/// An element triangle counts in every patch it overlaps, by the area of the overlap (not
/// only in the one holding its centroid): so each patch's element area is its own area, and
/// a cell no centroid falls in (elements as large as patches) is still there to shoot.
///
/// `open` is each face's uncovered part (`covered::open_parts`); triangles under a cover
/// weigh in no patch.
///
/// Checks `progress` every few thousand triangles: a tiny `patch_size` makes this loop long.
pub fn build_patches(
    faces: &[Face],
    open: &[Vec<Open>],
    el: &Elements,
    patch_size: f64,
    rays: u32,
    progress: &Progress,
) -> Result<Vec<Patch>, BakeError> {
    struct Piece {
        face: u32,
        cell: (u64, u64),
        part: u32,
        tri: u32,
        area: f64,
    }
    let grids: Vec<Grid> = faces
        .iter()
        .map(|f| Grid::new(&f.poly2, patch_size))
        .collect();
    let mut pieces: Vec<Piece> = Vec::with_capacity(el.triangles.len() * 2);
    for (t, tri) in el.triangles.iter().enumerate() {
        if t % 4096 == 0 {
            progress.check()?;
        }
        let face = el.tri_face[t];
        let (f, grid) = (&faces[face as usize], &grids[face as usize]);
        let mut q = tri.map(|v| f.frame.to_2d(el.positions[v as usize]));
        if signed_area_2d(&q) < 0.0 {
            q.swap(1, 2);
        }
        let lo = grid.cell(q[0].min(q[1]).min(q[2]));
        let hi = grid.cell(q[0].max(q[1]).max(q[2]));
        let parts = &open[face as usize];
        let (tlo, thi) = bounds(&q);
        let mut overlaps = false;
        for j in lo.1..=hi.1 {
            // One large triangle over a fine grid is a long loop of its own.
            if (j - lo.1) % 64 == 63 {
                progress.check()?;
            }
            for i in lo.0..=hi.0 {
                let in_cell = grid.clip(&q, (i, j));
                if !(signed_area_2d(&in_cell) > 0.0) {
                    continue;
                }
                overlaps = true;
                for (k, part) in parts.iter().enumerate() {
                    let area = if part.cuts.is_empty() {
                        signed_area_2d(&in_cell)
                    } else {
                        let (plo, phi) = bounds(&part.poly);
                        if plo.x > thi.x || plo.y > thi.y || phi.x < tlo.x || phi.y < tlo.y {
                            continue;
                        }
                        let p = part
                            .cuts
                            .iter()
                            .fold(in_cell.clone(), |p, h| clip_polygon_2d(&p, h, 0.0));
                        signed_area_2d(&p)
                    };
                    if area > 0.0 {
                        pieces.push(Piece {
                            face,
                            cell: (i, j),
                            part: k as u32,
                            tri: t as u32,
                            area,
                        });
                    }
                }
            }
        }
        // A degenerate triangle still carries its vertices' values into some patch (one
        // wholly under a cover into none).
        if !overlaps && !parts.is_empty() {
            let cell = grid.cell((q[0] + q[1] + q[2]) / 3.0);
            pieces.push(Piece {
                face,
                cell,
                part: 0,
                tri: t as u32,
                area: 0.0,
            });
        }
    }
    pieces.sort_by_key(|p| (p.face, p.cell.1, p.cell.0, p.part, p.tri));

    let mut patches = Vec::new();
    let mut start = 0;
    while start < pieces.len() {
        let face = pieces[start].face;
        let mut end = start;
        while end < pieces.len() && pieces[end].face == face {
            end += 1;
        }
        // Cells of this face with their pieces; a cell whose part of the face vanished (an
        // element poking out of the face by rounding) hands its pieces to the nearest.
        let f = &faces[face as usize];
        let grid = &grids[face as usize];
        // (cell and part, the face within it, (triangle, overlap area) pairs)
        type Cell = ((u64, u64, u32), Vec<DVec2>, Vec<(u32, f64)>);
        let mut cells: Vec<Cell> = Vec::new();
        let mut orphans: Vec<((u64, u64, u32), (u32, f64))> = Vec::new();
        let mut i = start;
        while i < end {
            let cell = (pieces[i].cell.0, pieces[i].cell.1, pieces[i].part);
            let mut j = i;
            while j < end && (pieces[j].cell.0, pieces[j].cell.1, pieces[j].part) == cell {
                j += 1;
            }
            let part = &open[face as usize][cell.2 as usize];
            let poly = simplify_convex(
                &part
                    .cuts
                    .iter()
                    .fold(grid.clip(&f.poly2, (cell.0, cell.1)), |p, h| {
                        clip_polygon_2d(&p, h, 0.0)
                    }),
            );
            let members = pieces[i..j].iter().map(|p| (p.tri, p.area));
            if poly.len() >= 3 && signed_area_2d(&poly) > 0.0 {
                cells.push((cell, poly, members.collect()));
            } else {
                orphans.extend(members.map(|m| (cell, m)));
            }
            i = j;
        }
        if cells.is_empty() {
            let poly = open[face as usize]
                .first()
                .map_or_else(|| f.poly2.clone(), |p| p.poly.clone());
            cells.push(((0, 0, 0), poly, Vec::new()));
        }
        for (cell, m) in orphans {
            let dist = |c: (u64, u64, u32)| c.0.abs_diff(cell.0).max(c.1.abs_diff(cell.1));
            let k = (0..cells.len())
                .min_by_key(|&k| dist(cells[k].0))
                .unwrap_or(0);
            cells[k].2.push(m);
        }
        for (cell, poly2, members) in cells {
            let seed = (cell.2 as u64) << 60 ^ (face as u64) << 40 ^ cell.1 << 20 ^ cell.0;
            patches.push(patch(face, f, &poly2, &members, el, rays, seed));
        }
        start = end;
        progress.check()?;
    }
    Ok(patches)
}

/// The face's grid: `n` cells of size `cell` (at most `patch_size`, so that no sliver
/// column or row is left over at the far edge) from the corner `origin` of its bounds.
pub(super) struct Grid {
    origin: DVec2,
    cell: DVec2,
    pub(super) n: (u64, u64),
}

impl Grid {
    pub(super) fn new(poly: &[DVec2], patch_size: f64) -> Self {
        let mut lo = DVec2::splat(f64::INFINITY);
        let mut hi = DVec2::splat(f64::NEG_INFINITY);
        for p in poly {
            lo = lo.min(*p);
            hi = hi.max(*p);
        }
        if !(lo.x <= hi.x && lo.y <= hi.y) {
            return Grid {
                origin: DVec2::ZERO,
                cell: DVec2::ONE,
                n: (1, 1),
            };
        }
        let size = hi - lo;
        // More cells than this per side would be patches smaller than any element.
        let count = |s: f64| ((s / patch_size).ceil().clamp(1.0, 1e6)) as u64;
        let n = (count(size.x), count(size.y));
        let cell = DVec2::new(size.x / n.0 as f64, size.y / n.1 as f64)
            .max(DVec2::splat(f64::MIN_POSITIVE));
        Grid {
            origin: lo,
            cell,
            n,
        }
    }

    fn cell(&self, p: DVec2) -> (u64, u64) {
        let q = (p - self.origin) / self.cell;
        let idx = |x: f64, n: u64| (x.floor().max(0.0) as u64).min(n - 1);
        (idx(q.x, self.n.0), idx(q.y, self.n.1))
    }

    /// The face polygon within the cell; outer cells are open outwards so that points
    /// rounded just past the bounds stay in.
    pub(super) fn clip(&self, poly: &[DVec2], (i, j): (u64, u64)) -> Vec<DVec2> {
        let lo = self.origin + self.cell * DVec2::new(i as f64, j as f64);
        let hi = lo + self.cell;
        let mut out = poly.to_vec();
        let sides = [
            (
                i > 0,
                HalfPlane {
                    n: DVec2::X,
                    c: lo.x,
                },
            ),
            (
                i + 1 < self.n.0,
                HalfPlane {
                    n: -DVec2::X,
                    c: -hi.x,
                },
            ),
            (
                j > 0,
                HalfPlane {
                    n: DVec2::Y,
                    c: lo.y,
                },
            ),
            (
                j + 1 < self.n.1,
                HalfPlane {
                    n: -DVec2::Y,
                    c: -hi.y,
                },
            ),
        ];
        for (on, h) in sides {
            if on {
                out = clip_polygon_2d(&out, &h, 0.0);
            }
        }
        simplify_convex(&out)
    }
}

pub(super) fn patch(
    face: u32,
    f: &Face,
    poly2: &[DVec2],
    members: &[(u32, f64)],
    el: &Elements,
    rays: u32,
    seed: u64,
) -> Patch {
    let area = signed_area_2d(poly2);
    let c2 = centroid_2d(poly2);
    let poly: Vec<DVec3> = poly2.iter().map(|p| f.frame.to_3d(*p)).collect();
    let centroid = f.frame.to_3d(c2);
    let radius = poly
        .iter()
        .map(|p| (*p - centroid).length())
        .fold(0.0, f64::max);

    let mut weights: Vec<(u32, f64)> = Vec::with_capacity(members.len() * 3);
    let mut total = 0.0;
    for &(t, w) in members {
        total += w;
        weights.extend(el.triangles[t as usize].iter().map(|&v| (v, w)));
    }
    // Only degenerate triangles: no area to weigh by, so all vertices count the same.
    if !(total > 0.0) {
        weights.iter_mut().for_each(|w| w.1 = 1.0);
        total = members.len() as f64;
    }
    weights.sort_by_key(|w| w.0);
    let mut merged: Vec<(u32, f64)> = Vec::with_capacity(weights.len());
    for (v, w) in weights {
        match merged.last_mut() {
            Some(last) if last.0 == v => last.1 += w,
            _ => merged.push((v, w)),
        }
    }
    // Each triangle's area went to its three corners.
    let scale = 1.0 / (3.0 * total);
    merged.iter_mut().for_each(|w| w.1 *= scale);

    let to3 = |v: Vec<DVec2>| v.into_iter().map(|p| f.frame.to_3d(p)).collect::<Vec<_>>();
    let samples = [
        vec![centroid],
        to3(stratified(poly2, c2, 4.min(rays), seed)),
        to3(stratified(poly2, c2, rays, seed)),
    ];
    Patch {
        face,
        poly,
        plane: f.plane,
        back: false,
        area,
        centroid,
        radius,
        weights: merged,
        samples,
    }
}

fn bounds(poly: &[DVec2]) -> (DVec2, DVec2) {
    poly.iter().fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    )
}

fn centroid_2d(poly: &[DVec2]) -> DVec2 {
    let n = poly.len();
    let o = poly[0];
    let (mut c, mut a) = (DVec2::ZERO, 0.0);
    for i in 1..n.saturating_sub(1) {
        let w = (poly[i] - o).perp_dot(poly[i + 1] - o);
        c += (o + poly[i] + poly[i + 1]) * w;
        a += w;
    }
    if a > 0.0 {
        c / (3.0 * a)
    } else {
        poly.iter().copied().sum::<DVec2>() / n as f64
    }
}

/// About `n` points spread evenly over a convex polygon: centres of a square grid over its
/// bounds, refined until `n` fall inside, then every k-th of them. Deterministic, so a bake
/// repeats exactly.
fn stratified(poly: &[DVec2], centroid: DVec2, n: u32, seed: u64) -> Vec<DVec2> {
    let n = n.max(1) as usize;
    if n == 1 {
        return vec![centroid];
    }
    let mut lo = DVec2::splat(f64::INFINITY);
    let mut hi = DVec2::splat(f64::NEG_INFINITY);
    for p in poly {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let size = hi - lo;
    let mut m = (n as f64).sqrt().ceil() as usize;
    let mut inside = Vec::new();
    // Slivers fill little of their bounds; past 32× refinement take what there is.
    for _ in 0..6 {
        inside.clear();
        // Grid aspect follows the bounds, so cells stay near square on long patches.
        let (mx, my) = if size.x >= size.y {
            (
                m,
                ((m as f64 * size.y / size.x.max(f64::MIN_POSITIVE)).round() as usize).max(1),
            )
        } else {
            (
                ((m as f64 * size.x / size.y.max(f64::MIN_POSITIVE)).round() as usize).max(1),
                m,
            )
        };
        for j in 0..my {
            for i in 0..mx {
                // Jittered within the cell (seeded, so repeatable): a regular grid would
                // alias with regular occluders such as slats or railings.
                let h = mix(seed ^ (j as u64) << 32 ^ i as u64 ^ (mx as u64) << 52);
                let (jx, jy) = (0.1 + 0.8 * unit(h), 0.1 + 0.8 * unit(mix(h)));
                let p = lo
                    + size * DVec2::new((i as f64 + jx) / mx as f64, (j as f64 + jy) / my as f64);
                if strictly_inside_convex(poly, p) {
                    inside.push(p);
                }
            }
        }
        if inside.len() >= n {
            break;
        }
        m *= 2;
    }
    if inside.is_empty() {
        return vec![centroid];
    }
    if inside.len() <= n {
        return inside;
    }
    (0..n).map(|k| inside[k * inside.len() / n]).collect()
}

#[cfg(test)]
pub(crate) mod test {
    use super::*;
    use crate::scene::test::face;

    /// Elements for `faces` by hand: each face's fan triangles split `k` times per side (so
    /// vertices on a face are not shared with other faces, as the mesher leaves them).
    pub(crate) fn grid_elements(faces: &[Face], k: usize) -> Elements {
        let mut el = Elements::default();
        for (fi, f) in faces.iter().enumerate() {
            let o = f.verts[0];
            for w in 1..f.verts.len() - 1 {
                let (a, b) = (f.verts[w] - o, f.verts[w + 1] - o);
                let base = el.positions.len() as u32;
                let id = |i: usize, j: usize| {
                    base + (i * (k + 1) - i * (i.saturating_sub(1)) / 2 + j) as u32
                };
                // Row i holds k + 1 - i points: o + (a·(j) + b·(i)) / k.
                for i in 0..=k {
                    for j in 0..=k - i {
                        el.positions
                            .push(o + (a * j as f64 + b * i as f64) / k as f64);
                        el.normals.push(f.plane.n);
                        el.vertex_face.push(fi as u32);
                    }
                }
                for i in 0..k {
                    for j in 0..k - i {
                        el.triangles.push([id(i, j), id(i, j + 1), id(i + 1, j)]);
                        if j + 1 < k - i {
                            el.triangles
                                .push([id(i, j + 1), id(i + 1, j + 1), id(i + 1, j)]);
                        }
                    }
                }
                let n = el.triangles.len() - el.tri_face.len();
                el.tri_face.extend(std::iter::repeat_n(fi as u32, n));
                el.tri_region.extend(std::iter::repeat_n(0, n));
            }
        }
        el
    }

    fn open_of(f: &Face) -> Vec<Vec<Open>> {
        crate::indirect::coplanar_contacts::open_parts(std::slice::from_ref(f), 1e-9)
    }

    fn square(s: f64) -> Face {
        let v = |x, y| DVec3::new(x, y, 0.0);
        face(
            &[v(0.0, 0.0), v(s, 0.0), v(s, s), v(0.0, s)],
            DVec3::ONE,
            DVec3::ZERO,
        )
    }

    #[test]
    fn grid_elements_cover_the_face() {
        let f = square(2.0);
        let el = grid_elements(std::slice::from_ref(&f), 5);
        let area: f64 = el
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| el.positions[v as usize]);
                0.5 * (b - a).cross(c - a).dot(f.plane.n)
            })
            .sum();
        assert!((area - 4.0).abs() < 1e-12, "{area}");
        assert_eq!(el.triangles.len(), 2 * 25);
    }

    #[test]
    fn square_face_splits_into_cells_covering_it() {
        let f = square(2.0);
        let el = grid_elements(std::slice::from_ref(&f), 8);
        // 2 / 0.7 → 3 cells a side of 2/3.
        let p = build_patches(
            std::slice::from_ref(&f),
            &open_of(&f),
            &el,
            0.7,
            16,
            &Progress::new(),
        )
        .unwrap();
        assert_eq!(p.len(), 9);
        let total: f64 = p.iter().map(|p| p.area).sum();
        assert!((total - 4.0).abs() < 1e-12);
        for q in &p {
            assert!((q.area - 4.0 / 9.0).abs() < 1e-12);
            let s: f64 = q.weights.iter().map(|w| w.1).sum();
            assert!((s - 1.0).abs() < 1e-12);
            assert_eq!(q.samples[0].len(), 1);
            assert_eq!(q.samples[1].len(), 4);
            assert_eq!(q.samples[2].len(), 16);
            assert!((q.radius - (2.0f64).sqrt() / 3.0).abs() < 1e-12);
        }
        // Every triangle's three corners weigh in exactly one patch: the weights times patch
        // areas over all patches add up to the face area.
        let mut per_vertex = vec![0.0; el.positions.len()];
        for q in &p {
            for &(v, w) in &q.weights {
                per_vertex[v as usize] += w * q.area;
            }
        }
        assert!((per_vertex.iter().sum::<f64>() - 4.0).abs() < 1e-12);
    }

    #[test]
    fn floor_under_a_box_is_in_no_patch() {
        let v = |x, y| DVec3::new(x, y, 0.0);
        let floor = square(4.0);
        // A box bottom facing down, 1 × 1 at (1.5, 1.5): it straddles four cells.
        let bottom = face(
            &[v(1.5, 1.5), v(1.5, 2.5), v(2.5, 2.5), v(2.5, 1.5)],
            DVec3::ONE,
            DVec3::ZERO,
        );
        let faces = [floor, bottom];
        let open = crate::indirect::coplanar_contacts::open_parts(&faces, 1e-9);
        let el = grid_elements(&faces, 8);
        let p = build_patches(&faces, &open, &el, 2.0, 16, &Progress::new()).unwrap();
        assert!(p.iter().all(|q| q.face == 0));
        let total: f64 = p.iter().map(|q| q.area).sum();
        assert!((total - 15.0).abs() < 1e-9, "{total}");
        let under = faces[0].frame.to_2d(v(2.0, 2.0));
        for q in &p {
            let poly: Vec<DVec2> = q.poly.iter().map(|x| faces[0].frame.to_2d(*x)).collect();
            assert!(!strictly_inside_convex(&poly, under));
        }
    }

    #[test]
    fn triangle_face_cells_are_clipped_and_samples_inside() {
        let v = |x, y| DVec3::new(x, y, 1.0);
        let f = face(
            &[v(0.0, 0.0), v(3.0, 0.0), v(0.0, 3.0)],
            DVec3::ONE,
            DVec3::ZERO,
        );
        let el = grid_elements(std::slice::from_ref(&f), 12);
        let p = build_patches(
            std::slice::from_ref(&f),
            &open_of(&f),
            &el,
            1.0,
            9,
            &Progress::new(),
        )
        .unwrap();
        let total: f64 = p.iter().map(|p| p.area).sum();
        assert!((total - 4.5).abs() < 1e-12);
        // Every patch holds elements; samples lie inside the face and on its plane.
        let poly: Vec<_> = f.poly2.clone();
        for q in &p {
            assert!(!q.weights.is_empty());
            for s in q.samples.iter().flatten() {
                assert!(f.plane.dist(*s).abs() < 1e-12);
                assert!(strictly_inside_convex(&poly, f.frame.to_2d(*s)));
            }
            assert!(!q.samples[2].is_empty() && q.samples[2].len() <= 9);
        }
    }
}
