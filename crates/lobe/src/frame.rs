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

/// The view direction `wo` in the local frame at polar angle `theta_deg`
/// from the normal and azimuth `phi_deg`, both in degrees:
/// `(sin θ cos φ, sin θ sin φ, cos θ)`. With `phi_deg = 0` it is
/// `(sin θ, 0, cos θ)`, in the xz plane.
#[inline]
#[must_use]
pub fn wo_from_theta(theta_deg: f64, phi_deg: f64) -> DVec3 {
    spherical_direction(theta_deg.to_radians(), phi_deg.to_radians())
}

/// The unit direction with polar angle `theta` (from `+z`) and azimuth
/// `phi`, in radians: `(sin θ cos φ, sin θ sin φ, cos θ)`.
#[inline]
#[must_use]
pub fn spherical_direction(theta: f64, phi: f64) -> DVec3 {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    DVec3::new(st * cp, st * sp, ct)
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

    #[test]
    fn wo_from_theta_in_the_xz_plane() {
        let t = 30f64.to_radians();
        assert_eq!(wo_from_theta(30.0, 0.0), DVec3::new(t.sin(), 0.0, t.cos()));
        assert_eq!(wo_from_theta(0.0, 0.0), DVec3::Z);
        assert!((wo_from_theta(90.0, 90.0) - DVec3::Y).length() < 1e-15);
    }
}
