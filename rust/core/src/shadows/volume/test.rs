use super::*;
use crate::geom::Frame;

pub(crate) fn square(c: DVec3, half: f64, up: bool) -> Vec<DVec3> {
    let mut v = vec![
        c + DVec3::new(-half, -half, 0.0),
        c + DVec3::new(half, -half, 0.0),
        c + DVec3::new(half, half, 0.0),
        c + DVec3::new(-half, half, 0.0),
    ];
    if !up {
        v.reverse();
    }
    v
}

pub(crate) fn face(verts: Vec<DVec3>) -> Face {
    let plane = Plane::from_polygon(&verts).unwrap();
    let frame = Frame::on_plane(&plane, verts[0]);
    let poly2 = verts.iter().map(|v| frame.to_2d(*v)).collect();
    Face {
        mesh: 0,
        source_polygon: 0,
        verts,
        plane,
        frame,
        poly2,
        albedo: DVec3::ONE,
        emission: DVec3::ZERO,
        area: 0.0,
    }
}

fn unit_light() -> LightKind {
    let verts = square(DVec3::new(0., 0., 2.), 0.5, false);
    let plane = Plane::from_polygon(&verts).unwrap();
    LightKind::Area {
        verts,
        plane,
        radiance: DVec3::ONE,
    }
}

#[test]
fn square_over_floor_matches_similar_triangles() {
    let occ = face(square(DVec3::new(0., 0., 1.), 0.4, true));
    let sv = shadow_volumes(&unit_light(), None, 0, &occ, 1e-12).unwrap();
    let u = sv.umbra.as_ref().unwrap();
    let s = &sv.penumbra[0];
    let on_floor = |x: f64, y: f64| DVec3::new(x, y, 0.0);
    // Umbra |x|,|y| ≤ 0.3; penumbra |x|,|y| < 1.3.
    assert!(u.contains(on_floor(0.299, 0.299), 0.0));
    assert!(!u.contains(on_floor(0.301, 0.0), 0.0));
    assert!(s.contains(on_floor(1.299, 0.0), 0.0));
    assert!(!s.contains(on_floor(1.301, 0.0), 0.0));
    assert!(s.contains(on_floor(1.29, 1.29), 0.0));
    // Nothing above the occluder is shadowed.
    assert!(!s.contains(DVec3::new(0., 0., 1.5), 0.0));
}

#[test]
fn occluder_behind_light_casts_nothing() {
    let occ = face(square(DVec3::new(0., 0., 3.), 0.4, true));
    assert!(shadow_volumes(&unit_light(), None, 0, &occ, 1e-12).is_none());
}

#[test]
fn light_straddling_occluder_plane_has_no_umbra() {
    // A vertical occluder through the light's centre line.
    let occ = face(vec![
        DVec3::new(0., -0.3, 0.5),
        DVec3::new(0., 0.3, 0.5),
        DVec3::new(0., 0.3, 2.5),
        DVec3::new(0., -0.3, 2.5),
    ]);
    let sv = shadow_volumes(&unit_light(), None, 0, &occ, 1e-12).unwrap();
    assert!(sv.umbra.is_none());
    assert_eq!(sv.penumbra.len(), 2);
    // Just beside the occluder's foot, on either side, light from the other half is cut.
    assert!(sv
        .penumbra
        .iter()
        .any(|v| v.contains(DVec3::new(0.05, 0.0, 0.0), 0.0)));
    assert!(sv
        .penumbra
        .iter()
        .any(|v| v.contains(DVec3::new(-0.05, 0.0, 0.0), 0.0)));
}

#[test]
fn point_light_volume_is_hard() {
    let kind = LightKind::Point {
        position: DVec3::new(0., 0., 2.),
        intensity: DVec3::ONE,
        spot: None,
        radius: 0.0,
        sphere: false,
    };
    let occ = face(square(DVec3::new(0., 0., 1.), 0.5, true));
    let sv = shadow_volumes(&kind, None, 0, &occ, 1e-12).unwrap();
    assert!(sv.hard);
    let u = sv.umbra.unwrap();
    assert!(u.contains(DVec3::new(0.99, 0.0, 0.0), 0.0));
    assert!(!u.contains(DVec3::new(1.01, 0.0, 0.0), 0.0));
}
