use glam::DVec3;

/// An oriented plane `n·x = d` with unit normal `n`. The positive side is where `n` points.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plane {
    pub n: DVec3,
    pub d: f64,
}

impl Plane {
    pub fn new(n: DVec3, d: f64) -> Self {
        Plane { n, d }
    }

    /// Plane through `p` with normal `n` (normalised here; `n` must be non-zero).
    pub fn from_point_normal(p: DVec3, n: DVec3) -> Self {
        let n = n.normalize();
        Plane { n, d: n.dot(p) }
    }

    /// Best-fit plane of a polygon by Newell's method: robust for non-planar and
    /// nearly collinear input, and oriented so that counter-clockwise vertices face +n
    /// (Blender's rule). `None` when the polygon has no area.
    pub fn from_polygon(pts: &[DVec3]) -> Option<Self> {
        let n = newell_normal(pts);
        let len = n.length();
        if !(len > 0.0) || !len.is_finite() {
            return None;
        }
        let n = n / len;
        let c = pts.iter().copied().sum::<DVec3>() / pts.len() as f64;
        Some(Plane { n, d: n.dot(c) })
    }

    /// Signed distance (positive on the side `n` points to).
    #[inline]
    pub fn dist(&self, p: DVec3) -> f64 {
        self.n.dot(p) - self.d
    }

    pub fn flipped(&self) -> Self {
        Plane {
            n: -self.n,
            d: -self.d,
        }
    }
}

/// Twice the vector area of a polygon (Newell): its length is twice the area, its direction
/// the normal of the counter-clockwise side.
pub fn newell_normal(pts: &[DVec3]) -> DVec3 {
    let c = pts.iter().copied().sum::<DVec3>() / pts.len().max(1) as f64;
    let mut n = DVec3::ZERO;
    for i in 0..pts.len() {
        let a = pts[i] - c;
        let b = pts[(i + 1) % pts.len()] - c;
        n += a.cross(b);
    }
    n
}

#[cfg(test)]
mod test {
    use super::*;

    #[test]
    fn ccw_square_faces_up() {
        let sq = [
            DVec3::new(0., 0., 1.),
            DVec3::new(1., 0., 1.),
            DVec3::new(1., 1., 1.),
            DVec3::new(0., 1., 1.),
        ];
        let p = Plane::from_polygon(&sq).unwrap();
        assert!((p.n - DVec3::Z).length() < 1e-15);
        assert!((p.d - 1.0).abs() < 1e-15);
        assert!((newell_normal(&sq).length() - 2.0).abs() < 1e-15);
    }

    #[test]
    fn degenerate_has_no_plane() {
        let line = [DVec3::ZERO, DVec3::X, DVec3::X * 2.0];
        assert!(Plane::from_polygon(&line).is_none());
    }
}
