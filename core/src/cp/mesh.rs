//! The subdivided icosahedron, point location in O(1) and the interpolation weights.
//!
//! **Subdivision.** Level `L` splits each base face into `n² = 4^L` triangles by the flat
//! grid `A·(n−i−j)/n + B·i/n + C·j/n` (`i + j ≤ n`), normalised once (in `f64`, then rounded
//! to `f32`), not by normalised edge midpoints level by level. Gnomonic projection maps
//! great circles to straight lines, so the spherical triangles of level `L` are exactly the
//! central projections of the flat grid's triangles: location is an index computation on the
//! base face's plane. Levels nest (the flat grid of `L` is a subgrid of that of `L + 1`).
//!
//! **Location.** The base face is found by the signs of the direction (its octant) and three
//! dot products: the first octant holds one whole face (the one with vertices
//! `(0,1,φ), (φ,0,1), (1,φ,0)`) and, across each of its edges, half of a neighbour; the
//! other octants are its reflections. Inside the base face, the barycentrics of the ray's hit
//! on the face's plane, `λ_k = d·(V_{k+1} × V_{k+2}) / Σ`, times `n`, give the grid cell and
//! its upper or lower triangle. No loop, whatever the level.

use alloc::vec;
use alloc::vec::Vec;

use crate::Error;
use crate::Vec3;
use crate::math;

/// Bound on the absolute error of each area weight against the `f64` area ratio of the same
/// triangle, at every level (measured 1.4e-6 at level 4 by
/// `tests::area_weights_are_stable_on_level_4_triangles`, which asserts this bound).
pub const WEIGHT_ABS_ERROR: f32 = 3e-6;

/// The highest subdivision level (2562 vertices, 5120 triangles).
pub const MAX_LEVEL: u32 = 4;

/// The interpolation weights inside a triangle.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Weights {
    /// The paper's eq. 2–4: `ω_i = α_i / Σ α_j`, `α_i` the area of the spherical triangle
    /// made of the direction and the two vertices other than `i`. Each area is
    /// `2·atan2(|a·(b×c)|, 1 + a·b + b·c + c·a)` (Van Oosterom and Strackee 1983), the
    /// triple product taken on edge differences so that it keeps its relative precision on
    /// level-4 triangles (Girard's `A + B + C − π` loses it all in `f32` from level 2).
    /// Not continuous across triangle edges: a spherical median does not halve a triangle's
    /// area, so on an edge the weight of the opposite vertex is 0 on both sides but the other
    /// two split differently (measured by `steradian report`, section `control-points`).
    #[default]
    Area,
    /// The barycentrics of the ray's hit on the base face's plane (gnomonic barycentrics):
    /// linear in the grid coordinates, continuous across every edge, a few FMAs.
    Gnomonic,
}

/// Where a direction falls: its triangle, the triangle's vertices and their weights.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Location {
    /// Index into [`Icosphere::triangles`].
    pub triangle: u32,
    /// The triangle's vertices (indices into [`Icosphere::vertices`]), counter-clockwise
    /// seen from outside.
    pub vertices: [u32; 3],
    /// Their weights: each in `[0, 1]`, summing to 1 within a few ulps.
    pub weights: [f32; 3],
}

/// A subdivided icosahedron of level 0–4 with adjacency.
#[derive(Clone, Debug)]
pub struct Icosphere {
    level: u32,
    vertices: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    /// Per base face, `(n + 1)²` grid slots `j·(n + 1) + i` → vertex index.
    grid: Vec<u32>,
    /// Base faces: vertices `[A, B, C]` and the edge normals `[B×C, C×A, A×B]`.
    faces: [[Vec3; 3]; 20],
    cross: [[Vec3; 3]; 20],
    /// Per octant (bit 0: x < 0, bit 1: y < 0, bit 2: z < 0), the base face of the octant
    /// face and of its three neighbours across the canonical edges.
    octant: [[u8; 4]; 8],
    neighbours: Vec<[u32; 3]>,
    ring_start: Vec<u32>,
    ring: Vec<u32>,
}

const PHI: f64 = 1.618_033_988_749_895;

fn norm64(p: [f64; 3]) -> [f64; 3] {
    let l = math::sqrt64(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    [p[0] / l, p[1] / l, p[2] / l]
}

fn to32(p: [f64; 3]) -> Vec3 {
    Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32)
}

fn base_vertices() -> [[f64; 3]; 12] {
    let mut v = [[0.0; 3]; 12];
    let mut k = 0;
    for axis in 0..3 {
        for s1 in [1.0, -1.0] {
            for s2 in [1.0, -1.0] {
                // Cyclic permutations of (0, ±1, ±φ).
                let mut p = [0.0; 3];
                p[(axis + 1) % 3] = s1;
                p[(axis + 2) % 3] = s2 * PHI;
                v[k] = norm64(p);
                k += 1;
            }
        }
    }
    v
}

fn dot64(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross64(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The 20 faces as vertex triples, counter-clockwise seen from outside, in lexicographic
/// order of their sorted vertex indices.
fn base_faces(v: &[[f64; 3]; 12]) -> [[usize; 3]; 20] {
    // Adjacent base vertices are at angle ~63.4°, cos = 1/√5; the next are at cos −1/√5.
    let adj = |a: usize, b: usize| dot64(v[a], v[b]) > 0.4;
    let mut f = [[0; 3]; 20];
    let mut k = 0;
    for a in 0..12 {
        for b in a + 1..12 {
            for c in b + 1..12 {
                if adj(a, b) && adj(b, c) && adj(a, c) {
                    let t = if dot64(cross64(v[a], v[b]), v[c]) > 0.0 {
                        [a, b, c]
                    } else {
                        [a, c, b]
                    };
                    f[k] = t;
                    k += 1;
                }
            }
        }
    }
    debug_assert_eq!(k, 20);
    f
}

impl Icosphere {
    /// The mesh of `level` (0–4). Deterministic: the same bits on every machine (built in
    /// `f64` with correctly rounded operations only).
    ///
    /// Vertex order: the 12 base vertices, then the points inside each base edge (edges in
    /// lexicographic order, from the lower vertex index), then each base face's interior
    /// points row by row.
    pub fn new(level: u32) -> Result<Self, Error> {
        if level > MAX_LEVEL {
            return Err(Error::OutOfRange {
                what: "level",
                value: level as f32,
                min: 0.0,
                max: MAX_LEVEL as f32,
            });
        }
        let n = 1u32 << level;
        let nu = n as usize;
        let bv = base_vertices();
        let bf = base_faces(&bv);
        let mut vertices: Vec<Vec3> = bv.iter().map(|p| to32(*p)).collect();
        // Edge points: for each base edge (a < b), k = 1..n−1 from a.
        let mut edges: Vec<(usize, usize)> = Vec::new();
        for f in &bf {
            for e in 0..3 {
                let (a, b) = (f[e], f[(e + 1) % 3]);
                let key = (a.min(b), a.max(b));
                if !edges.contains(&key) {
                    edges.push(key);
                }
            }
        }
        edges.sort_unstable();
        let mut edge_start = Vec::with_capacity(edges.len());
        for &(a, b) in &edges {
            edge_start.push(vertices.len() as u32);
            for k in 1..nu {
                let t = k as f64 / n as f64;
                let p = core::array::from_fn(|c| bv[a][c] * (1.0 - t) + bv[b][c] * t);
                vertices.push(to32(norm64(p)));
            }
        }
        let edge_point = |a: usize, b: usize, k: usize| -> u32 {
            // The point k/n of the way from a to b.
            if k == 0 {
                return a as u32;
            }
            if k == nu {
                return b as u32;
            }
            let (lo, kk) = if a < b { (a, k) } else { (b, nu - k) };
            let hi = a.max(b);
            let e = edges.binary_search(&(lo, hi)).expect("base edge");
            edge_start[e] + kk as u32 - 1
        };
        let side = nu + 1;
        let mut grid = vec![u32::MAX; 20 * side * side];
        let mut faces = [[Vec3::ZERO; 3]; 20];
        let mut cross = [[Vec3::ZERO; 3]; 20];
        for (fi, f) in bf.iter().enumerate() {
            let [a, b, c] = *f;
            faces[fi] = [to32(bv[a]), to32(bv[b]), to32(bv[c])];
            cross[fi] = [
                to32(cross64(bv[b], bv[c])),
                to32(cross64(bv[c], bv[a])),
                to32(cross64(bv[a], bv[b])),
            ];
            for j in 0..=nu {
                for i in 0..=nu - j {
                    let id = if j == 0 {
                        edge_point(a, b, i)
                    } else if i + j == nu {
                        edge_point(b, c, j)
                    } else if i == 0 {
                        edge_point(a, c, j)
                    } else {
                        let (wb, wc) = (i as f64 / n as f64, j as f64 / n as f64);
                        let wa = 1.0 - wb - wc;
                        let p =
                            core::array::from_fn(|k| bv[a][k] * wa + bv[b][k] * wb + bv[c][k] * wc);
                        vertices.push(to32(norm64(p)));
                        (vertices.len() - 1) as u32
                    };
                    grid[fi * side * side + j * side + i] = id;
                }
            }
        }
        let mut triangles = Vec::with_capacity(20 * nu * nu);
        for fi in 0..20 {
            let g = |i: usize, j: usize| grid[fi * side * side + j * side + i];
            for j in 0..nu {
                for i in 0..nu - j {
                    triangles.push([g(i, j), g(i + 1, j), g(i, j + 1)]);
                    if i + j + 1 < nu {
                        triangles.push([g(i + 1, j), g(i + 1, j + 1), g(i, j + 1)]);
                    }
                }
            }
        }
        // The octant table: reflect the canonical face and its neighbours' points into each
        // octant and find the base face that holds them.
        let p = norm64([0.0, 1.0, PHI]);
        let q = norm64([PHI, 0.0, 1.0]);
        let r = norm64([1.0, PHI, 0.0]);
        let centre = norm64(core::array::from_fn(|k| p[k] + q[k] + r[k]));
        // A point just outside each canonical edge, inside the first octant.
        let outside = |u: [f64; 3], w: [f64; 3]| {
            let m: [f64; 3] = core::array::from_fn(|k| (u[k] + w[k]) / 2.0);
            norm64(core::array::from_fn(|k| m[k] * 1.05 - centre[k] * 0.05))
        };
        let probes = [centre, outside(p, q), outside(q, r), outside(r, p)];
        let mut octant = [[0u8; 4]; 8];
        for (o, row) in octant.iter_mut().enumerate() {
            for (slot, probe) in row.iter_mut().zip(&probes) {
                let s: [f64; 3] =
                    core::array::from_fn(|k| if o >> k & 1 == 1 { -probe[k] } else { probe[k] });
                let mut best = (f64::NEG_INFINITY, 0);
                for (fi, f) in bf.iter().enumerate() {
                    let c: [f64; 3] =
                        core::array::from_fn(|k| bv[f[0]][k] + bv[f[1]][k] + bv[f[2]][k]);
                    let d = dot64(norm64(c), s);
                    if d > best.0 {
                        best = (d, fi);
                    }
                }
                *slot = best.1 as u8;
            }
        }
        let (neighbours, ring_start, ring) = adjacency(vertices.len(), &triangles);
        Ok(Self {
            level,
            vertices,
            triangles,
            grid,
            faces,
            cross,
            octant,
            neighbours,
            ring_start,
            ring,
        })
    }

    /// The subdivision level.
    pub fn level(&self) -> u32 {
        self.level
    }

    /// The unit vertex directions (the control points), in the order the values are indexed.
    pub fn vertices(&self) -> &[Vec3] {
        &self.vertices
    }

    /// The spherical triangles, counter-clockwise seen from outside: `20·4^L` of them, base
    /// face by base face.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// For each triangle, the triangle across its edge `k` (the edge opposite vertex `k`).
    pub fn triangle_neighbours(&self) -> &[[u32; 3]] {
        &self.neighbours
    }

    /// The vertices joined to vertex `v` by an edge (5 around the 12 base vertices, 6
    /// elsewhere), sorted by index. Empty for an index out of range.
    pub fn vertex_neighbours(&self, v: usize) -> &[u32] {
        match (self.ring_start.get(v), self.ring_start.get(v + 1)) {
            (Some(&a), Some(&b)) => &self.ring[a as usize..b as usize],
            _ => &[],
        }
    }

    /// The triangle that holds direction `d` and its weights. `d` may have any length
    /// (huge and subnormal ones included); a zero or non-finite `d` is an error. On an edge
    /// or a vertex either triangle may be returned: the weights agree there (for
    /// [`Weights::Gnomonic`] exactly, for [`Weights::Area`] up to the discontinuity
    /// documented on it).
    pub fn locate(&self, d: Vec3, weights: Weights) -> Result<Location, Error> {
        let u = unit(d)?;
        let f = self.base_face(u);
        let c = &self.cross[f];
        let b = [u.dot(c[0]), u.dot(c[1]), u.dot(c[2])];
        let s = b[0] + b[1] + b[2];
        let nu = 1usize << self.level;
        let n = nu as f32;
        let x = (b[1] / s * n).max(0.0);
        let y = (b[2] / s * n).max(0.0);
        let i = (math::floorf(x) as usize).min(nu - 1);
        let j = (math::floorf(y) as usize).min(nu - 1 - i);
        let (fx, fy) = (x - i as f32, y - j as f32);
        let up = fx + fy <= 1.0 || i + j + 1 == nu;
        let side = nu + 1;
        let g = |i: usize, j: usize| self.grid[f * side * side + j * side + i];
        let row = j * (2 * nu - j);
        let (triangle, vertices, gw) = if up {
            (
                f * nu * nu + row + 2 * i,
                [g(i, j), g(i + 1, j), g(i, j + 1)],
                [1.0 - fx - fy, fx, fy],
            )
        } else {
            (
                f * nu * nu + row + 2 * i + 1,
                [g(i + 1, j), g(i + 1, j + 1), g(i, j + 1)],
                [1.0 - fy, fx + fy - 1.0, 1.0 - fx],
            )
        };
        let weights = match weights {
            Weights::Gnomonic => normalise(gw.map(|w| w.max(0.0))),
            Weights::Area => {
                let v = vertices.map(|k| self.vertices[k as usize]);
                normalise([
                    area(u, v[1], v[2]),
                    area(v[0], u, v[2]),
                    area(v[0], v[1], u),
                ])
            }
        };
        Ok(Location {
            triangle: triangle as u32,
            vertices,
            weights,
        })
    }

    /// The function of `values` (one per vertex) at direction `d`: `Σ ω_i v_i` over the
    /// triangle that holds `d`. Errors: a wrong number of values, a zero or non-finite `d`.
    pub fn query(&self, values: &[f32], d: Vec3, weights: Weights) -> Result<f32, Error> {
        self.check(values)?;
        Ok(self.locate(d, weights)?.interpolate(values))
    }

    /// Checks that `values` has one entry per vertex.
    pub fn check(&self, values: &[f32]) -> Result<(), Error> {
        if values.len() != self.vertices.len() {
            return Err(Error::OutOfRange {
                what: "number of values",
                value: values.len() as f32,
                min: self.vertices.len() as f32,
                max: self.vertices.len() as f32,
            });
        }
        Ok(())
    }

    /// The base faces' vertices (for tests and the SIMD twin).
    pub fn base_faces(&self) -> &[[Vec3; 3]; 20] {
        &self.faces
    }

    /// Per base face `[A, B, C]`, the plane normals `[B×C, C×A, A×B]` whose dot products
    /// with a direction are its unnormalised gnomonic barycentrics (for the SIMD twin).
    pub fn face_planes(&self) -> &[[Vec3; 3]; 20] {
        &self.cross
    }

    /// The base face that holds the unit direction `u`: the octant face of `u`'s signs (bit 0:
    /// x < 0, bit 1: y < 0, bit 2: z < 0), or its neighbour across the canonical edge whose
    /// plane `|u|` is farthest behind (at most one is behind inside an octant, up to
    /// rounding on the face's corners, where both faces hold `u`).
    pub fn base_face(&self, u: Vec3) -> usize {
        let a = u.abs();
        let o = (u.x.is_sign_negative() as usize)
            | (u.y.is_sign_negative() as usize) << 1
            | (u.z.is_sign_negative() as usize) << 2;
        let mut region = 0;
        let mut worst = 0.0f32;
        for (k, e) in OCTANT_EDGES.iter().enumerate() {
            let t = a.dot(*e);
            if t < worst {
                worst = t;
                region = k + 1;
            }
        }
        self.octant_face(o, region)
    }

    /// The base face of octant `o` (bit 0: x < 0, bit 1: y < 0, bit 2: z < 0) in region `r`
    /// (0: the octant's own face, `k + 1`: across canonical edge `k` of [`OCTANT_EDGES`]), as
    /// [`Self::base_face`] picks them (for the SIMD twin, which finds the region lane-wise).
    /// Both indices are taken modulo their range.
    pub fn octant_face(&self, o: usize, r: usize) -> usize {
        self.octant[o & 7][r & 3] as usize
    }

    /// The table of the WGSL twin (`wgsl::CP_QUERY`, binding 3): `[level, weights (0 area,
    /// 1 gnomonic), V]`, [`OCTANT_EDGES`] (9), the face planes (20 × 9), the octant table
    /// (8 × 4), the grid (20 × (2^L + 1)², −1 outside each face's triangle), the vertices (3V)
    /// and `values` (V); integers as `f32` (all below 2²⁴, exact). Errors: a wrong number of values.
    pub fn gpu_table(&self, values: &[f32], weights: Weights) -> Result<Vec<f32>, Error> {
        self.check(values)?;
        let nv = self.vertices.len();
        let mut t = Vec::with_capacity(224 + self.grid.len() + 4 * nv);
        t.extend([
            self.level as f32,
            (weights == Weights::Gnomonic) as u32 as f32,
            nv as f32,
        ]);
        t.extend(OCTANT_EDGES.iter().flat_map(|e| [e.x, e.y, e.z]));
        t.extend(self.cross.iter().flatten().flat_map(|e| [e.x, e.y, e.z]));
        t.extend(self.octant.iter().flatten().map(|f| f32::from(*f)));
        t.extend(
            self.grid
                .iter()
                .map(|g| if *g == u32::MAX { -1.0 } else { *g as f32 }),
        );
        t.extend(self.vertices.iter().flat_map(|v| [v.x, v.y, v.z]));
        t.extend_from_slice(values);
        Ok(t)
    }

    /// The vertex at grid point `(i, j)` (`i + j ≤ 2^L`) of base face `f`, or `u32::MAX`
    /// outside the grid.
    pub fn grid_vertex(&self, f: usize, i: usize, j: usize) -> u32 {
        let side = (1usize << self.level) + 1;
        if f >= 20 || i >= side || j >= side {
            return u32::MAX;
        }
        self.grid[f * side * side + j * side + i]
    }

    /// One direction against many functions (the direction-driven transport of the paper's
    /// section 3.5 shares the weights along a ray): `out[k]` is the function of
    /// `values[k·V..(k + 1)·V]` at `d`, `V` the vertex count. Located once.
    /// Errors: `values.len() != out.len()·V`, a zero or non-finite `d`.
    pub fn query_many(
        &self,
        values: &[f32],
        d: Vec3,
        weights: Weights,
        out: &mut [f32],
    ) -> Result<(), Error> {
        let nv = self.vertices.len();
        if values.len() != out.len() * nv {
            return Err(Error::OutOfRange {
                what: "number of values",
                value: values.len() as f32,
                min: (out.len() * nv) as f32,
                max: (out.len() * nv) as f32,
            });
        }
        let l = self.locate(d, weights)?;
        for (o, f) in out.iter_mut().zip(values.chunks_exact(nv)) {
            *o = l.interpolate(f);
        }
        Ok(())
    }
}

impl Location {
    /// `Σ ω_i v_i` for one value per vertex (`values` indexed by vertex; an index past its
    /// end reads 0).
    pub fn interpolate(&self, values: &[f32]) -> f32 {
        let v = |k: usize| {
            values
                .get(self.vertices[k] as usize)
                .copied()
                .unwrap_or(0.0)
        };
        self.weights[0] * v(0) + self.weights[1] * v(1) + self.weights[2] * v(2)
    }
}

/// The canonical edge normals `P×Q, Q×R, R×P` of the first octant's face, unnormalised
/// (only the sign of the dot product matters): a direction `|d|` (componentwise absolute
/// value) is across edge `k` where its dot product with entry `k` is negative.
pub const OCTANT_EDGES: [Vec3; 3] = {
    // P=(0,1,φ), Q=(φ,0,1), R=(1,φ,0) unnormalised; φ = 1.6180339887.
    let f = 1.618_034_f32;
    [
        Vec3::new(1.0, f * f, -f), // P×Q = (1·1−φ·0, φ·φ−0·1, 0·0−1·φ)
        Vec3::new(-f, 1.0, f * f), // Q×R = (0·0−1·φ, 1·1−φ·0, φ·φ−0·1)
        Vec3::new(f * f, -f, 1.0), // R×P = (φ·φ−0·1, 0·0−1·φ, 1·1−φ·0)
    ]
};

/// `d` normalised, robust to huge and subnormal lengths (scaled by its largest component
/// first).
fn unit(d: Vec3) -> Result<Vec3, Error> {
    if !d.is_finite() {
        return Err(Error::NonFinite { what: "direction" });
    }
    let m = d.abs().max_element();
    if m == 0.0 {
        return Err(Error::ZeroVector { what: "direction" });
    }
    let s = d / m;
    Ok(s / math::sqrtf(s.length_squared()))
}

/// Twice the solid angle of the spherical triangle `(a, b, c)` of unit vectors, halved:
/// `E = 2·atan2(det, 1 + a·b + b·c + c·a)` with `det = a·(b×c)` taken as
/// `(b−a)·((c−a)×a)`, which is the same by multilinearity and exact to a few ulps of the
/// result for small triangles. Clamped at 0 (a direction a rounding error outside).
fn area(a: Vec3, b: Vec3, c: Vec3) -> f32 {
    let det = (b - a).dot((c - a).cross(a));
    let den = 1.0 + a.dot(b) + b.dot(c) + c.dot(a);
    2.0 * math::atan2f(det.max(0.0), den)
}

fn normalise(w: [f32; 3]) -> [f32; 3] {
    let s = w[0] + w[1] + w[2];
    if s > 0.0 {
        w.map(|x| x / s)
    } else {
        [1.0 / 3.0; 3]
    }
}

type Adjacency = (Vec<[u32; 3]>, Vec<u32>, Vec<u32>);

fn adjacency(nv: usize, triangles: &[[u32; 3]]) -> Adjacency {
    // Directed edges (from, to) → (triangle, opposite vertex slot); the twin is (to, from).
    let mut edges: Vec<(u32, u32, u32, u8)> = Vec::with_capacity(triangles.len() * 3);
    for (t, v) in triangles.iter().enumerate() {
        for k in 0..3 {
            edges.push((v[(k + 1) % 3], v[(k + 2) % 3], t as u32, k as u8));
        }
    }
    edges.sort_unstable();
    let mut neighbours = vec![[u32::MAX; 3]; triangles.len()];
    for &(a, b, t, k) in &edges {
        if let Ok(i) = edges.binary_search_by(|e| (e.0, e.1).cmp(&(b, a))) {
            neighbours[t as usize][k as usize] = edges[i].2;
        }
    }
    // One-ring: the targets of the directed edges from each vertex, sorted.
    let mut ring_start = Vec::with_capacity(nv + 1);
    let mut ring = Vec::with_capacity(edges.len());
    let mut e = 0;
    for v in 0..nv as u32 {
        ring_start.push(ring.len() as u32);
        while e < edges.len() && edges[e].0 == v {
            ring.push(edges[e].1);
            e += 1;
        }
    }
    ring_start.push(ring.len() as u32);
    (neighbours, ring_start, ring)
}

#[cfg(test)]
mod tests {
    use super::*;
    use steradian_reference::cp as reference;

    fn rng(seed: u64) -> impl FnMut() -> f32 {
        let mut s = seed;
        move || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 40) as f32) / (1u64 << 24) as f32 * 2.0 - 1.0
        }
    }

    fn dirs(n: usize, seed: u64) -> Vec<Vec3> {
        let mut r = rng(seed);
        (0..n)
            .map(|_| {
                loop {
                    let v = Vec3::new(r(), r(), r());
                    if v.length_squared() > 1e-3 && v.length_squared() <= 1.0 {
                        break v;
                    }
                }
            })
            .collect()
    }

    fn to64(v: Vec3) -> [f64; 3] {
        [v.x as f64, v.y as f64, v.z as f64]
    }

    /// Weight of every vertex of a location, for comparing locations that chose different
    /// triangles on a shared edge.
    fn spread(l: &Location) -> Vec<(u32, f64)> {
        let mut v: Vec<(u32, f64)> = l
            .vertices
            .iter()
            .zip(l.weights)
            .filter(|(_, w)| *w > 1e-7)
            .map(|(v, w)| (*v, w as f64))
            .collect();
        v.sort_by_key(|p| p.0);
        v
    }

    /// Largest difference of the weight given to any vertex by two locations.
    fn gap(a: &Location, b: &Location) -> f64 {
        let (a, b) = (spread(a), spread(b));
        let w = |s: &[(u32, f64)], v: u32| s.iter().find(|p| p.0 == v).map_or(0.0, |p| p.1);
        a.iter()
            .chain(&b)
            .map(|p| (w(&a, p.0) - w(&b, p.0)).abs())
            .fold(0.0, f64::max)
    }

    #[test]
    fn counts_adjacency_and_rings() {
        for level in 0..=MAX_LEVEL {
            let m = Icosphere::new(level).unwrap();
            let n = 1usize << level;
            assert_eq!(m.vertices().len(), 10 * n * n + 2, "level {level}");
            assert_eq!(m.triangles().len(), 20 * n * n);
            assert!(m.vertices().iter().all(|v| (v.length() - 1.0).abs() < 1e-6));
            for (t, nb) in m.triangle_neighbours().iter().enumerate() {
                for (k, o) in nb.iter().enumerate() {
                    assert!((*o as usize) < m.triangles().len(), "triangle {t} edge {k}");
                    assert!(m.triangle_neighbours()[*o as usize].contains(&(t as u32)));
                }
            }
            let degrees: Vec<usize> = (0..m.vertices().len())
                .map(|v| m.vertex_neighbours(v).len())
                .collect();
            assert_eq!(degrees.iter().filter(|d| **d == 5).count(), 12);
            assert!(degrees.iter().all(|d| *d == 5 || *d == 6));
            // Every triangle counter-clockwise seen from outside.
            for t in m.triangles() {
                let v = t.map(|k| m.vertices()[k as usize]);
                assert!(v[0].dot(v[1].cross(v[2])) > 0.0);
            }
        }
        assert!(Icosphere::new(5).is_err());
    }

    #[test]
    fn levels_nest_and_are_deterministic() {
        let (a, b) = (Icosphere::new(2).unwrap(), Icosphere::new(3).unwrap());
        for v in a.vertices() {
            assert!(b.vertices().iter().any(|w| (*v - *w).length() < 1e-6));
        }
        assert_eq!(Icosphere::new(3).unwrap().vertices(), b.vertices());
    }

    #[test]
    fn location_matches_the_brute_force_scan() {
        for level in 0..=3 {
            let m = Icosphere::new(level).unwrap();
            let v64: Vec<[f64; 3]> = m.vertices().iter().map(|v| to64(*v)).collect();
            let mut worst = 0.0f64;
            for d in dirs(400, 7 + level as u64) {
                let l = m.locate(d, Weights::Area).unwrap();
                let (t, w) = reference::locate(&v64, m.triangles(), to64(d));
                let r = Location {
                    triangle: t as u32,
                    vertices: m.triangles()[t],
                    weights: w.map(|x| x as f32),
                };
                worst = worst.max(gap(&l, &r));
            }
            assert!(worst < 2e-6, "level {level}: weight error {worst}");
        }
    }

    #[test]
    fn area_weights_are_stable_on_level_4_triangles() {
        // Against f64 areas of the same triangle (the VO-S form on edge differences keeps
        // the relative precision of the sub-areas; Girard's formula in f32 would not).
        let m = Icosphere::new(4).unwrap();
        let mut worst = 0.0f64;
        for d in dirs(5000, 3) {
            let l = m.locate(d, Weights::Area).unwrap();
            let u = to64(d.normalize());
            let v = l.vertices.map(|k| to64(m.vertices()[k as usize]));
            let a = [
                reference::triangle_area(u, v[1], v[2]),
                reference::triangle_area(v[0], u, v[2]),
                reference::triangle_area(v[0], v[1], u),
            ];
            let s = a[0] + a[1] + a[2];
            for (w, ak) in l.weights.iter().zip(a) {
                worst = worst.max((*w as f64 - ak / s).abs());
            }
            let sum: f32 = l.weights.iter().sum();
            assert!((sum - 1.0).abs() < 1e-6 && l.weights.iter().all(|w| *w >= 0.0));
        }
        assert!(worst < WEIGHT_ABS_ERROR as f64, "weight error {worst}");
        std::println!("level-4 area weight error {worst:.2e}");
    }

    #[test]
    fn vertices_reproduce_their_values_and_edges_are_shared() {
        for level in 0..=MAX_LEVEL {
            let m = Icosphere::new(level).unwrap();
            for (k, v) in m.vertices().iter().enumerate() {
                for w in [Weights::Area, Weights::Gnomonic] {
                    let l = m.locate(*v, w).unwrap();
                    let at = l.vertices.iter().position(|x| *x as usize == k);
                    let at = at.unwrap_or_else(|| panic!("level {level} vertex {k} not in {l:?}"));
                    assert!(
                        (l.weights[at] - 1.0).abs() < 2e-5,
                        "level {level} vertex {k}: {l:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn hard_directions_poles_axes_lengths_and_bad_input() {
        let m = Icosphere::new(4).unwrap();
        let mut cases = vec![];
        for axis in [Vec3::X, Vec3::Y, Vec3::Z] {
            cases.push(axis);
            cases.push(-axis);
        }
        // Base-edge midpoints and face centres (ties between faces), huge and tiny lengths.
        for f in m.base_faces() {
            cases.push(f[0] + f[1]);
            cases.push(f[0] + f[1] + f[2]);
        }
        for d in cases.clone() {
            cases.push(d * 1e38);
            cases.push(d * 1e-40);
            cases.push(Vec3::new(d.x, d.y, -0.0 * d.z + d.z));
        }
        let v64: Vec<[f64; 3]> = m.vertices().iter().map(|v| to64(*v)).collect();
        for d in cases {
            for w in [Weights::Area, Weights::Gnomonic] {
                let l = m.locate(d, w).unwrap();
                assert!(
                    l.weights.iter().all(|x| (0.0..=1.0).contains(x)),
                    "{d}: {l:?}"
                );
                assert!((l.weights.iter().sum::<f32>() - 1.0).abs() < 1e-6);
            }
            let l = m.locate(d, Weights::Area).unwrap();
            let (t, w) = reference::locate(&v64, m.triangles(), to64(d / d.abs().max_element()));
            let r = Location {
                triangle: t as u32,
                vertices: m.triangles()[t],
                weights: w.map(|x| x as f32),
            };
            assert!(gap(&l, &r) < 1e-5, "{d}: {l:?} vs {r:?}");
        }
        for bad in [
            Vec3::ZERO,
            Vec3::splat(f32::NAN),
            Vec3::new(f32::INFINITY, 0.0, 1.0),
        ] {
            assert!(m.locate(bad, Weights::Area).is_err());
        }
        assert!(m.query(&[0.0; 3], Vec3::Z, Weights::Area).is_err());
    }

    #[test]
    fn gnomonic_weights_are_continuous_and_close_to_area_weights() {
        // The two interpolants of a random function in [−1, 1] differ by < 0.05; points
        // 2e-4 rad apart across an edge differ by < 2e-2 under gnomonic weights (no jump,
        // only the slope over the gap).
        let m = Icosphere::new(4).unwrap();
        let mut r = rng(11);
        let values: Vec<f32> = (0..m.vertices().len()).map(|_| r()).collect();
        let mut diff = 0.0f32;
        for d in dirs(2000, 5) {
            let a = m.query(&values, d, Weights::Area).unwrap();
            let g = m.query(&values, d, Weights::Gnomonic).unwrap();
            diff = diff.max((a - g).abs());
        }
        assert!(diff < 0.05, "area vs gnomonic {diff}");
        for t in m.triangles().iter().take(200) {
            let (p, q) = (m.vertices()[t[0] as usize], m.vertices()[t[1] as usize]);
            let mid = (p + q).normalize();
            let out = p.cross(q).normalize() * 1e-4;
            let a = m.query(&values, mid + out, Weights::Gnomonic).unwrap();
            let b = m.query(&values, mid - out, Weights::Gnomonic).unwrap();
            assert!((a - b).abs() < 2e-2, "{a} vs {b}");
        }
    }

    #[test]
    fn query_many_equals_one_query_per_function() {
        let m = Icosphere::new(2).unwrap();
        let nv = m.vertices().len();
        let values: Vec<f32> = (0..3 * nv).map(|k| (k as f32 * 0.37).sin()).collect();
        let d = Vec3::new(0.3, -0.8, 0.2);
        let mut out = [0.0f32; 3];
        m.query_many(&values, d, Weights::Area, &mut out).unwrap();
        for (k, o) in out.iter().enumerate() {
            let one = m
                .query(&values[k * nv..(k + 1) * nv], d, Weights::Area)
                .unwrap();
            assert_eq!(*o, one);
        }
        assert!(
            m.query_many(&values[1..], d, Weights::Area, &mut out)
                .is_err()
        );
        assert!(
            m.query_many(&values, Vec3::ZERO, Weights::Area, &mut out)
                .is_err()
        );
    }
}
