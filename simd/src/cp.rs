//! Control-point queries, 8 (or 16) directions at a time (mirrors
//! `steradian_core::cp::mesh::Icosphere::query`).
//!
//! [`query_slices`] evaluates one function (one value per vertex) at many directions. The
//! arithmetic runs on lanes with the scalar kernel's operations in its order: the
//! normalisation by the largest component, the gnomonic barycentrics on the base face's
//! plane, the grid cell (`floor` written as `−ceil(−x)`, exact), the gnomonic weights, and
//! for the area weights the Van Oosterom–Strackee triple products and denominators. `wide`
//! has no gather: the region (which canonical edge plane `|u|` is behind) is found
//! lane-wise, then one pass per lane reads the face (`Icosphere::octant_face`) and its plane
//! normals, and a second the three vertices, their values and positions.
//!
//! - [`Weights::Gnomonic`]: only correctly rounded operations, so every lane is
//!   **bit-identical** to the scalar query.
//! - [`Weights::Area`]: the three `atan2` are wide's polynomial, not the standard
//!   library's; each lane is within [`AREA_TOL`]`·max|v_i|` (over the triangle's three
//!   values) of the scalar query (asserted lane by lane by the tests).
//!
//! A lane whose direction is zero or not finite (where the scalar query is an error) is NaN.

use steradian_core::cp::{Icosphere, OCTANT_EDGES, Weights};
use steradian_core::{Error, Vec3};

use crate::lanes::{ColumnKernel, Lanes, SliceVec, drive, max_num};

/// Bound on `|SIMD − scalar| / max|v_i|` for [`Weights::Area`] (wide's `atan2` against
/// the standard library's, a few ulps of each weight; asserted by the lane tests).
pub const AREA_TOL: f32 = 2e-6;

#[inline(always)]
fn dot<W: Lanes>(a: [W; 3], b: [W; 3]) -> W {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline(always)]
fn sub<W: Lanes>(a: [W; 3], b: [W; 3]) -> [W; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline(always)]
fn cross<W: Lanes>(a: [W; 3], b: [W; 3]) -> [W; 3] {
    [
        a[1] * b[2] - b[1] * a[2],
        a[2] * b[0] - b[2] * a[0],
        a[0] * b[1] - b[0] * a[1],
    ]
}

/// The scalar `area`: `2·atan2(max(det, 0), 1 + a·b + b·c + c·a)`.
#[inline(always)]
fn area<W: Lanes>(a: [W; 3], b: [W; 3], c: [W; 3]) -> W {
    let det = dot(sub(b, a), cross(sub(c, a), a));
    let den = W::splat(1.0) + dot(a, b) + dot(b, c) + dot(c, a);
    W::splat(2.0) * max_num(det, W::splat(0.0)).atan2(den)
}

/// The scalar `normalise`: `w / Σw`, or `1/3` each when the sum is not positive.
#[inline(always)]
fn normalise<W: Lanes>(w: [W; 3]) -> [W; 3] {
    let s = w[0] + w[1] + w[2];
    let pos = s.gt(W::splat(0.0));
    w.map(|x| pos.select(x / s, W::splat(1.0 / 3.0)))
}

struct Query<'a> {
    mesh: &'a Icosphere,
    values: &'a [f32],
    weights: Weights,
}

impl ColumnKernel<3, 1> for Query<'_> {
    const PADS: [f32; 3] = [0.0, 0.0, 1.0];

    #[inline(always)]
    fn apply<W: Lanes>(&self, [x, y, z]: [W; 3]) -> ([W; 1], W) {
        let zero = W::splat(0.0);
        let one = W::splat(1.0);
        // Normalisation (scalar `unit`): by the largest |component|, then by the length.
        let (ax, ay, az) = (x.abs(), y.abs(), z.abs());
        let inf = W::splat(f32::INFINITY);
        let finite = ax.lt(inf) & ay.lt(inf) & az.lt(inf);
        let m = ax.fast_max(ay).fast_max(az);
        let bad = !(finite & m.gt(zero));
        let m = bad.select(one, m);
        let s = [x / m, y / m, z / m];
        let len = dot(s, s).sqrt();
        let u = s.map(|c| bad.select(one, c / len));
        // The region, lane-wise: the scalar `base_face`'s running minimum over the three
        // canonical edge planes of |u|.
        let a = u.map(|c| c.abs());
        let mut region = zero;
        let mut worst = zero;
        for (k, e) in OCTANT_EDGES.iter().enumerate() {
            let t = dot(a, [W::splat(e.x), W::splat(e.y), W::splat(e.z)]);
            let m = t.lt(worst);
            region = m.select(W::splat((k + 1) as f32), region);
            worst = m.select(t, worst);
        }
        // Per lane: the octant's sign bits, the face, and its plane normals, in one pass.
        let planes = self.mesh.face_planes();
        let mut face = [0usize; 16];
        let mut pl = [[0.0f32; 16]; 9];
        let (ul, rl) = ([u[0].lanes(), u[1].lanes(), u[2].lanes()], region.lanes());
        for k in 0..W::N {
            let o = (ul[0][k].is_sign_negative() as usize)
                | (ul[1][k].is_sign_negative() as usize) << 1
                | (ul[2][k].is_sign_negative() as usize) << 2;
            let f = self.mesh.octant_face(o, rl[k] as usize);
            face[k] = f;
            for (p, n) in planes[f].iter().enumerate() {
                pl[3 * p][k] = n.x;
                pl[3 * p + 1][k] = n.y;
                pl[3 * p + 2][k] = n.z;
            }
        }
        let plane = |p: usize| -> [W; 3] {
            [
                W::load(&pl[3 * p][..W::N]),
                W::load(&pl[3 * p + 1][..W::N]),
                W::load(&pl[3 * p + 2][..W::N]),
            ]
        };
        let b = [dot(u, plane(0)), dot(u, plane(1)), dot(u, plane(2))];
        let sum = b[0] + b[1] + b[2];
        let nu = 1usize << self.mesh.level();
        let n = W::splat(nu as f32);
        let gx = max_num(b[1] / sum * n, zero);
        let gy = max_num(b[2] / sum * n, zero);
        let top = W::splat((nu - 1) as f32);
        let i = (-(-gx).ceil()).fast_min(top);
        let j = (-(-gy).ceil()).fast_min(top - i);
        let (fx, fy) = (gx - i, gy - j);
        let up = (fx + fy).le(one) | (i + j + one).eq(n);
        // Per lane: the triangle's vertices, their values and (for the area weights) their
        // positions, in one pass.
        let verts = self.mesh.vertices();
        let need_positions = self.weights == Weights::Area;
        let mut vals = [[0.0f32; 16]; 3];
        let mut pos = [[0.0f32; 16]; 9];
        let (il, jl, upl) = (i.lanes(), j.lanes(), up.lanes());
        for k in 0..W::N {
            let (ii, jj) = (il[k] as usize, jl[k] as usize);
            let g = |di: usize, dj: usize| self.mesh.grid_vertex(face[k], ii + di, jj + dj);
            let v = if upl[k].to_bits() != 0 {
                [g(0, 0), g(1, 0), g(0, 1)]
            } else {
                [g(1, 0), g(1, 1), g(0, 1)]
            };
            for (c, id) in v.into_iter().enumerate() {
                vals[c][k] = self.values.get(id as usize).copied().unwrap_or(0.0);
                if need_positions {
                    let p = verts.get(id as usize).copied().unwrap_or(Vec3::Z);
                    pos[3 * c][k] = p.x;
                    pos[3 * c + 1][k] = p.y;
                    pos[3 * c + 2][k] = p.z;
                }
            }
        }
        let w = match self.weights {
            Weights::Gnomonic => normalise([
                max_num(up.select(one - fx - fy, one - fy), zero),
                max_num(up.select(fx, fx + fy - one), zero),
                max_num(up.select(fy, one - fx), zero),
            ]),
            Weights::Area => {
                let at = |c: usize| -> [W; 3] {
                    [
                        W::load(&pos[3 * c][..W::N]),
                        W::load(&pos[3 * c + 1][..W::N]),
                        W::load(&pos[3 * c + 2][..W::N]),
                    ]
                };
                let v = [at(0), at(1), at(2)];
                normalise([
                    area(u, v[1], v[2]),
                    area(v[0], u, v[2]),
                    area(v[0], v[1], u),
                ])
            }
        };
        let val = |c: usize| W::load(&vals[c][..W::N]);
        let r = w[0] * val(0) + w[1] * val(1) + w[2] * val(2);
        ([bad.select(W::splat(f32::NAN), r)], zero)
    }
}

/// The function of `values` (one per vertex of `mesh`) at each direction `(x[k], y[k],
/// z[k])`, into `out[k]`: lane-wise `Icosphere::query`, bit-identical for
/// [`Weights::Gnomonic`] and within [`AREA_TOL`] for [`Weights::Area`]. A zero or
/// non-finite direction gives NaN.
///
/// Errors: a wrong number of values, or columns of different lengths.
pub fn query_slices(
    mesh: &Icosphere,
    values: &[f32],
    weights: Weights,
    x: &[f32],
    y: &[f32],
    z: &[f32],
    out: &mut [f32],
) -> Result<(), Error> {
    mesh.check(values)?;
    let n = out.len();
    if x.len() != n || y.len() != n || z.len() != n {
        return Err(Error::OutOfRange {
            what: "column length",
            value: x.len().max(y.len()).max(z.len()) as f32,
            min: n as f32,
            max: n as f32,
        });
    }
    let k = Query {
        mesh,
        values,
        weights,
    };
    drive::<SliceVec, _, 3, 1>("cp::query_slices", &k, [x, y, z], [out]);
    Ok(())
}
