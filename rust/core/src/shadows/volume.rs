//! Shadow volumes (paper 2.1, T_sdw) of every (light, occluder) pair that can cast a
//! shadow, as intersections of half-spaces.
//!
//! For a convex light L and convex occluder O, the penumbra volume
//! S = { p : some segment [p, l], l ∈ L, meets O } is convex (for any two points of S a
//! convex combination of their witnesses is a witness for the midpoint). When L lies on one
//! side of O's plane, S is bounded by the *separating* planes through an edge of one polygon
//! and a vertex of the other (the extreme rays of the cone of separating planes, the paper's
//! "largest angle" EV/VE planes), together with L's and O's own planes when they separate.
//! The umbra U = { p : every such segment meets O } is the intersection of the point-light
//! shadow volumes of L's vertices, because the cone from p through O is convex.
//! A light that straddles O's plane is cut by it into two pieces, each with its own S on the
//! far side of O; such a light has no umbra behind O alone.

use glam::{DVec2, DVec3};
use robust::{orient3d, Coord3D};

use crate::geom::plane::newell_normal;
use crate::geom::polygon::{
    clip_polygon_2d, clip_polygon_3d, signed_area_2d, simplify_convex, HalfPlane,
};
use crate::geom::{Frame, Plane};
use crate::scene::solids::Solid;
use crate::scene::{Face, LightKind};

/// Closed convex volume: the points with `plane.dist(p) >= 0` for every plane.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Volume {
    pub planes: Vec<Plane>,
    /// How many trailing planes a broad-phase query may leave out (a solid's front cap:
    /// they bound the volume on the light's side, where receivers seldom are).
    pub cap: usize,
}

impl Volume {
    /// The planes a conservative "may this box touch the volume" query needs.
    pub fn query_planes(&self) -> &[Plane] {
        &self.planes[..self.planes.len() - self.cap.min(self.planes.len())]
    }

    #[cfg(test)]
    pub fn contains(&self, p: DVec3, eps: f64) -> bool {
        self.planes.iter().all(|h| h.dist(p) >= -eps)
    }
}

/// Shadow volumes of one occluder for one light.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ShadowVolumes {
    pub occluder: u32,
    /// Partial or full shadow (one volume per side of the occluder the light is on).
    pub penumbra: Vec<Volume>,
    /// Full shadow; `None` when empty.
    pub umbra: Option<Volume>,
    /// Point and sun lights: umbra and penumbra coincide and the boundary is a D0 edge.
    pub hard: bool,
}

#[inline]
fn c3(p: DVec3) -> Coord3D<f64> {
    Coord3D {
        x: p.x,
        y: p.y,
        z: p.z,
    }
}

/// Plane through a, b, c oriented so that `inside` is on its non-negative side; `None`
/// when the three points are (nearly) collinear.
fn oriented_plane(a: DVec3, b: DVec3, c: DVec3, inside: DVec3) -> Option<Plane> {
    let n = (b - a).cross(c - a);
    let scale = (b - a).length_squared().max((c - a).length_squared());
    if !(n.length_squared() > 1e-24 * scale * scale) {
        return None;
    }
    let p = Plane::from_point_normal(a, n);
    Some(if p.dist(inside) < 0.0 { p.flipped() } else { p })
}

/// Exact side of `d` w.r.t. the plane through a, b, c (sign of robust orient3d).
#[inline]
fn side(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    orient3d(c3(a), c3(b), c3(c), c3(d))
}

/// Separating planes through an edge of `p` (given as vertex index pairs) and a vertex of
/// `q` (exact side tests): all of `p` on one closed side, all of `q` strictly on the other.
/// Each is oriented towards q's side (`towards_q`) or p's side.
fn separating_planes(
    pv: &[DVec3],
    pe: &[[u32; 2]],
    qv: &[DVec3],
    towards_q: bool,
    out: &mut Vec<Plane>,
) {
    let cq = qv.iter().copied().sum::<DVec3>() / qv.len() as f64;
    let cp = pv.iter().copied().sum::<DVec3>() / pv.len() as f64;
    let one_side = |a: DVec3, b: DVec3, v: DVec3, pts: &[DVec3]| -> Option<i8> {
        let mut sg = 0i8;
        for &x in pts {
            let s = side(a, b, v, x);
            if s != 0.0 {
                let t = if s > 0.0 { 1 } else { -1 };
                if sg == 0 {
                    sg = t;
                } else if sg != t {
                    return None;
                }
            }
        }
        Some(sg)
    };
    for &[i, j] in pe {
        let (a, b) = (pv[i as usize], pv[j as usize]);
        for &v in qv {
            // Test q first: for a solid it has the most points and fails soonest.
            let Some(sq) = one_side(a, b, v, qv) else {
                continue;
            };
            let Some(sp) = one_side(a, b, v, pv) else {
                continue;
            };
            // Separating: strictly opposite sides (a polygon wholly in the plane is degenerate).
            if sp == 0 || sq == 0 || sp == sq {
                continue;
            }
            let target = if towards_q { cq } else { cp };
            if let Some(pl) = oriented_plane(a, b, v, target) {
                if !out.iter().any(|o| {
                    (o.n - pl.n).length() < 1e-12 && (o.d - pl.d).abs() < 1e-12 * (1.0 + o.d.abs())
                }) {
                    out.push(pl);
                }
            }
        }
    }
}

fn ring(n: usize) -> Vec<[u32; 2]> {
    (0..n as u32).map(|i| [i, (i + 1) % n as u32]).collect()
}

/// The penumbra volume of light piece `l` (strictly on one side of `o`'s plane) and occluder `o`.
fn penumbra_volume(l: &[DVec3], o: &[DVec3]) -> Volume {
    let mut planes = Vec::new();
    separating_planes(l, &ring(l.len()), o, true, &mut planes);
    separating_planes(o, &ring(o.len()), l, false, &mut planes);
    // The polygons' own planes, when they separate.
    for (poly, other, towards_o) in [(l, o, true), (o, l, false)] {
        let Some(pl) = Plane::from_polygon(poly) else {
            continue;
        };
        let ds: Vec<f64> = other.iter().map(|x| pl.dist(*x)).collect();
        let scale = other
            .iter()
            .chain(poly)
            .map(|x| x.length())
            .fold(1e-300, f64::max);
        let tol = 1e-12 * scale;
        let pos = ds.iter().all(|&d| d >= -tol);
        let neg = ds.iter().all(|&d| d <= tol);
        if pos == neg {
            continue;
        }
        // Orient towards o when the plane is l's; towards the far side from l when it is o's.
        let pl = if towards_o {
            if pos {
                pl
            } else {
                pl.flipped()
            }
        } else if pos {
            pl.flipped()
        } else {
            pl
        };
        planes.push(pl);
    }
    Volume { planes, cap: 0 }
}

/// Shadow volume of occluder `o` from point `l`: the cone from l through o, beyond o.
fn point_volume(l: DVec3, o: &[DVec3], o_plane: &Plane) -> Option<Volume> {
    let dl = o_plane.dist(l);
    let scale = o.iter().map(|x| (*x - l).length()).fold(0.0, f64::max);
    if dl.abs() <= 1e-12 * scale {
        return None;
    }
    let c = o.iter().copied().sum::<DVec3>() / o.len() as f64;
    let mut planes = Vec::with_capacity(o.len() + 1);
    for i in 0..o.len() {
        planes.push(oriented_plane(l, o[i], o[(i + 1) % o.len()], c)?);
    }
    planes.push(if dl > 0.0 {
        o_plane.flipped()
    } else {
        *o_plane
    });
    Some(Volume { planes, cap: 0 })
}

/// Shadow volume of occluder `o` under a directional light travelling along `dir`.
fn sun_volume(dir: DVec3, o: &[DVec3], o_plane: &Plane) -> Option<Volume> {
    let dn = o_plane.n.dot(dir);
    if dn.abs() < 1e-12 {
        return None;
    }
    let c = o.iter().copied().sum::<DVec3>() / o.len() as f64;
    let mut planes = Vec::with_capacity(o.len() + 1);
    for i in 0..o.len() {
        let a = o[i];
        let b = o[(i + 1) % o.len()];
        planes.push(oriented_plane(
            a,
            b,
            a + dir * (b - a).length().max(1e-300),
            c,
        )?);
    }
    // The shadow lies on the side the light travels into.
    planes.push(if dn > 0.0 {
        *o_plane
    } else {
        o_plane.flipped()
    });
    Some(Volume { planes, cap: 0 })
}

/// Shadow volumes of `occluder` (face index `oi`) for a light of the given kind, or `None`
/// when the pair cannot cast a shadow (occluder behind or in the light's plane).
/// `eps` is the scene's length tolerance.
pub fn shadow_volumes(
    kind: &LightKind,
    light_verts_override: Option<&[DVec3]>,
    oi: u32,
    occluder: &Face,
    eps: f64,
) -> Option<ShadowVolumes> {
    match kind {
        LightKind::Area { verts, plane, .. } => {
            let lv = light_verts_override.unwrap_or(verts);
            // Only the part of the occluder in front of the light can stand between it and a
            // lit point.
            let o = clip_polygon_3d(&occluder.verts, plane, eps);
            if o.len() < 3 || o.iter().all(|x| plane.dist(*x) <= eps) {
                return None;
            }
            let o_plane = Plane::from_polygon(&o).unwrap_or(occluder.plane);
            let ds: Vec<f64> = lv.iter().map(|x| o_plane.dist(*x)).collect();
            let above = ds.iter().any(|&d| d > eps);
            let below = ds.iter().any(|&d| d < -eps);
            let mut penumbra = Vec::new();
            let mut umbra = None;
            if above && below {
                for pl in [o_plane, o_plane.flipped()] {
                    let piece = clip_polygon_3d(lv, &pl, 0.0);
                    if piece.len() >= 3 && newell_normal(&piece).length() > 0.0 {
                        penumbra.push(penumbra_volume(&piece, &o));
                    }
                }
            } else if above || below {
                penumbra.push(penumbra_volume(lv, &o));
                let mut planes = Vec::new();
                let mut ok = true;
                for &l in lv {
                    match point_volume(l, &o, &o_plane) {
                        Some(v) => planes.extend(v.planes),
                        None => {
                            ok = false;
                            break;
                        }
                    }
                }
                if ok {
                    planes.push(*plane);
                    umbra = Some(Volume { planes, cap: 0 });
                }
            } else {
                return None;
            }
            Some(ShadowVolumes {
                occluder: oi,
                penumbra,
                umbra,
                hard: false,
            })
        }
        LightKind::Point { position, .. } => {
            let v = point_volume(*position, &occluder.verts, &occluder.plane)?;
            Some(ShadowVolumes {
                occluder: oi,
                penumbra: vec![v.clone()],
                umbra: Some(v),
                hard: true,
            })
        }
        LightKind::Sun { direction, .. } => {
            let v = sun_volume(*direction, &occluder.verts, &occluder.plane)?;
            Some(ShadowVolumes {
                occluder: oi,
                penumbra: vec![v.clone()],
                umbra: Some(v),
                hard: true,
            })
        }
    }
}

/// What a convex solid does under one light.
#[derive(Debug, Clone, PartialEq)]
pub enum SolidShadow {
    /// It cannot shadow anything (behind the light).
    Culled,
    /// It touches or crosses the light's plane (or contains a point light): treat its faces
    /// one by one instead.
    Faces,
    Volumes(ShadowVolumes),
}

/// Shadow volumes of a closed convex solid (occluder index `oi`).
pub fn solid_volumes(
    kind: &LightKind,
    light_verts_override: Option<&[DVec3]>,
    oi: u32,
    s: &Solid,
    eps: f64,
) -> SolidShadow {
    match kind {
        LightKind::Area { verts, plane, .. } => {
            let lv = light_verts_override.unwrap_or(verts);
            let d: Vec<f64> = s.verts.iter().map(|v| plane.dist(*v)).collect();
            if d.iter().all(|&x| x <= eps) {
                return SolidShadow::Culled;
            }
            if d.iter().any(|&x| x <= eps) {
                return SolidShadow::Faces;
            }
            // Penumbra: separating planes (light edge + solid vertex, solid edge + light
            // vertex), the light's plane, and the solid's faces that have the whole light in
            // front of them.
            let mut planes = Vec::new();
            solid_separating_planes(lv, plane, s, &mut planes);
            planes.push(*plane);
            let before = planes.len();
            for f in &s.planes {
                if lv.iter().all(|l| f.dist(*l) >= -eps) {
                    planes.push(f.flipped());
                }
            }
            let cap = planes.len() - before;
            let penumbra = Volume { planes, cap };
            let mut umbra_planes = vec![*plane];
            for &l in lv {
                match point_solid_volume(l, s, eps) {
                    Some(v) => umbra_planes.extend(v.planes),
                    None => return SolidShadow::Faces,
                }
            }
            SolidShadow::Volumes(ShadowVolumes {
                occluder: oi,
                penumbra: vec![penumbra],
                umbra: Some(Volume {
                    planes: umbra_planes,
                    cap: 0,
                }),
                hard: false,
            })
        }
        LightKind::Point { position, .. } => match point_solid_volume(*position, s, eps) {
            Some(v) => SolidShadow::Volumes(ShadowVolumes {
                occluder: oi,
                penumbra: vec![v.clone()],
                umbra: Some(v),
                hard: true,
            }),
            None => SolidShadow::Faces,
        },
        LightKind::Sun { direction, .. } => {
            let front: Vec<bool> = s
                .planes
                .iter()
                .map(|p| p.n.dot(*direction) < -1e-12)
                .collect();
            let mut planes = Vec::new();
            for (e, fp) in s.edges.iter().zip(&s.edge_planes) {
                if front[fp[0] as usize] != front[fp[1] as usize] {
                    let (a, b) = (s.verts[e[0] as usize], s.verts[e[1] as usize]);
                    match oriented_plane(a, b, a + *direction * (b - a).length(), s.centroid) {
                        Some(p) => planes.push(p),
                        None => return SolidShadow::Faces,
                    }
                }
            }
            for (f, is_front) in s.planes.iter().zip(&front) {
                if *is_front {
                    planes.push(f.flipped());
                }
            }
            let v = Volume { planes, cap: 0 };
            SolidShadow::Volumes(ShadowVolumes {
                occluder: oi,
                penumbra: vec![v.clone()],
                umbra: Some(v),
                hard: true,
            })
        }
    }
}

/// Separating planes between a light polygon and a convex solid strictly in front of it,
/// in O(light × solid) rather than by testing every (edge, vertex) pair against every
/// vertex. Through a light edge, the separating plane touching the solid passes through the
/// solid vertex of largest angle about that edge, measured from the light's normal towards
/// the light's interior. Through a light vertex l, the planes touching the solid pass
/// through its silhouette edges as seen from l, and are supporting planes by convexity, so
/// only the light's side needs the exact test.
fn solid_separating_planes(lv: &[DVec3], lplane: &Plane, s: &Solid, out: &mut Vec<Plane>) {
    let cl = lv.iter().copied().sum::<DVec3>() / lv.len() as f64;
    let push = |pl: Plane, out: &mut Vec<Plane>| {
        if !out.iter().any(|o| {
            (o.n - pl.n).length() < 1e-12 && (o.d - pl.d).abs() < 1e-12 * (1.0 + o.d.abs())
        }) {
            out.push(pl);
        }
    };
    let light_on_one_side = |a: DVec3, b: DVec3, c: DVec3| -> Option<i8> {
        let mut sg = 0i8;
        for &x in lv {
            let v = side(a, b, c, x);
            if v != 0.0 {
                let t = if v > 0.0 { 1 } else { -1 };
                if sg != 0 && sg != t {
                    return None;
                }
                sg = t;
            }
        }
        Some(sg)
    };
    for i in 0..lv.len() {
        let (a, b) = (lv[i], lv[(i + 1) % lv.len()]);
        let u = (b - a).normalize_or_zero();
        if u == DVec3::ZERO {
            continue;
        }
        let e1 = lplane.n;
        let mut e2 = u.cross(e1);
        if e2.dot(cl - a) < 0.0 {
            e2 = -e2;
        }
        let ang = |v: DVec3| (v - a).dot(e2).atan2((v - a).dot(e1));
        let best = s
            .verts
            .iter()
            .map(|v| ang(*v))
            .fold(f64::NEG_INFINITY, f64::max);
        for &v in &s.verts {
            if ang(v) < best - 1e-9 {
                continue;
            }
            // Exact check that the plane really separates (the angle only nominates).
            let Some(sl) = light_on_one_side(a, b, v) else {
                continue;
            };
            let solid_ok = s.verts.iter().all(|&x| {
                let t = side(a, b, v, x);
                t == 0.0 || (t > 0.0) != (sl > 0)
            });
            if sl != 0 && solid_ok {
                if let Some(pl) = oriented_plane(a, b, v, s.centroid) {
                    push(pl, out);
                }
            }
        }
    }
    for &l in lv {
        for (e, fp) in s.edges.iter().zip(&s.edge_planes) {
            let f0 = s.planes[fp[0] as usize].dist(l) > 0.0;
            let f1 = s.planes[fp[1] as usize].dist(l) > 0.0;
            if f0 == f1 {
                continue;
            }
            let (a, b) = (s.verts[e[0] as usize], s.verts[e[1] as usize]);
            let Some(pl) = oriented_plane(a, b, l, s.centroid) else {
                continue;
            };
            // The light must lie wholly on the far side (touching allowed).
            let light_ok = lv.iter().all(|&x| {
                let t = side(a, b, l, x);
                t == 0.0 || (t > 0.0) != (side(a, b, l, s.centroid) > 0.0)
            });
            if light_ok {
                push(pl, out);
            }
        }
    }
}

/// Shadow volume of a convex solid from a point: the cone through its silhouette, beyond the
/// faces that face the point. `None` when the point is inside or on the solid.
fn point_solid_volume(l: DVec3, s: &Solid, eps: f64) -> Option<Volume> {
    let front: Vec<bool> = s.planes.iter().map(|p| p.dist(l) > eps).collect();
    if !front.iter().any(|&f| f) {
        return None;
    }
    let mut planes = Vec::new();
    for (e, fp) in s.edges.iter().zip(&s.edge_planes) {
        if front[fp[0] as usize] != front[fp[1] as usize] {
            planes.push(oriented_plane(
                l,
                s.verts[e[0] as usize],
                s.verts[e[1] as usize],
                s.centroid,
            )?);
        }
    }
    for (f, is_front) in s.planes.iter().zip(&front) {
        if *is_front {
            planes.push(f.flipped());
        }
    }
    Some(Volume { planes, cap: 0 })
}

/// Restricts a 3-D half-space to the receiver's plane: a 2-D half-plane in its frame, or
/// all (`Ok(None)`) / nothing (`Err(())`) when the planes are parallel.
fn restrict(h: &Plane, f: &Frame, eps: f64) -> Result<Option<HalfPlane>, ()> {
    let n = DVec2::new(h.n.dot(f.u), h.n.dot(f.v));
    let c = h.d - h.n.dot(f.origin);
    if n.length() <= 1e-14 {
        return if -c >= -eps { Ok(None) } else { Err(()) };
    }
    Ok(Some(HalfPlane { n, c }))
}

/// The part of receiver `r` inside `vol`, or `None` if it has no area.
pub fn clip_to_volume(r: &Face, vol: &Volume, eps: f64) -> Option<Vec<DVec2>> {
    let mut poly = r.poly2.clone();
    for h in &vol.planes {
        match restrict(h, &r.frame, eps) {
            Err(()) => return None,
            Ok(None) => {}
            Ok(Some(hp)) => {
                poly = clip_polygon_2d(&poly, &hp, eps);
                if poly.len() < 3 {
                    return None;
                }
            }
        }
    }
    let poly = simplify_convex(&poly);
    if poly.len() < 3 || signed_area_2d(&poly) <= eps * eps {
        return None;
    }
    Some(poly)
}

#[cfg(test)]
mod test;
