//! Moving least squares on scattered points in a plane: weights that turn values at the
//! points into a value at another point, exact for linear or quadratic fields. Used to fill
//! in indirect light between the vertices where it was computed (`gather`).

use glam::DVec2;

/// Moving least squares: the weights λ_i with value Σ λ_i f_i at `x` that fit a linear
/// (`N` = 3) or quadratic (`N` = 6) polynomial to the points `cands` by weighted least
/// squares (Wendland weights over a radius just past the farthest point). Reproduces such
/// polynomials exactly. Appends the weights and returns true, or appends nothing and returns
/// false when the points do not determine the polynomial well.
pub(super) fn fit<const N: usize>(
    x: DVec2,
    cands: &[u32],
    uv: &[DVec2],
    out: &mut Vec<(u32, f64)>,
) -> bool {
    if cands.len() < N {
        return false;
    }
    let reach = cands
        .iter()
        .map(|&k| (uv[k as usize] - x).length())
        .fold(0.0f64, f64::max)
        * 1.25;
    if !(reach > 0.0) {
        return false;
    }
    let w = |d: DVec2| {
        let t = (d.length() / reach).min(1.0);
        (1.0 - t).powi(4) * (4.0 * t + 1.0)
    };
    // The basis in coordinates scaled by `reach`, so the normal matrix is well conditioned.
    let basis = |d: DVec2| -> [f64; N] {
        let (u, v) = (d.x / reach, d.y / reach);
        let all = [1.0, u, v, u * u, u * v, v * v];
        std::array::from_fn(|i| all[i])
    };
    let mut m = [[0.0f64; N]; N];
    for &k in cands {
        let d = uv[k as usize] - x;
        let (p, wk) = (basis(d), w(d));
        for i in 0..N {
            for j in 0..N {
                m[i][j] += wk * p[i] * p[j];
            }
        }
    }
    // The value at x is the constant term: e₀ᵀ M⁻¹ Σ w p f, so solve M z = e₀.
    let mut e0 = [0.0; N];
    e0[0] = 1.0;
    let Some(z) = solve_spd(m, e0) else {
        return false;
    };
    let start = out.len();
    for &k in cands {
        let d = uv[k as usize] - x;
        let p = basis(d);
        let l = w(d) * (0..N).map(|i| z[i] * p[i]).sum::<f64>();
        if l != 0.0 {
            out.push((k, l));
        }
    }
    out.len() > start
}

/// Solves `m z = b` for a symmetric positive definite `m` by Cholesky, or `None` when a
/// pivot falls under 1e-9 of the largest diagonal entry (the points nearly on a curve the
/// basis cannot tell apart).
fn solve_spd<const N: usize>(m: [[f64; N]; N], b: [f64; N]) -> Option<[f64; N]> {
    let scale = (0..N).map(|i| m[i][i]).fold(0.0f64, f64::max);
    let mut l = [[0.0f64; N]; N];
    for i in 0..N {
        for j in 0..=i {
            let s = m[i][j] - (0..j).map(|k| l[i][k] * l[j][k]).sum::<f64>();
            if i == j {
                if !(s > 1e-9 * scale) {
                    return None;
                }
                l[i][i] = s.sqrt();
            } else {
                l[i][j] = s / l[j][j];
            }
        }
    }
    let mut y = [0.0; N];
    for i in 0..N {
        y[i] = (b[i] - (0..i).map(|k| l[i][k] * y[k]).sum::<f64>()) / l[i][i];
    }
    let mut z = [0.0; N];
    for i in (0..N).rev() {
        z[i] = (y[i] - (i + 1..N).map(|k| l[k][i] * z[k]).sum::<f64>()) / l[i][i];
    }
    Some(z)
}

/// Inverse-distance weights: for points that fit no plane.
pub(super) fn shepard(x: DVec2, cands: &[u32], uv: &[DVec2], out: &mut Vec<(u32, f64)>) {
    let w: Vec<f64> = cands
        .iter()
        .map(|&k| 1.0 / ((uv[k as usize] - x).length_squared() + f64::MIN_POSITIVE))
        .collect();
    let total: f64 = w.iter().sum();
    out.extend(cands.iter().zip(&w).map(|(&k, &wk)| (k, wk / total)));
}

#[cfg(test)]
mod test {
    use super::*;

    /// The weights `w` applied to `f` at the points.
    fn apply(w: &[(u32, f64)], pts: &[DVec2], f: impl Fn(DVec2) -> f64) -> f64 {
        w.iter().map(|&(k, l)| l * f(pts[k as usize])).sum()
    }

    #[test]
    fn fit_reproduces_a_linear_field() {
        let pts = [
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.1),
            DVec2::new(0.2, 0.9),
            DVec2::new(-0.7, 0.3),
            DVec2::new(0.4, -0.8),
        ];
        let cands: Vec<u32> = (0..pts.len() as u32).collect();
        let f = |p: DVec2| 3.0 - 2.0 * p.x + 0.5 * p.y;
        let x = DVec2::new(0.3, 0.2);
        let mut w = Vec::new();
        assert!(fit::<3>(x, &cands, &pts, &mut w));
        let got = apply(&w, &pts, f);
        assert!((got - f(x)).abs() < 1e-12, "{got} vs {}", f(x));
        let total: f64 = w.iter().map(|e| e.1).sum();
        assert!((total - 1.0).abs() < 1e-12);
    }

    #[test]
    fn quadratic_fit_reproduces_a_quadratic_field() {
        let pts: Vec<DVec2> = (0..9)
            .map(|i| {
                let a = i as f64 * 0.7;
                DVec2::new(a.cos(), a.sin()) * (0.3 + 0.08 * i as f64)
            })
            .collect();
        let cands: Vec<u32> = (0..pts.len() as u32).collect();
        let f =
            |p: DVec2| 1.0 + p.x - 2.0 * p.y + 0.7 * p.x * p.x - 0.4 * p.x * p.y + 1.3 * p.y * p.y;
        let x = DVec2::new(0.1, -0.2);
        let mut w = Vec::new();
        assert!(fit::<6>(x, &cands, &pts, &mut w));
        let got = apply(&w, &pts, f);
        assert!((got - f(x)).abs() < 1e-11, "{got} vs {}", f(x));
    }

    #[test]
    fn fit_refuses_collinear_points() {
        let pts = [
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(2.0, 0.0),
        ];
        let mut w = Vec::new();
        assert!(!fit::<3>(DVec2::new(0.5, 0.5), &[0, 1, 2], &pts, &mut w));
        assert!(w.is_empty());
    }
}
