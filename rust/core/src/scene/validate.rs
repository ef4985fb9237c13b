//! Checks every value of a parsed scene and builds the internal `Scene`. Errors name the
//! object (by name and index) and the field; degenerate polygons are dropped with a warning
//! because real meshes have them.

use glam::DVec3;

use super::convex::convex_pieces;
use super::json::{LightJson, MeshJson, PerPolygon, SceneJson};
use super::solids::{find_solids, Occluder};
use super::{Face, Light, LightKind, MeshInfo, Scene, Spot};
use crate::geom::{Frame, Plane};
use crate::scene::settings::Settings;
use crate::BakeError;

/// Largest coordinate magnitude accepted: far beyond any real scene, small enough that
/// squared distances stay finite.
const MAX_COORD: f64 = 1e12;
const MAX_RADIANCE: f64 = 1e30;

pub fn validate(s: &SceneJson) -> Result<Scene, BakeError> {
    let mut warnings = Vec::new();
    let mut meshes = Vec::with_capacity(s.meshes.len());
    let mut faces = Vec::new();
    let mut occluders = Vec::new();
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);

    if s.meshes.is_empty() {
        return Err(BakeError::Empty("the scene has no meshes".into()));
    }
    let world = s.settings.world.is_some_and(|w| w.iter().any(|x| *x > 0.0));
    if s.lights.is_empty() && !has_emission(s) && !world {
        return Err(BakeError::Empty(
            "the scene has no lights, no emissive polygons and no world light".into(),
        ));
    }
    for (mi, m) in s.meshes.iter().enumerate() {
        let obj = format!("mesh {:?} (meshes[{mi}])", m.name);
        let start = faces.len();
        validate_mesh(mi, m, &obj, &mut faces, &mut warnings, &mut lo, &mut hi)?;
        occluders.extend(find_solids(m, &faces, start));
        meshes.push(MeshInfo {
            name: m.name.clone(),
            output: m.output.unwrap_or(true),
            n_polygons: m.polygons.len(),
            face_start: start,
            face_end: faces.len(),
        });
    }
    if faces.is_empty() {
        return Err(BakeError::Empty(
            "every polygon of every mesh is degenerate (no area)".into(),
        ));
    }
    // Default element sizes follow what is baked: a light far off (a sun-sized area light
    // 100 m up) must not make every element of a 1 m object coarse.
    let mesh_diag = (hi - lo).length();
    let mut face_occluder = vec![u32::MAX; faces.len()];
    for (oi, o) in occluders.iter().enumerate() {
        for &f in o.faces() {
            face_occluder[f as usize] = oi as u32;
        }
    }
    for (fi, fo) in face_occluder.iter_mut().enumerate() {
        if *fo == u32::MAX {
            *fo = occluders.len() as u32;
            occluders.push(Occluder::Face(fi as u32));
        }
    }
    let mut lights = Vec::with_capacity(s.lights.len());
    for (li, l) in s.lights.iter().enumerate() {
        let obj = format!("light {:?} (lights[{li}])", l.name);
        let light = validate_light(li, l, &obj)?;
        if let LightKind::Area { verts, .. } = &light.kind {
            for v in verts {
                lo = lo.min(*v);
                hi = hi.max(*v);
            }
        }
        if let LightKind::Point {
            position, radius, ..
        } = &light.kind
        {
            lo = lo.min(*position - DVec3::splat(*radius));
            hi = hi.max(*position + DVec3::splat(*radius));
        }
        lights.push(light);
    }
    warnings.extend(super::reach::light_warnings(&lights, &faces));
    let emitters = super::emitters::emitter_lights(
        &meshes,
        &faces,
        &face_occluder,
        &occluders,
        lights.len(),
        &mut warnings,
    );
    lights.extend(emitters);
    super::precision::check(&meshes, &faces, lo, hi)?;
    let settings = Settings::from_json(&s.settings, mesh_diag)?;

    // Refuse up front what would not fit, before any stage allocates.
    let lightmaps = s.meshes.iter().filter(|m| m.uv.is_some()).count();
    let est = super::resources::estimate(&faces, lights.len(), &settings, &s.settings, lightmaps);
    super::resources::check(&est, &settings)?;
    Ok(Scene {
        meshes,
        faces,
        occluders,
        face_occluder,
        lights,
        settings,
        bounds_min: lo,
        bounds_max: hi,
        warnings,
    })
}

fn has_emission(s: &SceneJson) -> bool {
    s.meshes.iter().any(|m| match &m.emission {
        Some(PerPolygon::Uniform(c)) => c.iter().any(|&x| x > 0.0),
        Some(PerPolygon::PerPolygon(v)) => v.iter().any(|c| c.iter().any(|&x| x > 0.0)),
        None => false,
    })
}

/// A number as a person would write it in a message: 1e30, not thirty-one digits.
fn num(x: f64) -> String {
    if x != 0.0 && x.is_finite() && !(1e-4..1e6).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

fn check_point(obj: &str, field: &str, p: [f64; 3]) -> Result<DVec3, BakeError> {
    for (k, &x) in p.iter().enumerate() {
        if !x.is_finite() {
            return Err(BakeError::invalid(
                obj,
                field,
                format!("coordinate {k} is {x}, not a finite number"),
            ));
        }
        if x.abs() > MAX_COORD {
            return Err(BakeError::invalid(
                obj,
                field,
                format!("coordinate {k} = {} is beyond ±{MAX_COORD:e}", num(x)),
            ));
        }
    }
    Ok(DVec3::from_array(p))
}

fn check_color(obj: &str, field: &str, c: [f64; 3], max: f64) -> Result<DVec3, BakeError> {
    for (k, &x) in c.iter().enumerate() {
        if !x.is_finite() || x < 0.0 || x > max {
            return Err(BakeError::invalid(
                obj,
                field,
                format!("channel {k} is {}, must be in [0, {}]", num(x), num(max)),
            ));
        }
    }
    Ok(DVec3::from_array(c))
}

fn per_polygon(
    obj: &str,
    field: &str,
    v: &Option<PerPolygon>,
    n: usize,
    default: [f64; 3],
    max: f64,
) -> Result<Vec<DVec3>, BakeError> {
    match v {
        None => Ok(vec![DVec3::from_array(default); n]),
        Some(PerPolygon::Uniform(c)) => Ok(vec![check_color(obj, field, *c, max)?; n]),
        Some(PerPolygon::PerPolygon(cs)) => {
            if cs.len() != n {
                return Err(BakeError::invalid(
                    obj,
                    field,
                    format!("has {} entries for {n} polygons", cs.len()),
                ));
            }
            cs.iter()
                .enumerate()
                .map(|(i, c)| check_color(obj, &format!("{field}[{i}]"), *c, max))
                .collect()
        }
    }
}

#[allow(clippy::too_many_arguments)]
fn validate_mesh(
    mi: usize,
    m: &MeshJson,
    obj: &str,
    faces: &mut Vec<Face>,
    warnings: &mut Vec<String>,
    lo: &mut DVec3,
    hi: &mut DVec3,
) -> Result<(), BakeError> {
    let pos: Vec<DVec3> = m
        .positions
        .iter()
        .enumerate()
        .map(|(i, p)| check_point(obj, &format!("positions[{i}]"), *p))
        .collect::<Result<_, _>>()?;
    let albedo = per_polygon(
        obj,
        "albedo",
        &m.albedo,
        m.polygons.len(),
        [0.8, 0.8, 0.8],
        1.0,
    )?;
    let emission = per_polygon(
        obj,
        "emission",
        &m.emission,
        m.polygons.len(),
        [0.0; 3],
        MAX_RADIANCE,
    )?;
    let mut dropped = 0usize;
    for (pi, poly) in m.polygons.iter().enumerate() {
        if poly.len() < 3 {
            return Err(BakeError::invalid(
                obj,
                format!("polygons[{pi}]"),
                format!("has {} vertices, needs at least 3", poly.len()),
            ));
        }
        let mut pts = Vec::with_capacity(poly.len());
        for (k, &ix) in poly.iter().enumerate() {
            if ix < 0 || ix as usize >= pos.len() {
                return Err(BakeError::invalid(
                    obj,
                    format!("polygons[{pi}][{k}]"),
                    format!(
                        "index {ix} is out of range (the mesh has {} positions)",
                        pos.len()
                    ),
                ));
            }
            pts.push(pos[ix as usize]);
        }
        let pieces = convex_pieces(&pts);
        if pieces.is_empty() {
            dropped += 1;
            continue;
        }
        for verts in pieces {
            let Some(plane) = Plane::from_polygon(&verts) else {
                continue;
            };
            let frame = Frame::on_plane(&plane, verts[0]);
            let poly2: Vec<_> = verts.iter().map(|v| frame.to_2d(*v)).collect();
            let area = crate::geom::polygon::signed_area_2d(&poly2);
            if !(area > 0.0) {
                continue;
            }
            for v in &verts {
                *lo = lo.min(*v);
                *hi = hi.max(*v);
            }
            faces.push(Face {
                mesh: mi as u32,
                source_polygon: pi as u32,
                verts,
                plane,
                frame,
                poly2,
                albedo: albedo[pi],
                emission: emission[pi],
                area,
            });
        }
    }
    if dropped > 0 {
        warnings.push(format!(
            "{obj}: dropped {dropped} degenerate polygon(s) with no area"
        ));
    }
    Ok(())
}

fn validate_light(li: usize, l: &LightJson, obj: &str) -> Result<Light, BakeError> {
    let kinds = [
        l.polygon.is_some(),
        l.point.is_some(),
        l.direction.is_some() && l.spot.is_none() && l.point.is_none(),
    ];
    let n_kinds = kinds.iter().filter(|&&k| k).count();
    if n_kinds != 1 {
        return Err(BakeError::invalid(
            obj,
            "polygon/point/direction",
            "a light needs exactly one of `polygon`, `point` or `direction`",
        ));
    }
    let kind = if let Some(poly) = &l.polygon {
        let radiance = check_color(
            obj,
            "radiance",
            l.radiance.ok_or_else(|| {
                BakeError::invalid(obj, "radiance", "an area light needs `radiance`")
            })?,
            MAX_RADIANCE,
        )?;
        if poly.len() < 3 {
            return Err(BakeError::invalid(
                obj,
                "polygon",
                format!("has {} vertices, needs at least 3", poly.len()),
            ));
        }
        let verts: Vec<DVec3> = poly
            .iter()
            .enumerate()
            .map(|(i, p)| check_point(obj, &format!("polygon[{i}]"), *p))
            .collect::<Result<_, _>>()?;
        let pieces = convex_pieces(&verts);
        if pieces.is_empty() {
            return Err(BakeError::invalid(
                obj,
                "polygon",
                "has zero area (degenerate light)",
            ));
        }
        if pieces.len() > 1 || pieces[0].len() < verts.len() - count_collinear(&verts) {
            return Err(BakeError::invalid(
                obj,
                "polygon",
                "must be a convex planar polygon (split it into several lights)",
            ));
        }
        let verts = pieces.into_iter().next().unwrap();
        let plane = Plane::from_polygon(&verts).expect("non-degenerate");
        LightKind::Area {
            verts,
            plane,
            radiance,
        }
    } else if let Some(p) = l.point {
        let position = check_point(obj, "point", p)?;
        let intensity = check_color(
            obj,
            "intensity",
            l.intensity.ok_or_else(|| {
                BakeError::invalid(obj, "intensity", "a point light needs `intensity`")
            })?,
            MAX_RADIANCE,
        )?;
        let spot = match &l.spot {
            None => None,
            Some(s) => {
                let d = check_point(obj, "spot.direction", s.direction)?;
                if d.length() == 0.0 {
                    return Err(BakeError::invalid(
                        obj,
                        "spot.direction",
                        "is the zero vector",
                    ));
                }
                if !(s.angle.is_finite() && s.angle > 0.0 && s.angle <= std::f64::consts::PI) {
                    return Err(BakeError::invalid(
                        obj,
                        "spot.angle",
                        format!("{} must be in (0, π]", s.angle),
                    ));
                }
                if !(s.blend.is_finite() && (0.0..=1.0).contains(&s.blend)) {
                    return Err(BakeError::invalid(
                        obj,
                        "spot.blend",
                        format!("{} must be in [0, 1]", s.blend),
                    ));
                }
                Some(Spot {
                    direction: d.normalize(),
                    cos_half_angle: (s.angle * 0.5).cos(),
                    blend: s.blend,
                })
            }
        };
        let radius = l.radius.unwrap_or(0.0);
        if !(radius.is_finite() && radius >= 0.0 && radius <= MAX_COORD) {
            return Err(BakeError::invalid(
                obj,
                "radius",
                format!("{radius} must be a finite length ≥ 0"),
            ));
        }
        let sphere = l.sphere.unwrap_or(false);
        if sphere && radius == 0.0 {
            return Err(BakeError::invalid(
                obj,
                "sphere",
                "a sphere needs a `radius` above 0",
            ));
        }
        if l.angle.is_some() {
            return Err(BakeError::invalid(
                obj,
                "angle",
                "only a sun has an `angle` (a spot's cone is `spot.angle`)",
            ));
        }
        LightKind::Point {
            position,
            intensity,
            spot,
            radius,
            sphere,
        }
    } else {
        let d = check_point(obj, "direction", l.direction.unwrap())?;
        if d.length() == 0.0 {
            return Err(BakeError::invalid(obj, "direction", "is the zero vector"));
        }
        let irradiance = check_color(
            obj,
            "irradiance",
            l.irradiance.ok_or_else(|| {
                BakeError::invalid(obj, "irradiance", "a sun light needs `irradiance`")
            })?,
            MAX_RADIANCE,
        )?;
        let angle = l.angle.unwrap_or(0.0);
        if !(angle.is_finite() && (0.0..std::f64::consts::PI).contains(&angle)) {
            return Err(BakeError::invalid(
                obj,
                "angle",
                format!("{angle} must be in [0, π) radians"),
            ));
        }
        for (field, given) in [
            ("radius", l.radius.is_some()),
            ("sphere", l.sphere.is_some()),
        ] {
            if given {
                return Err(BakeError::invalid(
                    obj,
                    field,
                    "a sun has no radius (its size is `angle`)",
                ));
            }
        }
        LightKind::Sun {
            direction: d.normalize(),
            irradiance,
            half_angle: 0.5 * angle,
        }
    };
    Ok(Light {
        name: l.name.clone(),
        index: li,
        kind,
        from_face: None,
    })
}

/// Vertices that lie on the line through their neighbours: they vanish in a convex piece
/// without making the polygon non-convex.
fn count_collinear(v: &[DVec3]) -> usize {
    let n = v.len();
    (0..n)
        .filter(|&i| {
            let a = v[(i + n - 1) % n];
            let b = v[i];
            let c = v[(i + 1) % n];
            (b - a).cross(c - b).length() <= 1e-12 * (c - a).length_squared()
        })
        .count()
}
