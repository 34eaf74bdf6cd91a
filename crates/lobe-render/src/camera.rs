//! A pinhole camera.

use crate::geometry::Ray;
use glam::DVec3;

/// Largest accepted image width or height.
pub const MAX_SIZE: u32 = 16384;

/// A pinhole camera looking from `origin` toward `target`.
///
/// Film coordinates are in pixels: `(0, 0)` is the top-left corner of the
/// image, `x` grows to the right and `y` downward, so pixel `(i, j)` covers
/// `[i, i+1) × [j, j+1)`. A point to the camera's right (along
/// `forward × up`) appears on the right of the image, a point above it at
/// the top: the image is not mirrored.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    pub origin: DVec3,
    /// Unit view direction.
    pub forward: DVec3,
    /// Unit vector to the image's right.
    pub right: DVec3,
    /// Unit vector to the image's top.
    pub up: DVec3,
    /// Vertical field of view, degrees.
    pub fov_y: f64,
    pub width: u32,
    pub height: u32,
    pub(crate) tan_half: f64,
}

/// A camera parameter that cannot be used: the field and why.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{field}: {message}")]
pub struct CameraError {
    pub field: &'static str,
    pub message: String,
}

fn bad(field: &'static str, message: impl Into<String>) -> CameraError {
    CameraError {
        field,
        message: message.into(),
    }
}

impl Camera {
    /// A camera at `origin` looking at `target`, with `up` the approximate
    /// up direction, `fov_y` the vertical field of view in degrees (in
    /// (0, 180)) and an image of `width × height` pixels (1 to
    /// [`MAX_SIZE`] each).
    pub fn new(
        origin: DVec3,
        target: DVec3,
        up: DVec3,
        fov_y: f64,
        width: u32,
        height: u32,
    ) -> Result<Camera, CameraError> {
        for (field, v) in [("origin", origin), ("target", target), ("up", up)] {
            if !v.is_finite() {
                return Err(bad(field, format!("{v} is not a finite vector")));
            }
        }
        if !(fov_y > 0.0 && fov_y < 180.0) {
            return Err(bad(
                "fov_y",
                format!(
                    "{fov_y} is out of range: the vertical field of view must be in (0, 180) degrees"
                ),
            ));
        }
        for (field, v) in [("width", width), ("height", height)] {
            if v == 0 || v > MAX_SIZE {
                return Err(bad(
                    field,
                    format!("{v} is out of range: must be 1 to {MAX_SIZE} pixels"),
                ));
            }
        }
        let forward = (target - origin)
            .try_normalize()
            .ok_or_else(|| bad("target", "equals origin: the camera has no view direction"))?;
        let right = forward.cross(up).try_normalize().ok_or_else(|| {
            bad(
                "up",
                format!("{up} is zero or parallel to the view direction {forward}"),
            )
        })?;
        let up = right.cross(forward);
        Ok(Camera {
            origin,
            forward,
            right,
            up,
            fov_y,
            width,
            height,
            tan_half: (0.5 * fov_y.to_radians()).tan(),
        })
    }

    /// The ray through film position `(x, y)` in pixels (see [`Camera`]).
    #[inline]
    #[must_use]
    pub fn ray(&self, x: f64, y: f64) -> Ray {
        let (w, h) = (f64::from(self.width), f64::from(self.height));
        let sy = (1.0 - 2.0 * y / h) * self.tan_half;
        let sx = (2.0 * x / w - 1.0) * self.tan_half * (w / h);
        Ray {
            origin: self.origin,
            dir: (self.forward + self.right * sx + self.up * sy).normalize(),
        }
    }

    /// The film position `(x, y)` in pixels where the world point `p` is
    /// seen, or `None` when it is behind the camera.
    #[must_use]
    pub fn project(&self, p: DVec3) -> Option<(f64, f64)> {
        let d = p - self.origin;
        let z = d.dot(self.forward);
        if z <= 0.0 {
            return None;
        }
        let (w, h) = (f64::from(self.width), f64::from(self.height));
        let sx = d.dot(self.right) / z / (self.tan_half * (w / h));
        let sy = d.dot(self.up) / z / self.tan_half;
        Some((0.5 * (sx + 1.0) * w, 0.5 * (1.0 - sy) * h))
    }

    /// A film-space box `[x0, x1, y0, y1]` (pixels) outside of which no
    /// camera ray meets the axis-aligned box `lo..=hi`: the bounds of its
    /// eight corners' projections (the projection of a convex box is the
    /// hull of its corners'), widened by a pixel; `None` when a corner is
    /// not in front of the camera ([`Camera::project`] refuses it) or
    /// projects beyond the floats (no such bound).
    #[must_use]
    pub fn film_bounds(&self, lo: DVec3, hi: DVec3) -> Option<[f64; 4]> {
        let mut b = [
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        for k in 0..8 {
            let c = DVec3::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            );
            let (x, y) = self.project(c)?;
            b = [b[0].min(x), b[1].max(x), b[2].min(y), b[3].max(y)];
        }
        b.iter()
            .all(|v| v.is_finite())
            .then(|| [b[0] - 1.0, b[1] + 1.0, b[2] - 1.0, b[3] + 1.0])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Sphere;

    #[test]
    fn film_bounds_hold_every_ray_that_meets_the_sphere() {
        let cam = Camera::new(
            DVec3::new(0.3, 1.0, 5.5),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::Y,
            36.0,
            160,
            120,
        )
        .unwrap();
        for (center, radius) in [
            (DVec3::new(-1.05, 1.0, 0.0), 0.9),
            (DVec3::new(1.6, 0.2, 3.0), 0.5),
            (DVec3::new(0.0, 1.0, 4.0), 1.0),
        ] {
            let s = Sphere { center, radius };
            let r = DVec3::splat(radius);
            let b = cam.film_bounds(center - r, center + r).expect("in front");
            // The benchmark's sphere: a box well inside the film.
            if radius == 0.9 {
                assert!(b[1] - b[0] < 80.0 && b[3] - b[2] < 80.0, "{b:?}");
            }
            let (mut inside, mut outside) = (0, 0);
            for j in 0..600 {
                for i in 0..800 {
                    let (x, y) = (i as f64 * 0.2, j as f64 * 0.2);
                    if s.intersect(&cam.ray(x, y), f64::INFINITY).is_none() {
                        continue;
                    }
                    if (b[0]..=b[1]).contains(&x) && (b[2]..=b[3]).contains(&y) {
                        inside += 1;
                    } else {
                        outside += 1;
                    }
                }
            }
            assert!(inside > 100, "{center}: {inside} hits");
            assert_eq!(outside, 0, "{center}: hits outside {b:?}");
        }
        // Around or behind the camera: no bound.
        let o = cam.origin;
        assert_eq!(cam.film_bounds(o - 1.0, o + 1.0), None);
        assert_eq!(
            cam.film_bounds(o + DVec3::new(0.0, 0.0, 1.0), o + 2.0),
            None
        );
    }

    #[test]
    fn right_is_right_and_up_is_up() {
        let c = Camera::new(
            DVec3::new(0.0, 1.0, 4.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::Y,
            40.0,
            320,
            240,
        )
        .unwrap();
        // Looking down -Z with +Y up: +X is on the right.
        assert!((c.right - DVec3::X).length() < 1e-12);
        let r = c.ray(320.0, 0.0);
        assert!(r.dir.x > 0.0 && r.dir.y > 0.0);
        let (x, y) = c.project(DVec3::new(1.0, 1.5, 0.0)).unwrap();
        assert!(x > 160.0 && y < 120.0);
        let back = c.ray(x, y);
        let want = (DVec3::new(1.0, 1.5, 0.0) - c.origin).normalize();
        assert!((back.dir - want).length() < 1e-12);
        assert!(Camera::new(DVec3::ZERO, DVec3::Y, DVec3::Y, 40.0, 1, 1).is_err());
        assert!(Camera::new(DVec3::ZERO, DVec3::X, DVec3::Y, 180.0, 1, 1).is_err());
        assert!(Camera::new(DVec3::ZERO, DVec3::X, DVec3::Y, 40.0, 0, 1).is_err());
    }
}
