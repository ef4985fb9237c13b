use glam::{DVec2, DVec3};

use super::Plane;

/// An orthonormal 2-D coordinate frame on a plane: `u × v = n`, so counter-clockwise in the
/// frame is counter-clockwise seen from the plane's front.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    pub origin: DVec3,
    pub u: DVec3,
    pub v: DVec3,
    pub n: DVec3,
}

impl Frame {
    pub fn new(origin: DVec3, n: DVec3) -> Self {
        let n = n.normalize();
        // The axis least aligned with n gives the best-conditioned tangent.
        let a = if n.x.abs() <= n.y.abs() && n.x.abs() <= n.z.abs() {
            DVec3::X
        } else if n.y.abs() <= n.z.abs() {
            DVec3::Y
        } else {
            DVec3::Z
        };
        let u = a.cross(n).normalize();
        let v = n.cross(u);
        Frame { origin, u, v, n }
    }

    pub fn on_plane(plane: &Plane, origin_hint: DVec3) -> Self {
        let o = origin_hint - plane.n * plane.dist(origin_hint);
        Frame::new(o, plane.n)
    }

    #[inline]
    pub fn to_2d(&self, p: DVec3) -> DVec2 {
        let r = p - self.origin;
        DVec2::new(r.dot(self.u), r.dot(self.v))
    }

    #[inline]
    pub fn to_3d(&self, q: DVec2) -> DVec3 {
        self.origin + self.u * q.x + self.v * q.y
    }
}

#[cfg(test)]
mod test {
    use super::*;

    #[test]
    fn roundtrip_and_handedness() {
        for n in [
            DVec3::Z,
            -DVec3::Z,
            DVec3::new(1., 2., 3.),
            DVec3::new(-1e-9, 1.0, 0.0),
        ] {
            let f = Frame::new(DVec3::new(1., 2., 3.), n);
            assert!((f.u.cross(f.v) - f.n).length() < 1e-12);
            let p = f.to_3d(DVec2::new(0.3, -0.7));
            assert!((f.to_2d(p) - DVec2::new(0.3, -0.7)).length() < 1e-12);
        }
    }
}
