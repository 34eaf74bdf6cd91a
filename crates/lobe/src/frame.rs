//! Orthonormal frames: the local shading frame has `+z` along the normal.

use glam::DVec3;

/// An orthonormal basis `(s, t, n)`; `to_local` maps `n` to `+z`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    pub s: DVec3,
    pub t: DVec3,
    pub n: DVec3,
}

impl Frame {
    /// A frame around the unit normal `n`, with a tangent chosen without
    /// branches on `n` (Duff et al. 2017, "Building an orthonormal basis,
    /// revisited").
    #[must_use]
    pub fn from_normal(n: DVec3) -> Self {
        debug_assert!(crate::math::is_unit(n), "normal {n} is not a unit vector");
        let sign = 1.0f64.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let s = DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let t = DVec3::new(b, sign + n.y * n.y * a, -n.y);
        Frame { s, t, n }
    }

    /// A frame with `n` the normal and `s` the projection of `tangent` onto
    /// the plane of `n`: local x = tangent, local z = normal,
    /// local y = normal × tangent. Returns `None` when the tangent is
    /// parallel to the normal.
    #[must_use]
    pub fn from_normal_tangent(n: DVec3, tangent: DVec3) -> Option<Self> {
        let n = n.try_normalize()?;
        let s = (tangent - n * n.dot(tangent)).try_normalize()?;
        Some(Frame {
            s,
            t: n.cross(s),
            n,
        })
    }

    #[inline]
    #[must_use]
    pub fn to_local(&self, w: DVec3) -> DVec3 {
        DVec3::new(w.dot(self.s), w.dot(self.t), w.dot(self.n))
    }

    #[inline]
    #[must_use]
    pub fn to_world(&self, w: DVec3) -> DVec3 {
        self.s * w.x + self.t * w.y + self.n * w.z
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_orthonormal_and_round_trip() {
        for &n in &[
            DVec3::Z,
            -DVec3::Z,
            DVec3::X,
            DVec3::new(0.3, -0.4, 0.5).normalize(),
            DVec3::new(-1e-9, 0.0, -1.0).normalize(),
        ] {
            let f = Frame::from_normal(n);
            assert!((f.s.dot(f.t)).abs() < 1e-12);
            assert!((f.s.dot(f.n)).abs() < 1e-12);
            assert!(
                (f.s.cross(f.t) - f.n).length() < 1e-12,
                "right-handed for {n}"
            );
            let w = DVec3::new(0.1, 0.7, -0.2).normalize();
            assert!((f.to_world(f.to_local(w)) - w).length() < 1e-12);
            assert!((f.to_local(n) - DVec3::Z).length() < 1e-12);
        }
        let f = Frame::from_normal_tangent(DVec3::Y, DVec3::X).unwrap();
        assert!((f.to_local(DVec3::X) - DVec3::X).length() < 1e-12);
        assert!((f.to_local(DVec3::Y) - DVec3::Z).length() < 1e-12);
        assert!((f.to_world(DVec3::Y) - DVec3::Y.cross(DVec3::X)).length() < 1e-12);
        assert!(Frame::from_normal_tangent(DVec3::Y, DVec3::Y).is_none());
    }
}
