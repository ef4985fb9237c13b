//! What could stand between a shooter and a receiver: per shooter face, the receiver faces
//! something could be in front of (kept); per shot, the clipped shooter each receiver face
//! sees; per vertex group, the faces the rays must be tested against.

use std::sync::atomic::Ordering;

use glam::DVec3;
use rayon::prelude::*;

use super::pair::{Blockers, FaceBlockers, Pair, Reached};
use super::shooter::{Group, Shooter};
use super::{FACE_OCCLUDER_BUDGET, MAX_FACE_OCCLUDERS, MAX_LISTED_OCCLUDERS};
use crate::geom::polygon::clip_polygon_3d;
use crate::geom::Plane;

impl Shooter<'_> {
    /// The plane of face `fp` as seen from the side it shoots from (its back if `back`).
    pub(super) fn side_plane(&self, fp: u32, back: bool) -> Plane {
        let plane = self.scene.faces[fp as usize].plane;
        if back {
            plane.flipped()
        } else {
            plane
        }
    }

    /// The receivers of shots from face `fp` (from its back if `back`) that something could
    /// stand in front of.
    pub(super) fn face_blockers(&self, fp: u32, back: bool) -> Option<&[Reached]> {
        let nf = self.scene.faces.len();
        let cell = self.face_blockers[fp as usize + back as usize * nf].get_or_init(|| {
            if self.kept.load(Ordering::Relaxed) > FACE_OCCLUDER_BUDGET {
                return None;
            }
            let face = &self.scene.faces[fp as usize];
            let plane = self.side_plane(fp, back);
            let single = self.side_patches(fp, back) == 1;
            let found: Vec<Reached> = self
                .receivers
                .par_iter()
                .filter_map(|&f| {
                    let front = self.scene.faces[f as usize].plane;
                    let (lo, hi) = self.shaft(&face.verts, fp, &plane, f, &front)?;
                    // One patch to one vertex group: the group's own query does it.
                    let groups = self.group_start[f as usize + 1] - self.group_start[f as usize];
                    if single && groups == 1 {
                        return Some((f, FaceBlockers::Many));
                    }
                    let mut list = Vec::new();
                    let planes = [plane, front];
                    self.occ.candidates(lo, hi, &planes, &[fp, f], &mut list);
                    match list.len() {
                        0 => None,
                        n if n <= MAX_FACE_OCCLUDERS => Some((f, FaceBlockers::Listed(list))),
                        _ => Some((f, FaceBlockers::Many)),
                    }
                })
                .collect();
            let size = found.len()
                + found
                    .iter()
                    .map(|(_, b)| match b {
                        FaceBlockers::Listed(l) => l.len(),
                        FaceBlockers::Many => 0,
                    })
                    .sum::<usize>();
            self.kept.fetch_add(size, Ordering::Relaxed);
            Some(found)
        });
        cell.as_deref()
    }

    /// Whether a shooter polygon `poly` on face `fp` (plane `plane`) can light receiver face
    /// `f` on its side `side` (its plane, or turned round for its back), and then the box
    /// around the part of it in front of `f` and `f`.
    pub(super) fn shaft(
        &self,
        poly: &[DVec3],
        fp: u32,
        plane: &Plane,
        f: u32,
        side: &Plane,
    ) -> Option<(DVec3, DVec3)> {
        if f == fp {
            return None;
        }
        let face = &self.scene.faces[f as usize];
        // The face's vertices lie in its polygon, so if its corners are all behind the
        // shooter, so are they.
        if face.verts.iter().all(|v| plane.dist(*v) <= self.tol) {
            return None;
        }
        if poly.iter().all(|v| side.dist(*v) <= self.tol) {
            return None;
        }
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        for v in poly.iter().chain(&face.verts) {
            lo = lo.min(*v);
            hi = hi.max(*v);
        }
        Some((lo, hi))
    }

    /// The shooter (patch polygon `poly` on face `fp`) as receiver face `f` sees it, or
    /// `None` if no vertex of `f` can get light from it.
    pub(super) fn pair<'s>(
        &self,
        poly: &[DVec3],
        fp: u32,
        plane: &Plane,
        f: u32,
        known: Option<&'s [Reached]>,
    ) -> Option<Pair<'s>> {
        let side = self.scene.faces[f as usize].plane;
        self.pair_on(poly, fp, plane, f, side, known)
    }

    /// `pair` for the side of face `f` whose plane is `side` (for its back, the face's plane
    /// turned round, with `known` from `back_reach` for backs).
    pub(super) fn pair_on<'s>(
        &self,
        poly: &[DVec3],
        fp: u32,
        plane: &Plane,
        f: u32,
        side: Plane,
        known: Option<&'s [Reached]>,
    ) -> Option<Pair<'s>> {
        self.shaft(poly, fp, plane, f, &side)?;
        let poly = clip_polygon_3d(poly, &side, self.tol);
        if poly.len() < 3 {
            return None;
        }
        let inner = poly.iter().copied().sum::<DVec3>() / poly.len() as f64;
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        for v in &poly {
            lo = lo.min(*v);
            hi = hi.max(*v);
        }
        let known = match known.map(|k| k.binary_search_by_key(&f, |e| e.0).map(|i| &k[i].1)) {
            Some(Err(_)) => None,
            Some(Ok(FaceBlockers::Listed(l))) => Some(Some(&l[..])),
            Some(Ok(FaceBlockers::Many)) | None => Some(None),
        };
        Some(Pair {
            face: f,
            plane: side,
            poly,
            lo,
            hi,
            inner,
            known,
        })
    }

    /// What could stand between the shooter (`patch`, its whole polygon) and the vertices
    /// of `group`.
    pub(super) fn blockers(
        &self,
        fp: u32,
        patch: &[DVec3],
        plane: &Plane,
        pair: &Pair,
        group: &Group,
    ) -> Blockers {
        let Some(known) = pair.known else {
            return Blockers::None;
        };
        let (lo, hi) = (pair.lo.min(group.lo), pair.hi.max(group.hi));
        let mut list = Vec::new();
        match known {
            Some(l) => list.extend(
                l.iter()
                    .copied()
                    .filter(|&o| self.occ.box_overlaps(o, lo, hi)),
            ),
            None => {
                let planes = [*plane, pair.plane];
                self.occ
                    .candidates(lo, hi, &planes, &[fp, pair.face], &mut list);
            }
        }
        // A box test keeps a face that stands beside the shaft from the shooter to the
        // group, or beyond it, as a floor does for everything on it; its plane tells.
        list.retain(|&o| self.occ.straddled_by(o, &pair.poly, group.lo, group.hi));
        match list.len() {
            0 => Blockers::None,
            n if n <= MAX_LISTED_OCCLUDERS => Blockers::Listed(
                list.into_iter()
                    .map(|o| {
                        let d = patch.iter().map(|v| self.occ.plane_dist(o, *v));
                        let lo = d.clone().fold(f64::INFINITY, f64::min);
                        (o, lo, d.fold(f64::NEG_INFINITY, f64::max))
                    })
                    .collect(),
            ),
            _ => Blockers::Any,
        }
    }
}
