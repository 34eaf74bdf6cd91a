//! Rays and the analytic shapes: spheres and infinite planes, plus the
//! triangle test and the ray offset that keeps a new ray off the surface it
//! leaves.

use glam::DVec3;

/// A ray `origin + t dir`, `dir` unit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ray {
    pub origin: DVec3,
    pub dir: DVec3,
}

impl Ray {
    #[inline]
    #[must_use]
    pub fn at(&self, t: f64) -> DVec3 {
        self.origin + self.dir * t
    }
}

/// Where a ray meets a surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Ray parameter of the hit.
    pub t: f64,
    /// The hit point.
    pub p: DVec3,
    /// Unit geometric normal (the shape's own orientation, not yet turned
    /// toward the ray).
    pub ng: DVec3,
    /// Unit shading normal, on the same side as `ng` (equal to it except
    /// on meshes with vertex normals).
    pub ns: DVec3,
}

/// The relative size of the offset that moves a ray's origin off the
/// surface it starts on: `RAY_EPSILON · (1 + max |p_i|)` along the
/// geometric normal. The hit points are computed in f64 and re-projected on
/// spheres, so their error is a few ulps of the coordinates, far below it.
pub const RAY_EPSILON: f64 = 1e-7;

/// A ray leaving `p` in direction `dir`, its origin pushed off the surface
/// along the geometric normal `ng`, to the side `dir` points to.
#[inline]
#[must_use]
pub fn spawn_ray(p: DVec3, ng: DVec3, dir: DVec3) -> Ray {
    let eps = RAY_EPSILON * (1.0 + p.abs().max_element());
    let side = if dir.dot(ng) >= 0.0 { eps } else { -eps };
    Ray {
        origin: p + ng * side,
        dir,
    }
}

/// A sphere.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sphere {
    pub center: DVec3,
    pub radius: f64,
}

impl Sphere {
    /// The nearest hit with `t` in `(0, t_max)`.
    #[inline]
    #[must_use]
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<Hit> {
        let t = self.nearest_t(ray, t_max)?;
        let n = (ray.at(t) - self.center) / self.radius;
        let n = n.try_normalize()?;
        Some(Hit {
            t,
            p: self.center + n * self.radius,
            ng: n,
            ns: n,
        })
    }

    /// Whether the sphere blocks `ray` before `t_max`: a root `t` in
    /// `(0, t_max)`, as [`Sphere::intersect`] finds it, without the normal
    /// at the hit (which a shadow ray does not need; where it cannot be
    /// normalized, a point within rounding of the centre of a sphere far
    /// smaller than its distance, `intersect` has no hit and this blocks).
    #[inline]
    #[must_use]
    pub fn blocks(&self, ray: &Ray, t_max: f64) -> bool {
        self.nearest_t(ray, t_max).is_some()
    }

    /// The nearest root `t` of the ray's equation in `(0, t_max)`.
    #[inline]
    fn nearest_t(&self, ray: &Ray, t_max: f64) -> Option<f64> {
        let oc = ray.origin - self.center;
        let b = oc.dot(ray.dir);
        // The discriminant from the distance of the center to the line,
        // which keeps its precision for rays that start far away.
        let perp = oc - ray.dir * b;
        let r2 = self.radius * self.radius;
        let disc = r2 - perp.length_squared();
        if disc < 0.0 {
            return None;
        }
        let c = oc.length_squared() - r2;
        // Roots of t² + 2bt + c: q = -(b + sign(b) √disc), t = q and c / q.
        let q = -(b + disc.sqrt().copysign(b));
        let (mut t0, mut t1) = if q != 0.0 { (c / q, q) } else { (0.0, 0.0) };
        if t0 > t1 {
            std::mem::swap(&mut t0, &mut t1);
        }
        let t = if t0 > 0.0 {
            t0
        } else if t1 > 0.0 {
            t1
        } else {
            return None;
        };
        (t < t_max && t.is_finite()).then_some(t)
    }
}

/// An infinite plane through `point` with unit `normal`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plane {
    pub point: DVec3,
    pub normal: DVec3,
}

impl Plane {
    #[inline]
    #[must_use]
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<Hit> {
        let denom = ray.dir.dot(self.normal);
        if denom == 0.0 {
            return None;
        }
        let t = (self.point - ray.origin).dot(self.normal) / denom;
        if !(t > 0.0 && t < t_max) {
            return None;
        }
        // Project the point back onto the plane.
        let p = ray.at(t);
        let p = p - self.normal * (p - self.point).dot(self.normal);
        Some(Hit {
            t,
            p,
            ng: self.normal,
            ns: self.normal,
        })
    }
}

/// Ray–triangle test (the determinant form of Möller and Trumbore's
/// algorithm): `(t, b1, b2)` with barycentrics `b1`, `b2` of `v1`, `v2`.
#[inline]
#[must_use]
pub fn intersect_triangle(
    ray: &Ray,
    v0: DVec3,
    v1: DVec3,
    v2: DVec3,
    t_max: f64,
) -> Option<(f64, f64, f64)> {
    let e1 = v1 - v0;
    let e2 = v2 - v0;
    let pv = ray.dir.cross(e2);
    let det = e1.dot(pv);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let inv = 1.0 / det;
    let tv = ray.origin - v0;
    let b1 = tv.dot(pv) * inv;
    if !(0.0..=1.0).contains(&b1) {
        return None;
    }
    let qv = tv.cross(e1);
    let b2 = ray.dir.dot(qv) * inv;
    if b2 < 0.0 || b1 + b2 > 1.0 {
        return None;
    }
    let t = e2.dot(qv) * inv;
    (t > 0.0 && t < t_max).then_some((t, b1, b2))
}

/// An axis-aligned box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    pub min: DVec3,
    pub max: DVec3,
}

impl Aabb {
    pub const EMPTY: Aabb = Aabb {
        min: DVec3::splat(f64::INFINITY),
        max: DVec3::splat(f64::NEG_INFINITY),
    };

    #[inline]
    #[must_use]
    pub fn union(self, o: Aabb) -> Aabb {
        Aabb {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }

    #[inline]
    #[must_use]
    pub fn grow(self, p: DVec3) -> Aabb {
        Aabb {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    #[inline]
    #[must_use]
    pub fn centroid(&self) -> DVec3 {
        0.5 * (self.min + self.max)
    }

    /// Half the surface area (the SAH only needs ratios).
    #[inline]
    #[must_use]
    pub fn half_area(&self) -> f64 {
        let d = self.max - self.min;
        if d.min_element() < 0.0 {
            0.0
        } else {
            d.x * d.y + d.y * d.z + d.z * d.x
        }
    }

    /// The entry distance of the ray into the box when it enters before
    /// `t_max`, from the ray's precomputed reciprocal direction.
    #[inline]
    #[must_use]
    pub fn hit(&self, origin: DVec3, inv_dir: DVec3, t_max: f64) -> Option<f64> {
        let t0 = (self.min - origin) * inv_dir;
        let t1 = (self.max - origin) * inv_dir;
        // f64::min/max skip the NaN of 0·∞ (a ray in the plane of a face).
        let near = t0.min(t1);
        let far = t0.max(t1);
        let t_near = near.x.max(near.y).max(near.z).max(0.0);
        // Widen the far end by a few ulps so that a ray grazing a box that
        // has zero width on one axis (an axis-aligned triangle) still enters.
        let t_far = far.x.min(far.y).min(far.z).min(t_max) * (1.0 + 4.0 * f64::EPSILON);
        (t_near <= t_far).then_some(t_near)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A shadow ray's test finds what the hit does: random rays from
    /// outside, inside and on the sphere, any `t_max`.
    #[test]
    fn sphere_blocks_where_it_is_hit() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(11);
        let s = Sphere {
            center: DVec3::new(0.3, -0.2, 1.0),
            radius: 0.9,
        };
        let mut hits = 0;
        for k in 0..20_000 {
            let mut v = || DVec3::new(rng.random(), rng.random(), rng.random()) * 2.0 - 1.0;
            let origin = match k % 3 {
                0 => s.center + v() * 4.0,
                1 => s.center + v() * 0.5,
                _ => s.center + v().normalize() * s.radius,
            };
            let dir = v().normalize();
            let t_max = if k % 4 == 0 {
                f64::INFINITY
            } else {
                rng.random::<f64>() * 5.0
            };
            let ray = Ray { origin, dir };
            let hit = s.intersect(&ray, t_max).is_some();
            assert_eq!(s.blocks(&ray, t_max), hit, "{ray:?} t_max {t_max}");
            hits += usize::from(hit);
        }
        // Both outcomes, many times.
        assert!(hits > 3000 && hits < 17_000, "{hits}");
    }

    #[test]
    fn sphere_hits_from_outside_and_inside() {
        let s = Sphere {
            center: DVec3::new(0.0, 0.0, -5.0),
            radius: 1.0,
        };
        let r = Ray {
            origin: DVec3::ZERO,
            dir: -DVec3::Z,
        };
        let h = s.intersect(&r, f64::INFINITY).unwrap();
        assert!((h.t - 4.0).abs() < 1e-12);
        assert!((h.ng - DVec3::Z).length() < 1e-12);
        let inside = Ray {
            origin: s.center,
            dir: DVec3::X,
        };
        let h = s.intersect(&inside, f64::INFINITY).unwrap();
        assert!((h.t - 1.0).abs() < 1e-12);
        assert!(s.intersect(&r, 3.0).is_none());
        let away = Ray {
            origin: DVec3::ZERO,
            dir: DVec3::Z,
        };
        assert!(s.intersect(&away, f64::INFINITY).is_none());
    }

    #[test]
    fn rays_leaving_a_sphere_do_not_hit_it_again() {
        let s = Sphere {
            center: DVec3::new(0.3, 1.0, -2.0),
            radius: 1.0,
        };
        for k in 0..2000 {
            let a = k as f64 * 0.618_033_988_749;
            let b = k as f64 * 0.414_213_562_373;
            let n = DVec3::new(a.cos() * b.sin(), a.sin() * b.sin(), b.cos()).normalize();
            let p = s.center + n * s.radius;
            // A direction just above the tangent plane.
            let t = n.any_orthonormal_vector();
            let d = (t + n * 1e-9).normalize();
            let r = spawn_ray(p, n, d);
            assert!(s.intersect(&r, f64::INFINITY).is_none(), "{k}");
        }
    }

    #[test]
    fn plane_and_triangle() {
        let pl = Plane {
            point: DVec3::ZERO,
            normal: DVec3::Y,
        };
        let r = Ray {
            origin: DVec3::new(0.0, 2.0, 0.0),
            dir: DVec3::new(0.0, -1.0, 1.0).normalize(),
        };
        let h = pl.intersect(&r, f64::INFINITY).unwrap();
        assert!(h.p.y.abs() < 1e-15 && (h.p.z - 2.0).abs() < 1e-12);
        let (t, b1, b2) = intersect_triangle(
            &Ray {
                origin: DVec3::new(0.25, 0.25, 1.0),
                dir: -DVec3::Z,
            },
            DVec3::ZERO,
            DVec3::X,
            DVec3::Y,
            f64::INFINITY,
        )
        .unwrap();
        assert!((t - 1.0).abs() < 1e-12 && (b1 - 0.25).abs() < 1e-12 && (b2 - 0.25).abs() < 1e-12);
    }
}
