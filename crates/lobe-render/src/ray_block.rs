//! Rays in blocks, structure of arrays: camera rays, nearest hits, shadow
//! tests and ray offsets of many rays per call, for the batch loop.
//!
//! Each step is a plain loop over `f64` arrays with selects instead of
//! branches, run inside a `#[target_feature]` function of the SIMD level
//! ([`SimdLevel::run`]; AVX2: 4 lanes, AVX-512: 8), where the compiler vectorizes it. A lane
//! computes exactly what the scalar functions ([`Camera::ray`],
//! [`Sphere::intersect`], [`Plane::intersect`], [`spawn_ray`],
//! [`Scene::intersect`], [`Scene::occluded`]) compute, in the same order of
//! IEEE operations (no fused multiply-adds: Rust does not contract them),
//! so the results are the same bits; the tests below check it at every
//! level the CPU runs. Meshes are traced one ray at a time by their BVH.

use crate::camera::Camera;
#[cfg(doc)]
use crate::geometry::spawn_ray;
use crate::geometry::{Plane, RAY_EPSILON, Ray, Sphere};
use crate::scene::{Scene, Shape};
use glam::DVec3;
use lobe::batch::{SimdLevel, Step};

/// No object: [`HitBlock::obj`] of a ray that hits nothing.
pub const NO_HIT: u32 = u32::MAX;

/// Three coordinate arrays.
#[derive(Debug, Clone, Default)]
pub struct Vec3Block {
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    pub z: Vec<f64>,
}

impl Vec3Block {
    pub fn clear(&mut self) {
        self.x.clear();
        self.y.clear();
        self.z.clear();
    }

    pub fn push(&mut self, v: DVec3) {
        self.x.push(v.x);
        self.y.push(v.y);
        self.z.push(v.z);
    }

    /// The first `n` entries kept.
    pub fn truncate(&mut self, n: usize) {
        self.x.truncate(n);
        self.y.truncate(n);
        self.z.truncate(n);
    }

    /// `n` entries (zeros where new).
    pub fn resize(&mut self, n: usize) {
        self.x.resize(n, 0.0);
        self.y.resize(n, 0.0);
        self.z.resize(n, 0.0);
    }

    #[must_use]
    pub fn len(&self) -> usize {
        self.x.len()
    }

    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    #[inline]
    #[must_use]
    pub fn get(&self, i: usize) -> DVec3 {
        DVec3::new(self.x[i], self.y[i], self.z[i])
    }

    #[inline]
    pub fn set(&mut self, i: usize, v: DVec3) {
        self.x[i] = v.x;
        self.y[i] = v.y;
        self.z[i] = v.z;
    }

    /// The first `n` entries as three slices borrowed once, for a loop:
    /// it keeps their addresses in registers instead of reading the
    /// vectors' again after every store.
    ///
    /// # Panics
    /// If there are fewer than `n` entries.
    #[inline]
    #[must_use]
    pub fn view(&self, n: usize) -> Vec3View<'_> {
        Vec3View {
            x: &self.x[..n],
            y: &self.y[..n],
            z: &self.z[..n],
        }
    }

    /// [`Vec3Block::view`] to write.
    ///
    /// # Panics
    /// If there are fewer than `n` entries.
    #[inline]
    pub fn view_mut(&mut self, n: usize) -> Vec3ViewMut<'_> {
        Vec3ViewMut {
            x: &mut self.x[..n],
            y: &mut self.y[..n],
            z: &mut self.z[..n],
        }
    }
}

/// Read access to the first entries of a [`Vec3Block`] ([`Vec3Block::view`]).
#[derive(Debug, Clone, Copy)]
pub struct Vec3View<'a> {
    x: &'a [f64],
    y: &'a [f64],
    z: &'a [f64],
}

impl Vec3View<'_> {
    #[inline]
    #[must_use]
    pub fn get(&self, i: usize) -> DVec3 {
        DVec3::new(self.x[i], self.y[i], self.z[i])
    }
}

/// Write access to the first entries of a [`Vec3Block`]
/// ([`Vec3Block::view_mut`]).
#[derive(Debug)]
pub struct Vec3ViewMut<'a> {
    x: &'a mut [f64],
    y: &'a mut [f64],
    z: &'a mut [f64],
}

impl Vec3ViewMut<'_> {
    #[inline]
    pub fn set(&mut self, i: usize, v: DVec3) {
        self.x[i] = v.x;
        self.y[i] = v.y;
        self.z[i] = v.z;
    }
}

/// A block of rays `origin + t dir`, `dir` unit.
#[derive(Debug, Clone, Default)]
pub struct RayBlock {
    pub origin: Vec3Block,
    pub dir: Vec3Block,
}

impl RayBlock {
    pub fn clear(&mut self) {
        self.origin.clear();
        self.dir.clear();
    }

    pub fn push(&mut self, r: &Ray) {
        self.origin.push(r.origin);
        self.dir.push(r.dir);
    }

    #[must_use]
    pub fn len(&self) -> usize {
        self.dir.len()
    }

    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.dir.is_empty()
    }

    #[must_use]
    pub fn get(&self, i: usize) -> Ray {
        Ray {
            origin: self.origin.get(i),
            dir: self.dir.get(i),
        }
    }

    /// `n` rays (zeros where new).
    pub fn resize(&mut self, n: usize) {
        self.origin.resize(n);
        self.dir.resize(n);
    }
}

/// The nearest hits of a block of rays ([`Scene::intersect_many`]): per
/// ray the fields of [`crate::Hit`] and the object, [`NO_HIT`] for a miss
/// (its other fields are then unspecified).
#[derive(Debug, Clone, Default)]
pub struct HitBlock {
    pub t: Vec<f64>,
    pub obj: Vec<u32>,
    pub p: Vec3Block,
    pub ng: Vec3Block,
    pub ns: Vec3Block,
}

impl HitBlock {
    fn resize(&mut self, n: usize) {
        self.t.resize(n, 0.0);
        self.obj.resize(n, NO_HIT);
        self.p.resize(n);
        self.ng.resize(n);
        self.ns.resize(n);
    }
}

/// `a · b` as glam's `DVec3::dot` computes it.
#[inline(always)]
fn dot(ax: f64, ay: f64, az: f64, bx: f64, by: f64, bz: f64) -> f64 {
    (ax * bx) + (ay * by) + (az * bz)
}

impl Camera {
    /// [`Camera::ray`] of film positions `(xs[i], ys[i])`, into `out`
    /// (resized to their number), the same bits.
    ///
    /// # Panics
    /// If `xs` and `ys` differ in length.
    pub fn rays_many(&self, level: SimdLevel, xs: &[f64], ys: &[f64], out: &mut RayBlock) {
        assert_eq!(xs.len(), ys.len(), "rays_many: lengths differ");
        out.resize(xs.len());
        level.run(CameraRays(self, xs, ys, out));
    }
}

/// [`Camera::rays_many`]'s loop.
struct CameraRays<'a>(&'a Camera, &'a [f64], &'a [f64], &'a mut RayBlock);

impl Step for CameraRays<'_> {
    #[inline(always)]
    fn run(self) {
        let CameraRays(cam, xs, ys, out) = self;
        let (w, h) = (f64::from(cam.width), f64::from(cam.height));
        let (f, r, u, o) = (cam.forward, cam.right, cam.up, cam.origin);
        let th = cam.tan_half;
        let d = &mut out.dir;
        let n = xs.len();
        let (dx, dy, dz) = (&mut d.x[..n], &mut d.y[..n], &mut d.z[..n]);
        for i in 0..n {
            let sy = (1.0 - 2.0 * ys[i] / h) * th;
            let sx = (2.0 * xs[i] / w - 1.0) * th * (w / h);
            let vx = f.x + r.x * sx + u.x * sy;
            let vy = f.y + r.y * sx + u.y * sy;
            let vz = f.z + r.z * sx + u.z * sy;
            let k = 1.0 / dot(vx, vy, vz, vx, vy, vz).sqrt();
            dx[i] = vx * k;
            dy[i] = vy * k;
            dz[i] = vz * k;
        }
        let og = &mut out.origin;
        og.x[..n].fill(o.x);
        og.y[..n].fill(o.y);
        og.z[..n].fill(o.z);
    }
}

/// RowBlock of a chunk of [`sphere_chunk`].
const CHUNK: usize = 8;

/// A sphere's hits of the rays `start..start + m` (`m ≤ CHUNK`, its rays
/// count): per lane `t` (infinite when none) and the unit normal
/// (unspecified when none), as [`Sphere::intersect`] with `t_max = ∞`
/// finds them; without `NORMALS`, `t` alone as [`Sphere::blocks`] finds it
/// (the normals zero). The steps that only a hit needs (the root, then the
/// normal) are skipped for a chunk where no lane gets that far, as the
/// scalar test returns early. Inlined into each caller's loop over the
/// chunks, so that it is compiled for the caller's SIMD level.
#[inline(always)]
fn sphere_chunk<const NORMALS: bool>(
    s: &Sphere,
    rays: &RayBlock,
    start: usize,
    m: usize,
) -> ([f64; CHUNK], [[f64; CHUNK]; 3]) {
    let (c, r) = (s.center, s.radius);
    let r2 = r * r;
    let (og, dg) = (&rays.origin, &rays.dir);
    // The chunk's rays; a short chunk's other lanes are zeros.
    let mut o = [[0.0; CHUNK]; 3];
    let mut d = [[0.0; CHUNK]; 3];
    for (src, dst) in [&og.x, &og.y, &og.z, &dg.x, &dg.y, &dg.z]
        .into_iter()
        .zip(o.iter_mut().chain(d.iter_mut()))
    {
        if m == CHUNK {
            // A fixed-size copy (vector moves, not a call to memcpy).
            dst.copy_from_slice(&src[start..start + CHUNK]);
        } else {
            dst[..m].copy_from_slice(&src[start..start + m]);
        }
    }
    let mut t = [f64::INFINITY; CHUNK];
    let mut nrm = [[0.0; CHUNK]; 3];
    let (mut b, mut disc, mut cc) = ([0.0; CHUNK], [0.0; CHUNK], [0.0; CHUNK]);
    let mut any = false;
    for l in 0..CHUNK {
        let (ocx, ocy, ocz) = (o[0][l] - c.x, o[1][l] - c.y, o[2][l] - c.z);
        b[l] = dot(ocx, ocy, ocz, d[0][l], d[1][l], d[2][l]);
        let (px, py, pz) = (
            ocx - d[0][l] * b[l],
            ocy - d[1][l] * b[l],
            ocz - d[2][l] * b[l],
        );
        disc[l] = r2 - dot(px, py, pz, px, py, pz);
        cc[l] = dot(ocx, ocy, ocz, ocx, ocy, ocz) - r2;
        // A ray that starts outside (or on) the sphere and does not go
        // toward its centre (`c ≥ 0`, `b ≥ 0`: both roots ≤ 0 below, so no
        // hit) needs no roots: a shadow ray leaving the sphere it starts
        // on, which is every shadow ray's test against its own sphere.
        let away = (b[l] >= 0.0) & (cc[l] >= 0.0);
        any |= (l < m) & (disc[l] >= 0.0) & !away;
    }
    if any {
        // Roots of t² + 2bt + c: q = −(b + sign(b) √disc), t = q and c / q.
        any = false;
        for l in 0..CHUNK {
            let q = -(b[l] + disc[l].sqrt().copysign(b[l]));
            let nz = q != 0.0;
            let t0 = if nz { cc[l] / q } else { 0.0 };
            let t1 = if nz { q } else { 0.0 };
            let (lo, hi) = if t0 > t1 { (t1, t0) } else { (t0, t1) };
            let tl = if lo > 0.0 { lo } else { hi };
            // `disc < 0` gave NaN above.
            let ok = disc[l] >= 0.0 && tl > 0.0 && tl.is_finite();
            t[l] = if ok { tl } else { f64::INFINITY };
            any |= (l < m) & ok;
        }
    }
    if NORMALS && any {
        // The normal at `o + t d`, normalized as `try_normalize`: a
        // hit only where that succeeds.
        for l in 0..CHUNK {
            let tl = t[l];
            let nx = (o[0][l] + d[0][l] * tl - c.x) / r;
            let ny = (o[1][l] + d[1][l] * tl - c.y) / r;
            let nz = (o[2][l] + d[2][l] * tl - c.z) / r;
            let rcp = 1.0 / dot(nx, ny, nz, nx, ny, nz).sqrt();
            let ok = rcp.is_finite() && rcp > 0.0;
            t[l] = if ok { tl } else { f64::INFINITY };
            nrm[0][l] = nx * rcp;
            nrm[1][l] = ny * rcp;
            nrm[2][l] = nz * rcp;
        }
    }
    (t, nrm)
}

/// A plane's candidate hit in one lane: `t` (infinite when none) and the
/// point, as [`Plane::intersect`] with `t_max = ∞` finds them.
#[inline(always)]
fn plane_lane(pl: &Plane, o: [f64; 3], d: [f64; 3]) -> (f64, [f64; 3]) {
    let (n, q) = (pl.normal, pl.point);
    let denom = dot(d[0], d[1], d[2], n.x, n.y, n.z);
    let t = dot(q.x - o[0], q.y - o[1], q.z - o[2], n.x, n.y, n.z) / denom;
    let ok = denom != 0.0 && t > 0.0 && t < f64::INFINITY;
    let (px, py, pz) = (o[0] + d[0] * t, o[1] + d[1] * t, o[2] + d[2] * t);
    let k = dot(px - q.x, py - q.y, pz - q.z, n.x, n.y, n.z);
    (
        if ok { t } else { f64::INFINITY },
        [px - n.x * k, py - n.y * k, pz - n.z * k],
    )
}

impl Scene {
    /// [`Scene::intersect`] of every ray of `rays` with `t_max = ∞`, into
    /// `out` (resized to their number): the same hits, bit for bit.
    pub fn intersect_many(&self, level: SimdLevel, rays: &RayBlock, out: &mut HitBlock) {
        self.intersect_many_where(level, rays, out, |_| true);
    }

    /// [`Scene::intersect_many`] with the objects `k` for which `may_hit(k)`
    /// is false left out: the same hits when no ray meets those (a caller
    /// that knows where the rays go, such as a block of camera rays and
    /// [`crate::camera::Camera::film_bounds`]).
    pub fn intersect_many_where(
        &self,
        level: SimdLevel,
        rays: &RayBlock,
        out: &mut HitBlock,
        may_hit: impl Fn(usize) -> bool,
    ) {
        let n = rays.len();
        out.resize(n);
        out.t[..n].fill(f64::INFINITY);
        out.obj[..n].fill(NO_HIT);
        for (k, o) in self.objects.iter().enumerate() {
            if !may_hit(k) {
                continue;
            }
            match &o.shape {
                Shape::Sphere(s) => level.run(SphereHits(s, k as u32, rays, out)),
                Shape::Plane(p) => level.run(PlaneHits(p, k as u32, rays, out)),
                Shape::Mesh(m) => {
                    for i in 0..n {
                        if let Some(h) = m.intersect(&rays.get(i), out.t[i]) {
                            out.t[i] = h.t;
                            out.obj[i] = k as u32;
                            out.p.set(i, h.p);
                            out.ng.set(i, h.ng);
                            out.ns.set(i, h.ns);
                        }
                    }
                }
            }
        }
    }

    /// [`Scene::occluded`] of every ray of `rays`, into `out` (resized to
    /// their number).
    pub fn occluded_many(&self, level: SimdLevel, rays: &RayBlock, out: &mut Vec<bool>) {
        let n = rays.len();
        out.clear();
        out.resize(n, false);
        for o in &self.objects {
            match &o.shape {
                Shape::Sphere(s) => level.run(SphereBlocks(s, rays, out)),
                Shape::Plane(p) => level.run(PlaneBlocks(p, rays, out)),
                Shape::Mesh(m) => {
                    for (i, b) in out.iter_mut().enumerate() {
                        if !*b {
                            *b = m.occluded(&rays.get(i), f64::INFINITY);
                        }
                    }
                }
            }
        }
    }
}

/// `out[i] |= hit(origin, dir)` of every ray.
#[inline(always)]
fn lanes_each(rays: &RayBlock, out: &mut [bool], hit: impl Fn([f64; 3], [f64; 3]) -> bool) {
    let n = rays.len();
    let (o, d) = (&rays.origin, &rays.dir);
    let (ox, oy, oz) = (&o.x[..n], &o.y[..n], &o.z[..n]);
    let (dx, dy, dz) = (&d.x[..n], &d.y[..n], &d.z[..n]);
    let out = &mut out[..n];
    for i in 0..n {
        out[i] |= hit([ox[i], oy[i], oz[i]], [dx[i], dy[i], dz[i]]);
    }
}

/// `out[i] |= ` whether the sphere blocks ray `i`.
struct SphereBlocks<'a>(&'a Sphere, &'a RayBlock, &'a mut [bool]);

impl Step for SphereBlocks<'_> {
    #[inline(always)]
    fn run(self) {
        let SphereBlocks(s, rays, out) = self;
        let n = rays.len();
        for start in (0..n).step_by(CHUNK) {
            let m = (n - start).min(CHUNK);
            let (t, _) = sphere_chunk::<false>(s, rays, start, m);
            for (b, &t) in out[start..start + m].iter_mut().zip(&t) {
                *b |= t < f64::INFINITY;
            }
        }
    }
}

/// `out[i] |= ` whether the plane blocks ray `i`.
struct PlaneBlocks<'a>(&'a Plane, &'a RayBlock, &'a mut [bool]);

impl Step for PlaneBlocks<'_> {
    #[inline(always)]
    fn run(self) {
        let PlaneBlocks(p, rays, out) = self;
        lanes_each(rays, out, |o, d| plane_lane(p, o, d).0 < f64::INFINITY);
    }
}

/// Sphere `k`'s hits of the rays that are nearer than the hits' so far,
/// into them.
struct SphereHits<'a>(&'a Sphere, u32, &'a RayBlock, &'a mut HitBlock);

impl Step for SphereHits<'_> {
    #[inline(always)]
    fn run(self) {
        let SphereHits(s, k, rays, out) = self;
        let (c, r) = (s.center, s.radius);
        let n = rays.len();
        for start in (0..n).step_by(CHUNK) {
            let m = (n - start).min(CHUNK);
            let (tc, nv) = sphere_chunk::<true>(s, rays, start, m);
            let e = start + m;
            let (t, obj) = (&mut out.t[start..e], &mut out.obj[start..e]);
            let (px, py, pz) = (
                &mut out.p.x[start..e],
                &mut out.p.y[start..e],
                &mut out.p.z[start..e],
            );
            let (gx, gy, gz) = (
                &mut out.ng.x[start..e],
                &mut out.ng.y[start..e],
                &mut out.ng.z[start..e],
            );
            let (sx, sy, sz) = (
                &mut out.ns.x[start..e],
                &mut out.ns.y[start..e],
                &mut out.ns.z[start..e],
            );
            for i in 0..m {
                let near = tc[i] < t[i];
                if !near {
                    continue;
                }
                let (nx, ny, nz) = (nv[0][i], nv[1][i], nv[2][i]);
                t[i] = tc[i];
                obj[i] = k;
                // `center + n · radius`, the point re-projected on the sphere.
                px[i] = c.x + nx * r;
                py[i] = c.y + ny * r;
                pz[i] = c.z + nz * r;
                gx[i] = nx;
                gy[i] = ny;
                gz[i] = nz;
                sx[i] = nx;
                sy[i] = ny;
                sz[i] = nz;
            }
        }
    }
}

/// Plane `k`'s hits of the rays that are nearer than the hits' so far,
/// into them.
struct PlaneHits<'a>(&'a Plane, u32, &'a RayBlock, &'a mut HitBlock);

impl Step for PlaneHits<'_> {
    #[inline(always)]
    fn run(self) {
        let PlaneHits(pl, k, rays, out) = self;
        let n = rays.len();
        let (o, d) = (&rays.origin, &rays.dir);
        let (ox, oy, oz) = (&o.x[..n], &o.y[..n], &o.z[..n]);
        let (dx, dy, dz) = (&d.x[..n], &d.y[..n], &d.z[..n]);
        let (t, obj) = (&mut out.t[..n], &mut out.obj[..n]);
        let (px, py, pz) = (&mut out.p.x[..n], &mut out.p.y[..n], &mut out.p.z[..n]);
        let (gx, gy, gz) = (&mut out.ng.x[..n], &mut out.ng.y[..n], &mut out.ng.z[..n]);
        let (sx, sy, sz) = (&mut out.ns.x[..n], &mut out.ns.y[..n], &mut out.ns.z[..n]);
        let nm = pl.normal;
        for i in 0..n {
            let (ti, p) = plane_lane(pl, [ox[i], oy[i], oz[i]], [dx[i], dy[i], dz[i]]);
            let near = ti < t[i];
            let sel = |new: f64, old: f64| if near { new } else { old };
            t[i] = sel(ti, t[i]);
            obj[i] = if near { k } else { obj[i] };
            px[i] = sel(p[0], px[i]);
            py[i] = sel(p[1], py[i]);
            pz[i] = sel(p[2], pz[i]);
            gx[i] = sel(nm.x, gx[i]);
            gy[i] = sel(nm.y, gy[i]);
            gz[i] = sel(nm.z, gz[i]);
            sx[i] = sel(nm.x, sx[i]);
            sy[i] = sel(nm.y, sy[i]);
            sz[i] = sel(nm.z, sz[i]);
        }
    }
}

/// [`spawn_ray`] of every `(p[i], ng[i], dir[i])`, into `out` (resized to
/// their number): the same rays, bit for bit.
///
/// # Panics
/// If the three differ in length.
pub fn spawn_many(
    level: SimdLevel,
    p: &Vec3Block,
    ng: &Vec3Block,
    dir: &Vec3Block,
    out: &mut RayBlock,
) {
    let n = p.len();
    assert!(
        ng.len() == n && dir.len() == n,
        "spawn_many: lengths differ"
    );
    out.resize(n);
    level.run(Spawn(p, ng, dir, out));
}

/// `a.max(b)` of two absolute values (no `-0`), as `f64::max` gives it,
/// NaN included, but as a comparison and a select, which the compiler
/// vectorizes (`f64::max`'s NaN rule kept the loop scalar).
#[inline(always)]
fn max_of_abs(a: f64, b: f64) -> f64 {
    if b > a || a.is_nan() { b } else { a }
}

/// The origins of [`spawn_many`]'s rays. The outputs are parameters of
/// their own, so that the compiler knows they do not overlap the inputs
/// (`&mut` parameters are `noalias`) and vectorizes the loop without
/// run-time overlap checks (it left the loop scalar inline in
/// [`Spawn::run`]).
#[inline(always)]
fn spawn_lanes(
    (px, py, pz): (&[f64], &[f64], &[f64]),
    (gx, gy, gz): (&[f64], &[f64], &[f64]),
    (dx, dy, dz): (&[f64], &[f64], &[f64]),
    ox: &mut [f64],
    oy: &mut [f64],
    oz: &mut [f64],
) {
    let n = ox.len();
    let (oy, oz) = (&mut oy[..n], &mut oz[..n]);
    let (px, py, pz) = (&px[..n], &py[..n], &pz[..n]);
    let (gx, gy, gz) = (&gx[..n], &gy[..n], &gz[..n]);
    let (dx, dy, dz) = (&dx[..n], &dy[..n], &dz[..n]);
    for i in 0..n {
        let m = max_of_abs(px[i].abs(), max_of_abs(py[i].abs(), pz[i].abs()));
        let eps = RAY_EPSILON * (1.0 + m);
        let side = if dot(dx[i], dy[i], dz[i], gx[i], gy[i], gz[i]) >= 0.0 {
            eps
        } else {
            -eps
        };
        ox[i] = px[i] + gx[i] * side;
        oy[i] = py[i] + gy[i] * side;
        oz[i] = pz[i] + gz[i] * side;
    }
}

/// [`spawn_many`]'s loop.
struct Spawn<'a>(
    &'a Vec3Block,
    &'a Vec3Block,
    &'a Vec3Block,
    &'a mut RayBlock,
);

impl Step for Spawn<'_> {
    #[inline(always)]
    fn run(self) {
        let Spawn(p, ng, dir, out) = self;
        let n = p.len();
        let (o, od) = (&mut out.origin, &mut out.dir);
        let (dx, dy, dz) = (&dir.x[..n], &dir.y[..n], &dir.z[..n]);
        spawn_lanes(
            (&p.x[..n], &p.y[..n], &p.z[..n]),
            (&ng.x[..n], &ng.y[..n], &ng.z[..n]),
            (dx, dy, dz),
            &mut o.x[..n],
            &mut o.y[..n],
            &mut o.z[..n],
        );
        od.x[..n].copy_from_slice(dx);
        od.y[..n].copy_from_slice(dy);
        od.z[..n].copy_from_slice(dz);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::spawn_ray;
    use crate::mesh::Mesh;
    use crate::scene::Object;
    use lobe::envmap::EnvMap;
    use lobe::{Material, Rgb};
    use rand::{RngExt, SeedableRng};
    use rand_pcg::Pcg64;
    use std::sync::Arc;

    fn levels() -> Vec<SimdLevel> {
        SimdLevel::ALL
            .into_iter()
            .filter(|l| l.is_available())
            .collect()
    }

    fn unit(rng: &mut Pcg64) -> DVec3 {
        loop {
            let v = DVec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            );
            if let Some(u) = v.try_normalize() {
                return u;
            }
        }
    }

    /// Spheres (one touching another, one inside another), a plane and a
    /// mesh (a quad), in an order where later objects are nearer and farther.
    fn scene(with_mesh: bool) -> Scene {
        let camera = Camera::new(DVec3::new(0.0, 1.0, 5.0), DVec3::Y, DVec3::Y, 40.0, 64, 48)
            .expect("a camera");
        let m = || Material::lambert(Rgb::splat(0.5)).expect("a material");
        let mut s = Scene::new(camera, EnvMap::constant(Rgb::ONE))
            .with(Object::sphere(DVec3::new(-1.0, 1.0, 0.0), 0.9, m()).unwrap())
            .with(Object::plane(DVec3::ZERO, DVec3::new(0.1, 1.0, 0.0), m()).unwrap())
            .with(Object::sphere(DVec3::new(0.8, 1.0, 0.0), 0.9, m()).unwrap())
            .with(Object::sphere(DVec3::new(0.8, 1.0, 0.0), 0.3, m()).unwrap())
            .with(Object::sphere(DVec3::new(0.0, 0.5, 2.0), 1e-3, m()).unwrap());
        if with_mesh {
            let obj = "v -2 0 -1\nv 2 0 -1\nv 2 3 -1\nv -2 3 -1\nf 1 2 3 4\n";
            let mesh = Mesh::parse_obj(obj).expect("a mesh");
            s = s.with(Object::mesh(Arc::new(mesh), m()));
        }
        s
    }

    /// Rays from inside, outside and on the surfaces (offset as the
    /// renderer offsets them), some grazing.
    fn rays(scene: &Scene, n: usize, seed: u64) -> Vec<Ray> {
        let mut rng = Pcg64::seed_from_u64(seed);
        let mut out = Vec::with_capacity(n);
        while out.len() < n {
            let o = DVec3::new(
                rng.random_range(-3.0..3.0),
                rng.random_range(-1.0..3.0),
                rng.random_range(-3.0..6.0),
            );
            let d = unit(&mut rng);
            let r = Ray { origin: o, dir: d };
            out.push(r);
            // A ray leaving the hit, toward a random side.
            if let Some((h, _)) = scene.intersect(&r, f64::INFINITY) {
                out.push(spawn_ray(h.p, h.ng, unit(&mut rng)));
                // Grazing: along the tangent plane.
                let g = (d - h.ng * d.dot(h.ng)).try_normalize().unwrap_or(d);
                out.push(spawn_ray(h.p, h.ng, g));
            }
        }
        out
    }

    fn block_of(rays: &[Ray]) -> RayBlock {
        let mut l = RayBlock::default();
        for r in rays {
            l.push(r);
        }
        l
    }

    #[test]
    fn nearest_hits_and_shadow_tests_are_the_scalar_ones_bit_for_bit() {
        for with_mesh in [false, true] {
            let scene = scene(with_mesh);
            let rays = rays(&scene, 4000, 7);
            let block = block_of(&rays);
            let (mut hits, mut blocked) = (HitBlock::default(), Vec::new());
            for level in levels() {
                scene.intersect_many(level, &block, &mut hits);
                scene.occluded_many(level, &block, &mut blocked);
                let mut n_hit = 0;
                for (i, r) in rays.iter().enumerate() {
                    let want = scene.intersect(r, f64::INFINITY);
                    assert_eq!(blocked[i], scene.occluded(r), "{level:?} ray {i} {r:?}");
                    match want {
                        None => assert_eq!(hits.obj[i], NO_HIT, "{level:?} ray {i} {r:?}"),
                        Some((h, k)) => {
                            n_hit += 1;
                            let got = (
                                hits.obj[i] as usize,
                                hits.t[i].to_bits(),
                                hits.p.get(i).to_array().map(f64::to_bits),
                                hits.ng.get(i).to_array().map(f64::to_bits),
                                hits.ns.get(i).to_array().map(f64::to_bits),
                            );
                            let want = (
                                k,
                                h.t.to_bits(),
                                h.p.to_array().map(f64::to_bits),
                                h.ng.to_array().map(f64::to_bits),
                                h.ns.to_array().map(f64::to_bits),
                            );
                            assert_eq!(got, want, "{level:?} ray {i} {r:?}");
                        }
                    }
                }
                // Both kinds are there in numbers.
                assert!(n_hit > 1000 && n_hit < rays.len() - 500, "{n_hit} hits");
            }
        }
    }

    /// Shadow rays leaving the sphere they start on, in runs of whole
    /// chunks (which skip the roots: every lane starts outside and goes
    /// away), and rays from outside along a tangent (`b = ±0`), against
    /// the scalar tests.
    #[test]
    fn rays_leaving_a_sphere_are_the_scalar_ones_bit_for_bit() {
        let scene = scene(false);
        let mut rng = Pcg64::seed_from_u64(11);
        let mut rays = Vec::new();
        for o in &scene.objects {
            let Shape::Sphere(s) = &o.shape else {
                continue;
            };
            for _ in 0..64 {
                let n = unit(&mut rng);
                let mut d = unit(&mut rng);
                if d.dot(n) < 0.0 {
                    d = -d;
                }
                rays.push(spawn_ray(s.center + n * s.radius, n, d));
            }
            for (e, f) in [
                (DVec3::X, DVec3::Y),
                (DVec3::Y, DVec3::Z),
                (DVec3::Z, DVec3::X),
            ] {
                for k in [1.0, 1.5, 3.0] {
                    let origin = s.center + e * (s.radius * k);
                    rays.push(Ray { origin, dir: f });
                    rays.push(Ray { origin, dir: -f });
                }
            }
        }
        let block = block_of(&rays);
        let (mut hits, mut blocked) = (HitBlock::default(), Vec::new());
        let mut n_blocked = 0;
        for level in levels() {
            scene.intersect_many(level, &block, &mut hits);
            scene.occluded_many(level, &block, &mut blocked);
            for (i, r) in rays.iter().enumerate() {
                assert_eq!(blocked[i], scene.occluded(r), "{level:?} ray {i} {r:?}");
                n_blocked += usize::from(blocked[i]);
                let want = scene.intersect(r, f64::INFINITY);
                assert_eq!(
                    want.map(|(h, k)| (k as u32, h.t.to_bits())),
                    (hits.obj[i] != NO_HIT).then(|| (hits.obj[i], hits.t[i].to_bits())),
                    "{level:?} ray {i} {r:?}"
                );
            }
        }
        // Some are blocked by another sphere (two touch, one is inside one).
        assert!(n_blocked > 0);
    }

    #[test]
    fn camera_rays_and_offsets_are_the_scalar_ones_bit_for_bit() {
        let scene = scene(false);
        let cam = &scene.camera;
        let mut rng = Pcg64::seed_from_u64(3);
        let xs: Vec<f64> = (0..1000).map(|_| rng.random_range(0.0..64.0)).collect();
        let ys: Vec<f64> = (0..1000).map(|_| rng.random_range(0.0..48.0)).collect();
        let (mut p, mut ng, mut dir) = (
            Vec3Block::default(),
            Vec3Block::default(),
            Vec3Block::default(),
        );
        for _ in 0..1000 {
            p.push(DVec3::new(
                rng.random_range(-1e3..1e3),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1e-3..1e-3),
            ));
            ng.push(unit(&mut rng));
            dir.push(unit(&mut rng));
        }
        let mut out = RayBlock::default();
        for level in levels() {
            cam.rays_many(level, &xs, &ys, &mut out);
            for i in 0..xs.len() {
                let want = cam.ray(xs[i], ys[i]);
                assert_eq!(out.get(i), want, "{level:?} {i}");
                assert_eq!(
                    out.get(i).dir.to_array().map(f64::to_bits),
                    want.dir.to_array().map(f64::to_bits)
                );
            }
            spawn_many(level, &p, &ng, &dir, &mut out);
            for i in 0..p.len() {
                let want = spawn_ray(p.get(i), ng.get(i), dir.get(i));
                assert_eq!(
                    [out.get(i).origin, out.get(i).dir].map(|v| v.to_array().map(f64::to_bits)),
                    [want.origin, want.dir].map(|v| v.to_array().map(f64::to_bits)),
                    "{level:?} {i}"
                );
            }
        }
    }
}
