//! From the surface to the UV square: each source polygon is cut into triangles, each with
//! the affine map its three corner UVs define, and element triangles are cut along them.
//!
//! Blender interpolates UVs over the triangles it tessellates a polygon into, so the map from
//! a polygon to UV space is piecewise affine. The triangles here follow `scene::convex`: a
//! planar convex polygon is fanned from its first corner (Blender's split of a quad), other
//! planar polygons are ear-clipped, and a non-planar polygon keeps the ear-clip triangles
//! with their own planes, as the scene stage baked them. For a polygon whose UVs are an
//! affine image of it (Lightmap Pack, any planar projection) every triangulation gives the
//! same map.

use glam::{DVec2, DVec3};

use super::raster::{clip, Attr};
use crate::geom::{Frame, Plane};
use crate::scene::convex::{ear_clip, is_convex, PLANAR_TOL};

/// One triangle of a source polygon: its corners in a frame on its plane, and their UVs.
#[derive(Debug, Clone)]
pub(crate) struct UvTriangle {
    pub plane: Plane,
    pub frame: Frame,
    pub p: [DVec2; 3],
    pub uv: [DVec2; 3],
    /// Twice the signed area of `p` (non-zero).
    det: f64,
}

impl UvTriangle {
    fn new(plane: Plane, frame: Frame, p: [DVec2; 3], uv: [DVec2; 3]) -> Option<Self> {
        let det = (p[1] - p[0]).perp_dot(p[2] - p[0]);
        (det != 0.0 && det.is_finite()).then_some(UvTriangle {
            plane,
            frame,
            p,
            uv,
            det,
        })
    }

    /// UV of a point given in `frame`, by barycentrics.
    #[inline]
    pub fn to_uv(&self, q: DVec2) -> DVec2 {
        let b1 = (q - self.p[0]).perp_dot(self.p[2] - self.p[0]) / self.det;
        let b2 = (self.p[1] - self.p[0]).perp_dot(q - self.p[0]) / self.det;
        self.uv[0] + (self.uv[1] - self.uv[0]) * b1 + (self.uv[2] - self.uv[0]) * b2
    }

    /// Signed UV area.
    pub fn uv_area(&self) -> f64 {
        0.5 * (self.uv[1] - self.uv[0]).perp_dot(self.uv[2] - self.uv[0])
    }
}

/// A source polygon as UV triangles; `planar` polygons share one plane.
#[derive(Debug, Clone, Default)]
pub(crate) struct SourcePolygon {
    pub tris: Vec<UvTriangle>,
    pub planar: bool,
    /// Distance within which a point counts as on a triangle's plane.
    pub tol: f64,
}

impl SourcePolygon {
    /// Cuts polygon `corners` (indices into `positions`, with one UV each) into triangles.
    /// Empty when the polygon has no area (the scene stage drops it too).
    pub fn new(positions: &[DVec3], corners: &[u32], uvs: &[DVec2]) -> Self {
        // Repeated consecutive points carry nothing (scene::convex drops them as well).
        let mut idx: Vec<usize> = Vec::with_capacity(corners.len());
        for k in 0..corners.len() {
            let q = positions[corners[k] as usize];
            if idx.last().map(|&l| positions[corners[l] as usize]) != Some(q) {
                idx.push(k);
            }
        }
        while idx.len() > 1
            && positions[corners[idx[0]] as usize]
                == positions[corners[*idx.last().unwrap()] as usize]
        {
            idx.pop();
        }
        if idx.len() < 3 {
            return SourcePolygon::default();
        }
        let pts: Vec<DVec3> = idx
            .iter()
            .map(|&k| positions[corners[k] as usize])
            .collect();
        let Some(plane) = Plane::from_polygon(&pts) else {
            return SourcePolygon::default();
        };
        let extent = pts
            .iter()
            .map(|q| (*q - pts[0]).length())
            .fold(0.0, f64::max);
        let planar = pts
            .iter()
            .all(|q| plane.dist(*q).abs() <= PLANAR_TOL * extent);
        let frame = Frame::on_plane(&plane, pts[0]);
        let p2: Vec<DVec2> = pts.iter().map(|q| frame.to_2d(*q)).collect();
        let tri_idx: Vec<[usize; 3]> = if planar && is_convex(&p2) {
            (1..p2.len() - 1).map(|k| [0, k, k + 1]).collect()
        } else {
            ear_clip(&p2)
        };
        let uv_of = |k: usize| uvs[idx[k]];
        let tris = tri_idx
            .into_iter()
            .filter_map(|[a, b, c]| {
                if planar {
                    UvTriangle::new(
                        plane,
                        frame,
                        [p2[a], p2[b], p2[c]],
                        [uv_of(a), uv_of(b), uv_of(c)],
                    )
                } else {
                    let t = [pts[a], pts[b], pts[c]];
                    let pl = Plane::from_polygon(&t)?;
                    let fr = Frame::on_plane(&pl, t[0]);
                    UvTriangle::new(
                        pl,
                        fr,
                        t.map(|q| fr.to_2d(q)),
                        [uv_of(a), uv_of(b), uv_of(c)],
                    )
                }
            })
            .collect();
        SourcePolygon {
            tris,
            planar,
            tol: 1e-6 * extent,
        }
    }

    /// Cuts an element triangle (corners `pts` with colours `cols`) along this polygon's
    /// triangles and hands each part, mapped to UV and scaled by `scale` (texels per unit
    /// UV), to `out`.
    pub fn map_element(
        &self,
        pts: [DVec3; 3],
        cols: [DVec3; 3],
        scale: DVec2,
        buf: &mut [Vec<Attr>; 2],
        out: &mut impl FnMut(&[Attr]),
    ) {
        let centroid = (pts[0] + pts[1] + pts[2]) / 3.0;
        let nearest = if self.planar {
            None
        } else {
            // The plane the element was meshed on: within `tol`, or else the closest.
            let d = |t: &UvTriangle| t.plane.dist(centroid).abs();
            self.tris.iter().map(d).reduce(f64::min)
        };
        for t in &self.tris {
            if let Some(dmin) = nearest {
                let dt = t.plane.dist(centroid).abs();
                if dt > self.tol.max(dmin) {
                    continue;
                }
            }
            let [a, b] = buf;
            a.clear();
            a.extend((0..3).map(|k| Attr {
                p: t.frame.to_2d(pts[k]),
                c: cols[k],
            }));
            let s = t.det.signum();
            for e in 0..3 {
                let (p0, p1) = (t.p[e], t.p[(e + 1) % 3]);
                clip(a, |q| s * (p1 - p0).perp_dot(q - p0), b);
                std::mem::swap(a, b);
                if a.len() < 3 {
                    break;
                }
            }
            if a.len() < 3 {
                continue;
            }
            for v in a.iter_mut() {
                v.p = t.to_uv(v.p) * scale;
            }
            out(a);
        }
    }
}

#[cfg(test)]
mod test {
    use super::*;

    #[test]
    fn quad_is_split_like_blender_and_maps_its_corners() {
        let pos = [
            DVec3::new(0., 0., 0.),
            DVec3::new(2., 0., 0.),
            DVec3::new(2., 1., 0.),
            DVec3::new(0., 1., 0.),
        ];
        // Not an affine image of the quad: the two triangles have different maps.
        let uv = [
            DVec2::new(0.1, 0.1),
            DVec2::new(0.9, 0.2),
            DVec2::new(0.7, 0.8),
            DVec2::new(0.2, 0.9),
        ];
        let sp = SourcePolygon::new(&pos, &[0, 1, 2, 3], &uv);
        assert_eq!(sp.tris.len(), 2);
        for t in &sp.tris {
            for k in 0..3 {
                assert!((t.to_uv(t.p[k]) - t.uv[k]).length() < 1e-12);
            }
        }
        // The element covering the whole quad is cut along the 0–2 diagonal.
        let mut parts = Vec::new();
        let mut buf = [Vec::new(), Vec::new()];
        sp.map_element(
            [pos[0], pos[1], pos[2]],
            [DVec3::ONE; 3],
            DVec2::ONE,
            &mut buf,
            &mut |p: &[Attr]| parts.push(p.to_vec()),
        );
        assert_eq!(
            parts.len(),
            1,
            "triangle 0-1-2 lies in the first fan triangle"
        );
        sp.map_element(
            [pos[0], pos[1], pos[3]],
            [DVec3::ONE; 3],
            DVec2::ONE,
            &mut buf,
            &mut |p: &[Attr]| parts.push(p.to_vec()),
        );
        assert_eq!(parts.len(), 3, "triangle 0-1-3 straddles the diagonal");
    }
}
