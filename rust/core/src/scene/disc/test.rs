//! Round lights against closed forms computed by quadrature over the light itself.

use std::f64::consts::PI;

use glam::DVec3;

use super::*;
use crate::geom::lambert::polygon_irradiance;

fn point(radius: f64, sphere: bool) -> LightKind {
    LightKind::Point {
        position: DVec3::new(0.3, -0.2, 2.0),
        intensity: DVec3::new(1.0, 2.0, 3.0),
        spot: None,
        radius,
        sphere,
    }
}

/// E = ∫ L (n·ω) dω over the directions from `p` that hit the sphere (centre `c`, radius
/// `r`), by a midpoint rule in (θ, φ) about the axis to the centre.
fn sphere_quadrature(p: DVec3, n: DVec3, c: DVec3, r: f64, radiance: f64) -> f64 {
    let d = c - p;
    let axis = d.normalize();
    let alpha = (r / d.length()).asin();
    let f = Frame::new(DVec3::ZERO, axis);
    let (nt, np) = (400, 400);
    let mut e = 0.0;
    for i in 0..nt {
        let t = alpha * (i as f64 + 0.5) / nt as f64;
        for j in 0..np {
            let ph = 2.0 * PI * (j as f64 + 0.5) / np as f64;
            let w = axis * t.cos() + (f.u * ph.cos() + f.v * ph.sin()) * t.sin();
            let dw = t.sin() * (alpha / nt as f64) * (2.0 * PI / np as f64);
            e += radiance * n.dot(w).max(0.0) * dw;
        }
    }
    e
}

#[test]
fn a_sphere_lights_an_unoccluded_point_like_a_point_light_at_its_centre() {
    let (r, i) = (0.2, 1.0);
    let light = point(r, true);
    let LightKind::Point { position: c, .. } = light else {
        unreachable!()
    };
    let radiance = i / (PI * r * r);
    for (p, n) in [
        (DVec3::ZERO, DVec3::Z),
        (
            DVec3::new(1.0, 0.5, 0.0),
            DVec3::new(0.3, 0.0, 1.0).normalize(),
        ),
        (
            DVec3::new(-0.4, 0.2, 1.5),
            DVec3::new(0.5, -0.2, 1.0).normalize(),
        ),
    ] {
        let d = c - p;
        let point_light = n.dot(d.normalize()) / d.length_squared();
        let quad = sphere_quadrature(p, n, c, r, radiance);
        assert!(
            (quad - point_light).abs() < 1e-4 * point_light,
            "{p} {quad} {point_light}"
        );
        let closed = unoccluded(&light, p, n).expect("above the horizon").y;
        assert!((closed - 2.0 * point_light).abs() < 1e-12 * closed);
        // The silhouette disc carries the same light: its polygon within the stated bound.
        let disc = facing(&light, p, 10.0).unwrap();
        let poly = polygon_irradiance(p, n, &disc.polygon()) * disc.radiance.x;
        assert!(
            (poly - point_light).abs() < (PI / 48.0).powi(2) * point_light,
            "{p} {poly} {point_light} {quad}"
        );
    }
}

#[test]
fn a_soft_point_is_a_disc_facing_the_point() {
    let (r, i) = (0.2, 1.0);
    let light = point(r, false);
    let c = DVec3::new(0.3, -0.2, 2.0);
    let radiance = i / (PI * r * r);
    for (p, n) in [
        (DVec3::ZERO, DVec3::Z),
        (
            DVec3::new(1.0, 0.5, 0.0),
            DVec3::new(0.3, 0.0, 1.0).normalize(),
        ),
    ] {
        // ∫ L cos cos' / R² dA over the disc facing p, by a midpoint rule in polar coordinates.
        let m = (p - c).normalize();
        let f = Frame::new(c, m);
        let (nr, np) = (300, 300);
        let mut quad = 0.0;
        for a in 0..nr {
            let rho = r * (a as f64 + 0.5) / nr as f64;
            for b in 0..np {
                let ph = 2.0 * PI * (b as f64 + 0.5) / np as f64;
                let x = f.to_3d(DVec2::new(rho * ph.cos(), rho * ph.sin()));
                let w = x - p;
                let r2 = w.length_squared();
                let da = rho * (r / nr as f64) * (2.0 * PI / np as f64);
                quad += radiance * n.dot(w).max(0.0) * m.dot(-w).max(0.0) / (r2 * r2) * da;
            }
        }
        let d = c - p;
        let soft = n.dot(d.normalize()) / (d.length_squared() + r * r);
        assert!((quad - soft).abs() < 1e-4 * soft, "{quad} {soft}");
        let closed = unoccluded(&light, p, n).unwrap().x;
        assert!((closed - soft).abs() < 1e-12 * soft);
    }
}

#[test]
fn a_sun_disc_fully_visible_gives_e_cos() {
    let h = 2.5f64.to_radians();
    let dir = DVec3::new(0.3, 0.1, -1.0).normalize();
    let sun = LightKind::Sun {
        direction: dir,
        irradiance: DVec3::splat(3.0),
        half_angle: h,
    };
    let n = DVec3::new(0.1, -0.2, 1.0).normalize();
    let p = DVec3::new(1.0, 2.0, 0.0);
    let disc = facing(&sun, p, 50.0).unwrap();
    // The cone of half-angle h about −dir as a sphere far away: the same quadrature.
    let far = 1e3;
    let quad = sphere_quadrature(p, n, p - dir * far, far * h.sin(), disc.radiance.x);
    let want = 3.0 * n.dot(-dir);
    assert!((quad - want).abs() < 1e-4 * want, "{quad} {want}");
    assert!((unoccluded(&sun, p, n).unwrap().x - want).abs() < 1e-12 * want);
    let poly = polygon_irradiance(p, n, &disc.polygon()) * disc.radiance.x;
    assert!((poly - want).abs() < (PI / 48.0).powi(2) * want);
    // Tilted 90° − 2h from the sun: wholly above the horizon; 90° − h/2: partly below.
    let side = dir.cross(DVec3::X).normalize();
    let tilted = |a: f64| -dir * a.cos() + side * a.sin();
    assert!(unoccluded(&sun, p, tilted(PI / 2.0 - 2.0 * h)).is_some());
    assert!(unoccluded(&sun, p, tilted(PI / 2.0 - 0.5 * h)).is_none());
}

#[test]
fn the_polygon_has_the_disc_area_and_faces_the_point() {
    let d = Disc {
        centre: DVec3::new(1.0, 2.0, 3.0),
        normal: DVec3::new(0.0, 0.6, -0.8),
        radius: 0.3,
        radiance: DVec3::ONE,
    };
    let poly = d.polygon();
    assert_eq!(poly.len(), DISC_SIDES);
    let newell = crate::geom::plane::newell_normal(&poly);
    assert!((0.5 * newell.length() - PI * 0.09).abs() < 1e-12);
    assert!(newell.normalize().dot(d.normal) > 1.0 - 1e-12);
}

/// Tiny deterministic generator for the property test below.
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// The proxy's promise: from every point an occluder shadows (some ray to the point's own
/// disc meets the occluder), every ray to that disc meets the proxy disc's plane within its
/// radius.
#[test]
fn the_proxy_disc_holds_every_shadowed_point_s_cone() {
    let mut rng = Lcg(7);
    for sphere in [false, true] {
        let light = point(0.2, sphere);
        let LightKind::Point { position: c, .. } = light else {
            unreachable!()
        };
        let occ: Vec<DVec3> = [(-0.3, -0.3), (0.4, -0.3), (0.4, 0.2), (-0.3, 0.2)]
            .iter()
            .map(|&(x, y)| DVec3::new(x + 0.3, y - 0.2, 1.2))
            .collect();
        let near = polygon_distance(c, &occ);
        assert!((near - 0.8).abs() < 1e-12);
        let Proxy::Disc(px) = proxy(&light, &occ, near, DVec3::ZERO, 5.0) else {
            panic!("a proxy disc")
        };
        assert!(px.radius > 0.2 && px.radius < 0.4, "{}", px.radius);
        let plane = px.plane();
        let mut shadowed = 0;
        for _ in 0..4000 {
            let p = DVec3::new(
                rng.next() * 4.0 - 2.0,
                rng.next() * 4.0 - 2.0,
                rng.next() * 1.1,
            );
            let disc = facing(&light, p, 10.0).unwrap();
            let rim = disc.polygon();
            let hits = rim
                .iter()
                .chain(std::iter::once(&disc.centre))
                .any(|l| crate::direct::exact::segment_blocked(p, *l, &occ));
            if !hits {
                continue;
            }
            shadowed += 1;
            // Every ray to the point's own disc (its rim, sampled finely) meets the proxy's
            // plane inside the disc of the proxy's radius, and so inside its polygon.
            let fine = Frame::new(disc.centre, disc.normal);
            let proxy_poly = px.circumscribed();
            for k in 0..720 {
                let t = std::f64::consts::TAU * k as f64 / 720.0;
                let l = fine.to_3d(DVec2::new(disc.radius * t.cos(), disc.radius * t.sin()));
                let w = l - p;
                let s = -plane.dist(p) / plane.n.dot(w);
                let x = p + w * s;
                assert!((x - px.centre).length() <= px.radius * (1.0 + 1e-9));
                let inside = (0..PROXY_SIDES).all(|i| {
                    let (a, b) = (proxy_poly[i], proxy_poly[(i + 1) % PROXY_SIDES]);
                    (b - a).cross(x - a).dot(px.normal) >= 0.0
                });
                assert!(inside);
            }
        }
        assert!(shadowed > 200, "{shadowed}");
    }
}

#[test]
fn distance_to_a_polygon() {
    let sq: Vec<DVec3> = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
        .iter()
        .map(|&(x, y)| DVec3::new(x, y, 0.0))
        .collect();
    assert!((polygon_distance(DVec3::new(0.5, 0.5, 2.0), &sq) - 2.0).abs() < 1e-15);
    assert!((polygon_distance(DVec3::new(2.0, 0.5, 0.0), &sq) - 1.0).abs() < 1e-15);
    assert!((polygon_distance(DVec3::new(2.0, 2.0, 1.0), &sq) - 3f64.sqrt()).abs() < 1e-15);
}
