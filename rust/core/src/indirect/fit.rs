//! Far vertex groups: seen from a group of receiver vertices with nothing in between that
//! could block, a small, far patch's form factor varies smoothly over the group. It is then
//! evaluated exactly on a 3×3 grid over the group's bounds and interpolated (biquadratic)
//! at the vertices, after checking the interpolant against exact values at four more points.

use glam::DVec2;

use super::pair::Pair;
use super::receiver::form_factor;
use super::shooter::{Group, Shooter};
use crate::geom::Plane;
use crate::indirect::patches::Patch;

/// Groups with fewer vertices are evaluated vertex by vertex: a fit costs 13 evaluations.
pub(super) const FIT_MIN_VERTS: usize = 24;
/// A group is far when the patch's radius plus its own is at most this fraction of their
/// distance: the factor then changes by well under a half across it.
const FIT_FAR: f64 = 0.3;
/// The interpolant is used when it misses the exact factor at the check points by at most
/// this fraction of the group's largest factor.
pub(super) const FIT_TOL: f64 = 1e-3;

/// Grid nodes in each axis (fractions of the bounds), and the check points between them.
const NODES: [f64; 3] = [0.0, 0.5, 1.0];
const CHECKS: [f64; 2] = [0.25, 0.75];

impl Shooter<'_> {
    /// Form factors from `patch` (on `plane`) to the vertices of `group`, interpolated, for
    /// a group with no blockers; `None` when the group is small or near, or when the
    /// factor is not smooth enough over it (then each vertex is evaluated alone).
    pub(super) fn fitted(
        &self,
        patch: &Patch,
        plane: &Plane,
        pair: &Pair,
        group: &Group,
    ) -> Option<Vec<f64>> {
        let verts = &self.face_verts[group.start as usize..group.end as usize];
        if verts.len() < FIT_MIN_VERTS {
            return None;
        }
        let centre = (group.lo + group.hi) * 0.5;
        let radius = (group.hi - group.lo).length() * 0.5;
        if !(patch.radius + radius <= FIT_FAR * (patch.centroid - centre).length()) {
            return None;
        }
        let frame = &self.scene.faces[pair.face as usize].frame;
        let n = self.el.normals[verts[0] as usize];
        let mut lo = DVec2::splat(f64::INFINITY);
        let mut hi = DVec2::splat(f64::NEG_INFINITY);
        for &v in verts {
            let q = frame.to_2d(self.points[v as usize]);
            lo = lo.min(q);
            hi = hi.max(q);
        }
        let size = hi - lo;
        if !(size.x > 0.0 && size.y > 0.0) {
            return None;
        }
        // Exact factor at fractions (s, t) of the bounds; `None` where the per-vertex path
        // would give nothing (behind the shooter), which no smooth fit can follow.
        let exact = |s: f64, t: f64| -> Option<f64> {
            let x = frame.to_3d(lo + size * DVec2::new(s, t));
            if plane.dist(x) <= self.tol {
                return None;
            }
            let ff = form_factor(x, n, &pair.poly);
            (ff > 0.0 && ff.is_finite()).then_some(ff)
        };
        let mut grid = [[0.0; 3]; 3];
        for (i, &s) in NODES.iter().enumerate() {
            for (j, &t) in NODES.iter().enumerate() {
                grid[i][j] = exact(s, t)?;
            }
        }
        let interp = |s: f64, t: f64| -> f64 {
            let (ls, lt) = (lagrange(s), lagrange(t));
            let mut sum = 0.0;
            for i in 0..3 {
                for j in 0..3 {
                    sum += grid[i][j] * ls[i] * lt[j];
                }
            }
            sum
        };
        let largest = grid.iter().flatten().fold(0.0f64, |m, &g| m.max(g));
        for &s in &CHECKS {
            for &t in &CHECKS {
                if !((interp(s, t) - exact(s, t)?).abs() <= FIT_TOL * largest) {
                    return None;
                }
            }
        }
        self.fitted_verts
            .fetch_add(verts.len(), std::sync::atomic::Ordering::Relaxed);
        Some(
            verts
                .iter()
                .map(|&v| {
                    let q = (frame.to_2d(self.points[v as usize]) - lo) / size;
                    interp(q.x.clamp(0.0, 1.0), q.y.clamp(0.0, 1.0)).max(0.0)
                })
                .collect(),
        )
    }
}

/// Quadratic Lagrange basis on the nodes 0, ½, 1, at `t`.
fn lagrange(t: f64) -> [f64; 3] {
    [
        2.0 * (t - 0.5) * (t - 1.0),
        -4.0 * t * (t - 1.0),
        2.0 * t * (t - 0.5),
    ]
}

#[cfg(test)]
mod test {
    use super::lagrange;

    #[test]
    fn lagrange_basis_is_one_at_its_node_and_sums_to_one() {
        for (k, t) in [0.0, 0.5, 1.0].into_iter().enumerate() {
            let l = lagrange(t);
            for (i, li) in l.iter().enumerate() {
                assert_eq!(*li, if i == k { 1.0 } else { 0.0 });
            }
        }
        for t in [0.1, 0.3, 0.77] {
            assert!((lagrange(t).iter().sum::<f64>() - 1.0).abs() < 1e-15);
        }
    }
}
