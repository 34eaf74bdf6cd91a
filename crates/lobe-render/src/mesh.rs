//! Triangle meshes: a Wavefront OBJ reader and a bounding volume hierarchy
//! built with the surface area heuristic over binned centroids.

use crate::geometry::{Aabb, Hit, Ray, intersect_triangle};
use glam::DVec3;
use std::path::{Path, PathBuf};

/// What went wrong reading or building a mesh.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    #[error("{path}: cannot read the mesh file: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}:{line}: {message}")]
    Obj {
        path: PathBuf,
        line: usize,
        message: String,
    },
    #[error("{0}")]
    Invalid(String),
}

/// A triangle mesh with its BVH.
#[derive(Debug, Clone)]
pub struct Mesh {
    /// Triangle vertices, in BVH order.
    tris: Vec<[DVec3; 3]>,
    /// Vertex normals of each triangle (BVH order), when the file has them.
    normals: Vec<Option<[DVec3; 3]>>,
    nodes: Vec<Node>,
    bounds: Aabb,
    /// Triangles dropped because they have no area.
    pub degenerate: usize,
}

/// A BVH node: an inner node's left child is the next node and its right
/// child is node `first`; a leaf holds the `count > 0` triangles from `first`.
#[derive(Debug, Clone, Copy)]
struct Node {
    bounds: Aabb,
    first: u32,
    count: u32,
}

/// Triangles per leaf at most (unless their centroids coincide).
const LEAF_SIZE: usize = 4;
const BINS: usize = 16;
/// Past this depth, splits are at the median (bounds the depth).
const SAH_DEPTH: usize = 48;
const STACK: usize = 128;

impl Mesh {
    /// A mesh from positions, triangles (indices into `positions`) and,
    /// per triangle, optional indices into `normals`. Triangles of zero area
    /// are dropped (counted in [`Mesh::degenerate`]); zero normals are
    /// ignored (the face normal is used).
    pub fn new(
        positions: &[DVec3],
        normals: &[DVec3],
        triangles: &[[u32; 3]],
        triangle_normals: &[Option<[u32; 3]>],
    ) -> Result<Mesh, MeshError> {
        if !triangle_normals.is_empty() && triangle_normals.len() != triangles.len() {
            return Err(MeshError::Invalid(format!(
                "{} triangles but {} normal triples",
                triangles.len(),
                triangle_normals.len()
            )));
        }
        if let Some(p) = positions.iter().find(|p| !p.is_finite()) {
            return Err(MeshError::Invalid(format!("vertex {p} is not finite")));
        }
        let mut tris = Vec::with_capacity(triangles.len());
        let mut tn = Vec::with_capacity(triangles.len());
        let mut degenerate = 0;
        for (k, t) in triangles.iter().enumerate() {
            let get = |i: u32| {
                positions.get(i as usize).copied().ok_or_else(|| {
                    MeshError::Invalid(format!(
                        "triangle {k}: vertex index {i} is out of range ({} vertices)",
                        positions.len()
                    ))
                })
            };
            let v = [get(t[0])?, get(t[1])?, get(t[2])?];
            let area2 = (v[1] - v[0]).cross(v[2] - v[0]).length();
            if area2.is_nan() || area2 <= 0.0 || area2.is_infinite() {
                degenerate += 1;
                continue;
            }
            let n = match triangle_normals.get(k).copied().flatten() {
                Some(ni) => {
                    let mut out = [DVec3::ZERO; 3];
                    let mut ok = true;
                    for (o, &i) in out.iter_mut().zip(&ni) {
                        let n = normals.get(i as usize).copied().ok_or_else(|| {
                            MeshError::Invalid(format!(
                                "triangle {k}: normal index {i} is out of range ({} normals)",
                                normals.len()
                            ))
                        })?;
                        match n.try_normalize() {
                            Some(n) => *o = n,
                            None => ok = false,
                        }
                    }
                    ok.then_some(out)
                }
                None => None,
            };
            tris.push(v);
            tn.push(n);
        }
        if tris.is_empty() {
            return Err(MeshError::Invalid(format!(
                "the mesh has no triangles with an area ({} given, {degenerate} degenerate)",
                triangles.len()
            )));
        }
        let mut mesh = Mesh {
            tris,
            normals: tn,
            nodes: Vec::new(),
            bounds: Aabb::EMPTY,
            degenerate,
        };
        mesh.build();
        Ok(mesh)
    }

    /// Read a Wavefront OBJ file: `v` and `vn` lines and `f` lines with
    /// three or more vertices (`v`, `v/vt`, `v//vn` or `v/vt/vn`, 1-based,
    /// negative indices counting back from the last vertex so far);
    /// polygons are fan-triangulated. Other statements are ignored.
    pub fn load_obj(path: &Path) -> Result<Mesh, MeshError> {
        let text = std::fs::read(path).map_err(|source| MeshError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let text = String::from_utf8_lossy(&text);
        Self::parse_obj(&text).map_err(|e| match e {
            ObjError::Line(line, message) => MeshError::Obj {
                path: path.to_path_buf(),
                line,
                message,
            },
            ObjError::Mesh(m) => MeshError::Invalid(format!("{}: {m}", path.display())),
        })
    }

    /// Parse OBJ text (see [`Mesh::load_obj`]).
    pub fn parse_obj(text: &str) -> Result<Mesh, ObjError> {
        let mut positions: Vec<DVec3> = Vec::new();
        let mut normals: Vec<DVec3> = Vec::new();
        let mut texcoords = 0usize;
        let mut triangles: Vec<[u32; 3]> = Vec::new();
        let mut tri_normals: Vec<Option<[u32; 3]>> = Vec::new();
        let mut face: Vec<(u32, Option<u32>)> = Vec::new();
        let mut any_normals = false;
        for (n, raw) in text.lines().enumerate() {
            let line_no = n + 1;
            let err = |m: String| ObjError::Line(line_no, m);
            let line = raw.split('#').next().unwrap_or("").trim();
            let mut words = line.split_whitespace();
            let Some(kw) = words.next() else { continue };
            match kw {
                "v" | "vn" => {
                    let mut c = [0.0; 3];
                    for (i, slot) in c.iter_mut().enumerate() {
                        let w = words
                            .next()
                            .ok_or_else(|| err(format!("`{kw}` needs 3 numbers, got {i}")))?;
                        *slot = w
                            .parse::<f64>()
                            .ok()
                            .filter(|x| x.is_finite())
                            .ok_or_else(|| err(format!("`{w}` is not a finite number")))?;
                    }
                    if kw == "v" {
                        positions.push(DVec3::from_array(c));
                    } else {
                        normals.push(DVec3::from_array(c));
                    }
                }
                "vt" => texcoords += 1,
                "f" => {
                    face.clear();
                    for w in words {
                        let mut parts = w.split('/');
                        let resolve = |s: &str,
                                       count: usize,
                                       what: &str|
                         -> Result<u32, ObjError> {
                            let i: i64 = s.parse().map_err(|_| {
                                err(format!("face vertex `{w}`: `{s}` is not an index"))
                            })?;
                            let idx = if i > 0 {
                                i - 1
                            } else if i < 0 {
                                count as i64 + i
                            } else {
                                -1
                            };
                            if idx < 0 || idx >= count as i64 {
                                return Err(err(format!(
                                    "face vertex `{w}`: {what} index {i} is out of range ({count} so far)"
                                )));
                            }
                            u32::try_from(idx)
                                .map_err(|_| err(format!("face vertex `{w}`: index too large")))
                        };
                        let v = resolve(parts.next().unwrap_or(""), positions.len(), "vertex")?;
                        let vt = parts.next();
                        if let Some(t) = vt.filter(|t| !t.is_empty()) {
                            resolve(t, texcoords, "texture")?;
                        }
                        let vn = match parts.next() {
                            Some(s) if !s.is_empty() => Some(resolve(s, normals.len(), "normal")?),
                            _ => None,
                        };
                        if parts.next().is_some() {
                            return Err(err(format!(
                                "face vertex `{w}`: expected v, v/vt, v//vn or v/vt/vn"
                            )));
                        }
                        face.push((v, vn));
                    }
                    if face.len() < 3 {
                        return Err(err(format!(
                            "a face needs at least 3 vertices, got {}",
                            face.len()
                        )));
                    }
                    let all_n = face.iter().all(|f| f.1.is_some());
                    any_normals |= all_n;
                    for k in 1..face.len() - 1 {
                        let (a, b, c) = (face[0], face[k], face[k + 1]);
                        triangles.push([a.0, b.0, c.0]);
                        tri_normals.push(if all_n {
                            Some([a.1.unwrap_or(0), b.1.unwrap_or(0), c.1.unwrap_or(0)])
                        } else {
                            None
                        });
                    }
                }
                _ => {}
            }
        }
        if triangles.is_empty() {
            return Err(ObjError::Mesh("the file has no faces".into()));
        }
        if !any_normals {
            tri_normals.clear();
        }
        Mesh::new(&positions, &normals, &triangles, &tri_normals)
            .map_err(|e| ObjError::Mesh(e.to_string()))
    }

    /// Number of triangles (degenerate ones dropped).
    #[must_use]
    pub fn len(&self) -> usize {
        self.tris.len()
    }

    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.tris.is_empty()
    }

    #[must_use]
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    fn build(&mut self) {
        let n = self.tris.len();
        let boxes: Vec<Aabb> = self
            .tris
            .iter()
            .map(|t| Aabb::EMPTY.grow(t[0]).grow(t[1]).grow(t[2]))
            .collect();
        let centroids: Vec<DVec3> = boxes.iter().map(Aabb::centroid).collect();
        let mut order: Vec<u32> = (0..n as u32).collect();
        let mut nodes = Vec::with_capacity(2 * n / LEAF_SIZE + 1);
        build_node(&mut nodes, &mut order, 0, &boxes, &centroids, 0);
        self.bounds = nodes[0].bounds;
        self.nodes = nodes;
        self.tris = order.iter().map(|&i| self.tris[i as usize]).collect();
        self.normals = order.iter().map(|&i| self.normals[i as usize]).collect();
    }

    /// The nearest hit with `t` in `(0, t_max)`.
    #[must_use]
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<Hit> {
        let inv = ray.dir.recip();
        let mut best: Option<(f64, usize, f64, f64)> = None;
        let mut t_best = t_max;
        let mut stack = [0u32; STACK];
        let mut sp = 0usize;
        let mut node = 0usize;
        self.nodes[0].bounds.hit(ray.origin, inv, t_best)?;
        loop {
            let nd = &self.nodes[node];
            if nd.count > 0 {
                let first = nd.first as usize;
                for k in first..first + nd.count as usize {
                    let [a, b, c] = self.tris[k];
                    if let Some((t, b1, b2)) = intersect_triangle(ray, a, b, c, t_best) {
                        t_best = t;
                        best = Some((t, k, b1, b2));
                    }
                }
            } else {
                let (l, r) = (node + 1, nd.first as usize);
                let hl = self.nodes[l].bounds.hit(ray.origin, inv, t_best);
                let hr = self.nodes[r].bounds.hit(ray.origin, inv, t_best);
                match (hl, hr) {
                    (Some(tl), Some(tr)) => {
                        // The nearer child first; the other waits.
                        let (near, far) = if tr < tl { (r, l) } else { (l, r) };
                        stack[sp] = far as u32;
                        sp += 1;
                        node = near;
                        continue;
                    }
                    (Some(_), None) => {
                        node = l;
                        continue;
                    }
                    (None, Some(_)) => {
                        node = r;
                        continue;
                    }
                    (None, None) => {}
                }
            }
            // Pop the next node that the ray still reaches.
            loop {
                if sp == 0 {
                    return best.map(|(t, k, b1, b2)| self.hit(t, k, b1, b2));
                }
                sp -= 1;
                let n = stack[sp] as usize;
                if self.nodes[n].bounds.hit(ray.origin, inv, t_best).is_some() {
                    node = n;
                    break;
                }
            }
        }
    }

    /// `true` when something blocks the ray before `t_max`.
    #[must_use]
    pub fn occluded(&self, ray: &Ray, t_max: f64) -> bool {
        let inv = ray.dir.recip();
        let mut stack = [0u32; STACK];
        let mut sp = 0usize;
        if self.nodes[0].bounds.hit(ray.origin, inv, t_max).is_none() {
            return false;
        }
        let mut node = 0usize;
        loop {
            let nd = &self.nodes[node];
            if nd.count > 0 {
                let first = nd.first as usize;
                for k in first..first + nd.count as usize {
                    let [a, b, c] = self.tris[k];
                    if intersect_triangle(ray, a, b, c, t_max).is_some() {
                        return true;
                    }
                }
            } else {
                let (l, r) = (node + 1, nd.first as usize);
                let hl = self.nodes[l].bounds.hit(ray.origin, inv, t_max).is_some();
                let hr = self.nodes[r].bounds.hit(ray.origin, inv, t_max).is_some();
                if hl && hr {
                    stack[sp] = r as u32;
                    sp += 1;
                    node = l;
                    continue;
                } else if hl {
                    node = l;
                    continue;
                } else if hr {
                    node = r;
                    continue;
                }
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            node = stack[sp] as usize;
        }
    }

    fn hit(&self, t: f64, k: usize, b1: f64, b2: f64) -> Hit {
        let [a, b, c] = self.tris[k];
        let ng = (b - a).cross(c - a).normalize();
        let b0 = 1.0 - b1 - b2;
        let p = a * b0 + b * b1 + c * b2;
        let ns = match self.normals[k] {
            Some([na, nb, nc]) => {
                let n = (na * b0 + nb * b1 + nc * b2).try_normalize().unwrap_or(ng);
                if n.dot(ng) < 0.0 { -n } else { n }
            }
            None => ng,
        };
        Hit { t, p, ng, ns }
    }
}

/// An OBJ parse error, by line, or a mesh that cannot be built.
#[derive(Debug, Clone, PartialEq)]
pub enum ObjError {
    Line(usize, String),
    Mesh(String),
}

impl std::fmt::Display for ObjError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ObjError::Line(l, m) => write!(f, "line {l}: {m}"),
            ObjError::Mesh(m) => f.write_str(m),
        }
    }
}

impl std::error::Error for ObjError {}

/// Build the subtree over `order` (whose first triangle has index `offset`
/// in the final order) and return its node index.
fn build_node(
    nodes: &mut Vec<Node>,
    order: &mut [u32],
    offset: usize,
    boxes: &[Aabb],
    centroids: &[DVec3],
    depth: usize,
) -> usize {
    let bounds = order
        .iter()
        .fold(Aabb::EMPTY, |b, &i| b.union(boxes[i as usize]));
    let cb = order
        .iter()
        .fold(Aabb::EMPTY, |b, &i| b.grow(centroids[i as usize]));
    let me = nodes.len();
    nodes.push(Node {
        bounds,
        first: offset as u32,
        count: order.len() as u32,
    });
    let n = order.len();
    if n <= LEAF_SIZE {
        return me;
    }
    let ext = cb.max - cb.min;
    let axis = if ext.x >= ext.y && ext.x >= ext.z {
        0
    } else if ext.y >= ext.z {
        1
    } else {
        2
    };
    let mid = if ext[axis] <= 0.0 {
        // Coincident centroids: split the list in half (SAH cannot help).
        n / 2
    } else if depth >= SAH_DEPTH {
        median_split(order, centroids, axis)
    } else {
        match sah_split(order, boxes, centroids, axis, cb, bounds) {
            Some(m) => m,
            None => return me,
        }
    };
    let (left, right) = order.split_at_mut(mid);
    nodes[me].count = 0;
    let l = build_node(nodes, left, offset, boxes, centroids, depth + 1);
    debug_assert_eq!(l, me + 1);
    let r = build_node(nodes, right, offset + mid, boxes, centroids, depth + 1);
    nodes[me].first = r as u32;
    me
}

fn median_split(order: &mut [u32], centroids: &[DVec3], axis: usize) -> usize {
    let mid = order.len() / 2;
    order.select_nth_unstable_by(mid, |&a, &b| {
        centroids[a as usize][axis].total_cmp(&centroids[b as usize][axis])
    });
    mid
}

/// Partition `order` at the best binned-SAH plane on `axis`; `None` when a
/// leaf is cheaper (only for small `n`).
fn sah_split(
    order: &mut [u32],
    boxes: &[Aabb],
    centroids: &[DVec3],
    axis: usize,
    cb: Aabb,
    bounds: Aabb,
) -> Option<usize> {
    let (lo, hi) = (cb.min[axis], cb.max[axis]);
    let scale = BINS as f64 / (hi - lo);
    let bin_of = |c: DVec3| (((c[axis] - lo) * scale) as usize).min(BINS - 1);
    let mut bin_box = [Aabb::EMPTY; BINS];
    let mut bin_n = [0usize; BINS];
    for &i in order.iter() {
        let b = bin_of(centroids[i as usize]);
        bin_n[b] += 1;
        bin_box[b] = bin_box[b].union(boxes[i as usize]);
    }
    // Cost of splitting after bin k, from prefix and suffix sweeps.
    let mut left_cost = [0.0; BINS];
    let (mut acc, mut cnt) = (Aabb::EMPTY, 0usize);
    for k in 0..BINS - 1 {
        acc = acc.union(bin_box[k]);
        cnt += bin_n[k];
        left_cost[k] = acc.half_area() * cnt as f64;
    }
    let (mut acc, mut cnt) = (Aabb::EMPTY, 0usize);
    let mut best = (f64::INFINITY, 0usize);
    for k in (0..BINS - 1).rev() {
        acc = acc.union(bin_box[k + 1]);
        cnt += bin_n[k + 1];
        let left_n: usize = order.len() - cnt;
        if cnt == 0 || left_n == 0 {
            continue;
        }
        let c = left_cost[k] + acc.half_area() * cnt as f64;
        if c < best.0 {
            best = (c, k);
        }
    }
    let n = order.len();
    // Traversal cost 1 against intersection cost 1 per triangle.
    let split_cost = 1.0 + best.0 / bounds.half_area().max(f64::MIN_POSITIVE);
    if !best.0.is_finite() {
        return Some(median_split(order, centroids, axis));
    }
    if split_cost >= n as f64 && n <= 4 * LEAF_SIZE {
        return None;
    }
    let k = best.1;
    // Partition in place: bins 0..=k to the left.
    let mut i = 0;
    let mut j = n;
    while i < j {
        if bin_of(centroids[order[i] as usize]) <= k {
            i += 1;
        } else {
            j -= 1;
            order.swap(i, j);
        }
    }
    Some(i)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(n: usize) -> String {
        // An n×n grid of quads in the z = 0 plane, as OBJ text.
        let mut s = String::new();
        for j in 0..=n {
            for i in 0..=n {
                s += &format!("v {} {} 0\n", i as f64 / n as f64, j as f64 / n as f64);
            }
        }
        for j in 0..n {
            for i in 0..n {
                let a = j * (n + 1) + i + 1;
                s += &format!("f {} {} {} {}\n", a, a + 1, a + n + 2, a + n + 1);
            }
        }
        s
    }

    #[test]
    fn obj_forms_and_errors() {
        let m = Mesh::parse_obj(
            "# a quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n\
             f 1/1/1 2/1/1 3/1/1 4/1/1\nf -4//-1 -2//-1 -1//-1\n",
        )
        .unwrap();
        assert_eq!(m.len(), 3);
        assert!(matches!(
            Mesh::parse_obj("v 0 0 0\nf 1 2 3\n"),
            Err(ObjError::Line(2, _))
        ));
        assert!(matches!(
            Mesh::parse_obj("v 0 0 x\n"),
            Err(ObjError::Line(1, _))
        ));
        assert!(matches!(
            Mesh::parse_obj("v 0 0 0\n"),
            Err(ObjError::Mesh(_))
        ));
        assert!(matches!(
            Mesh::parse_obj("v 0 0 0\nv 1 0 0\nf 1 2\n"),
            Err(ObjError::Line(3, _))
        ));
    }

    #[test]
    fn bvh_matches_brute_force() {
        let m = Mesh::parse_obj(&grid(40)).unwrap();
        assert_eq!(m.len(), 3200);
        let mut hits = 0;
        for k in 0..3000 {
            let a = k as f64 * 0.618_033_988_749 % 1.0;
            let b = k as f64 * 0.414_213_562_373 % 1.0;
            let origin = DVec3::new(a * 1.4 - 0.2, b * 1.4 - 0.2, 1.0);
            let dir = DVec3::new(0.3 * (a - 0.5), 0.2 * (b - 0.5), -1.0).normalize();
            let ray = Ray { origin, dir };
            let brute = m
                .tris
                .iter()
                .filter_map(|t| intersect_triangle(&ray, t[0], t[1], t[2], f64::INFINITY))
                .map(|h| h.0)
                .fold(f64::INFINITY, f64::min);
            let got = m
                .intersect(&ray, f64::INFINITY)
                .map_or(f64::INFINITY, |h| h.t);
            assert_eq!(got, brute, "ray {k}");
            assert_eq!(m.occluded(&ray, f64::INFINITY), brute.is_finite());
            hits += usize::from(brute.is_finite());
        }
        assert!(hits > 1000);
    }
}
