//! The last check of every bake: each input polygon's output triangles cover its area, lie
//! in it and face its way. A bake that lost or moved geometry (a scene past the precision
//! contract of `precision`, or a bug) ends in an error naming the polygon instead of a
//! result that silently misses a floor.
//!
//! The check is on the output itself (after welding), so it sees what the user would get.
//! It is linear in the output: each triangle is compared with the convex pieces of its own
//! source polygon only.

use glam::DVec3;
use rayon::prelude::*;

use crate::bake::BakedMesh;
use crate::geom::polygon::signed_area_2d;
use crate::scene::{Face, Scene};
use crate::BakeError;

/// Output area may differ from the input area by this fraction (the mesher snaps corners by
/// ~1e-9 of a receiver, and the weld merges vertices within 1e-9 of the scene), and a vertex
/// may lie this fraction of its polygon's size outside it.
pub const AREA_TOLERANCE: f64 = 1e-5;
pub const DISTANCE_TOLERANCE: f64 = 1e-6;

/// Checks `out` (one `BakedMesh` per scene mesh, same order) against the scene's polygons.
pub fn check(scene: &Scene, out: &[BakedMesh]) -> Result<(), BakeError> {
    let weld = 1e-9 * scene.diagonal();
    for (mi, (info, baked)) in scene.meshes.iter().zip(out).enumerate() {
        if !info.output {
            continue;
        }
        let obj = format!("mesh {:?} (meshes[{mi}])", info.name);
        let faces = &scene.faces[info.face_start..info.face_end];
        // Convex pieces of each source polygon (validate keeps a polygon's pieces together).
        let mut pieces: Vec<Vec<usize>> = vec![Vec::new(); info.n_polygons];
        for (i, f) in faces.iter().enumerate() {
            pieces[f.source_polygon as usize].push(i);
        }
        // Sizes and windings once per polygon and face, not per corner (a 1,000-gon's
        // outline would otherwise be walked three times per triangle).
        let sizes: Vec<f64> = pieces.iter().map(|own| extent(faces, own)).collect();
        let ccw: Vec<bool> = faces
            .iter()
            .map(|f| signed_area_2d(&f.poly2) >= 0.0)
            .collect();
        // One triangle's signed area in its polygon's plane, or why it fails.
        let triangle = |t: usize| -> Result<f64, BakeError> {
            let tri = baked.triangles[t];
            let p = baked.source_polygon[t] as usize;
            let Some(own) = pieces.get(p).filter(|v| !v.is_empty()) else {
                return Err(BakeError::invalid(
                    &obj,
                    format!("polygons[{p}]"),
                    "the bake made triangles for a polygon that has none (internal error)",
                ));
            };
            let v = tri.map(|i| DVec3::from_array(baked.positions[i as usize]));
            let tol = DISTANCE_TOLERANCE * sizes[p] + 4.0 * weld;
            // The piece the triangle lies in gives its facing: a non-planar polygon's pieces
            // lie in planes of their own.
            let centre = (v[0] + v[1] + v[2]) / 3.0;
            let piece = own
                .iter()
                .copied()
                .find(|&i| inside(&faces[i], ccw[i], centre, tol))
                .unwrap_or(own[0]);
            let n = faces[piece].plane.n;
            let signed = 0.5 * (v[1] - v[0]).cross(v[2] - v[0]).dot(n);
            if signed < -(tol * tol) {
                return Err(lost(&obj, p, "a triangle of the bake faces the other way"));
            }
            for q in v {
                if !own.iter().any(|&i| inside(&faces[i], ccw[i], q, tol)) {
                    return Err(lost(
                        &obj,
                        p,
                        &format!(
                            "a triangle of the bake has a corner {} outside the polygon",
                            show(q)
                        ),
                    ));
                }
            }
            Ok(signed)
        };
        // On all threads (room-8328's 3.3M triangles were one of the steps that left a core
        // idle at the end of its bake); a failure is found again in order, so the error
        // names the first triangle that fails, and the areas are summed in order, as on one
        // thread.
        let signed: Vec<f64> = (0..baked.triangles.len())
            .into_par_iter()
            .map(|t| triangle(t).unwrap_or(f64::NAN))
            .collect();
        if let Some(t) = signed.iter().position(|x| x.is_nan()) {
            triangle(t)?;
        }
        let mut covered = vec![0.0f64; info.n_polygons];
        for (&p, a) in baked.source_polygon.iter().zip(&signed) {
            covered[p as usize] += a;
        }
        for (p, own) in pieces.iter().enumerate() {
            if own.is_empty() {
                continue; // degenerate, dropped with a warning by `validate`
            }
            let area: f64 = own.iter().map(|&i| faces[i].area).sum();
            let tol = AREA_TOLERANCE * area + 4.0 * weld * sizes[p];
            if (covered[p] - area).abs() > tol {
                return Err(lost(
                    &obj,
                    p,
                    &format!(
                        "the bake covers {:.6}% of its area",
                        100.0 * covered[p] / area
                    ),
                ));
            }
        }
    }
    Ok(())
}

fn lost(obj: &str, p: usize, what: &str) -> BakeError {
    BakeError::invalid(
        obj,
        format!("polygons[{p}]"),
        format!(
            "{what}: geometry lost to floating-point precision (see the README's precision contract)"
        ),
    )
}

fn show(q: DVec3) -> String {
    format!("({:e}, {:e}, {:e})", q.x, q.y, q.z)
}

/// The largest extent of a polygon's pieces.
fn extent(faces: &[Face], pieces: &[usize]) -> f64 {
    pieces
        .iter()
        .map(|&i| faces[i].extent(0.0))
        .fold(0.0, f64::max)
}

/// `q` within `tol` of the convex face (its plane, and its 2-D outline).
fn inside(f: &Face, ccw: bool, q: DVec3, tol: f64) -> bool {
    if f.plane.dist(q).abs() > tol {
        return false;
    }
    let p = f.frame.to_2d(q);
    let poly = &f.poly2;
    let n = poly.len();
    // Signed distance of p to the left of edge i (inside for a counter-clockwise outline).
    let left_of = |i: usize| {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        let e = b - a;
        let len = e.length();
        if len == 0.0 {
            return f64::INFINITY;
        }
        let d = e.perp_dot(p - a) / len;
        if ccw {
            d
        } else {
            -d
        }
    };
    if n <= 16 || !ccw {
        return (0..n).all(|i| left_of(i) >= -tol);
    }
    // Many edges (a 1,000-gon disk): find the wedge of the fan from vertex 0 that holds p by
    // bisection, and test the one outline edge that closes it, and the fan's two sides.
    let side = |i: usize| (poly[i] - poly[0]).perp_dot(p - poly[0]);
    if side(1) < 0.0 {
        return left_of(0) >= -tol;
    }
    if side(n - 1) > 0.0 {
        return left_of(n - 1) >= -tol;
    }
    let (mut lo, mut hi) = (1usize, n - 1);
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if side(mid) >= 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    left_of(lo) >= -tol
}

#[cfg(test)]
mod test {
    use super::*;
    use crate::scene::json::SceneJson;

    /// A floor (two polygons) under a square light, baked.
    fn baked() -> (Scene, Vec<BakedMesh>) {
        let text = r#"{"format":"penumbra-scene","version":1,
          "meshes":[{"name":"Floor","positions":[[-1,-1,0],[0,-1,0],[0,1,0],[-1,1,0],[1,-1,0],[1,1,0]],
                     "polygons":[[0,1,2,3],[1,4,5,2]]},
                    {"name":"Occ","positions":[[-0.2,-0.2,0.5],[0.2,-0.2,0.5],[0.2,0.2,0.5],[-0.2,0.2,0.5]],
                     "polygons":[[0,1,2,3]]}],
          "lights":[{"name":"L","polygon":[[-0.3,-0.3,2],[-0.3,0.3,2],[0.3,0.3,2],[0.3,-0.3,2]],"radiance":[1,1,1]}],
          "settings":{"indirect":false}}"#;
        let scene = crate::scene::validate(&SceneJson::from_str(text).unwrap()).unwrap();
        let bake = crate::bake(&scene, &crate::Progress::new()).unwrap();
        (scene, bake.meshes)
    }

    #[test]
    fn a_real_bake_passes() {
        let (scene, out) = baked();
        check(&scene, &out).unwrap();
    }

    #[test]
    fn a_missing_triangle_is_named() {
        let (scene, mut out) = baked();
        let t = out[0].source_polygon.iter().position(|&p| p == 1).unwrap();
        out[0].triangles.remove(t);
        out[0].source_polygon.remove(t);
        let e = check(&scene, &out).unwrap_err().to_string();
        assert!(
            e.starts_with(r#"mesh "Floor" (meshes[0]): polygons[1]: the bake covers"#),
            "{e}"
        );
        assert!(e.contains("geometry lost"), "{e}");
    }

    #[test]
    fn a_corner_outside_its_polygon_is_named() {
        let (scene, mut out) = baked();
        // Shift one polygon-0 triangle (x in [-1, 0]) by 1.5 along x, onto polygon 1.
        let t = out[0].source_polygon.iter().position(|&p| p == 0).unwrap();
        for k in 0..3 {
            let mut q = out[0].positions[out[0].triangles[t][k] as usize];
            q[0] += 1.5;
            out[0].positions.push(q);
            out[0].triangles[t][k] = (out[0].positions.len() - 1) as u32;
        }
        let e = check(&scene, &out).unwrap_err().to_string();
        assert!(
            e.contains("polygons[0]") && e.contains("outside the polygon"),
            "{e}"
        );
    }

    /// The check runs on all threads, yet of two broken triangles it names the first, as
    /// a serial check would (and as the same bake always does).
    #[test]
    fn the_first_broken_triangle_is_named() {
        let (scene, mut out) = baked();
        let n = out[0].triangles.len();
        assert!(n >= 4, "{n}");
        // A flipped triangle last, a corner moved far off the floor first.
        out[0].triangles[n - 1].swap(1, 2);
        let mut q = out[0].positions[out[0].triangles[0][0] as usize];
        q[2] += 1.0;
        out[0].positions.push(q);
        out[0].triangles[0][0] = (out[0].positions.len() - 1) as u32;
        let e = check(&scene, &out).unwrap_err().to_string();
        assert!(e.contains("outside the polygon"), "{e}");
        // With the first mended, the flipped one is named.
        let (_, good) = baked();
        out[0].triangles[0] = good[0].triangles[0];
        let e = check(&scene, &out).unwrap_err().to_string();
        assert!(e.contains("faces the other way"), "{e}");
    }

    #[test]
    fn a_flipped_triangle_is_named() {
        let (scene, mut out) = baked();
        let t = out[1].triangles.len() / 2;
        out[1].triangles[t].swap(1, 2);
        let e = check(&scene, &out).unwrap_err().to_string();
        assert!(
            e.starts_with(
                r#"mesh "Occ" (meshes[1]): polygons[0]: a triangle of the bake faces the other way"#
            ),
            "{e}"
        );
    }
}
