//! Shading on a lattice of pixels, interpolated between: what a method computes where its
//! result varies slowly across a surface (the `hvl` method's indirect light) at every
//! `s`-th pixel across and down, and what each other pixel takes from its cell's corners.
//!
//! **The rule** ([`interpolate_cell`]). The lattice's nodes are the pixels `(a·s, b·s)`,
//! the last column and row clamped to the image. A pixel takes the bilinear
//! interpolation, by pixel distance, of those corners of its cell that see its own object
//! with a normal within [`NORMAL_COS`] of its own, renormalised over them, when they hold
//! at least [`MIN_WEIGHT`] of its weight; any other pixel (at an object's edge or a
//! crease, beside a light or the environment) computes its own. The interpolation is
//! exact where the shaded value is bilinear across the cell (unit test); a method's plan
//! chooses `s` by what it costs elsewhere ([`strided_probes`]), and `s = 1` computes every
//! pixel.
//!
//! Not for the `rsl` method's environment light, where it was tried: on `environment` the
//! city's sun casts sharp shadows on the floor, and the probes' estimate at a spacing of 2
//! was several times a plan's share of the default target.

use std::collections::HashMap;

use rayon::prelude::*;

use super::{Rgb, Scene, Seen, ShadingPoint};

/// Smallest cosine between the normals of a pixel and a lattice node it interpolates from.
pub const NORMAL_COS: f64 = 0.95;

/// Least bilinear weight of a pixel's usable lattice corners.
pub const MIN_WEIGHT: f64 = 0.5;

/// The lattice spacings a plan tries, coarsest first (1 is every pixel).
pub const STRIDE_CANDIDATES: [usize; 4] = [4, 3, 2, 1];

/// The shaded nodes of a lattice over a scene's image.
pub struct Lattice {
    stride: usize,
    width: usize,
    height: usize,
    columns: usize,
    nodes: Vec<Option<(ShadingPoint, Rgb)>>,
}

impl Lattice {
    /// The lattice of spacing `stride` (at least 1) over `scene`'s image, the surface point
    /// each node sees shaded by `shade(state, point)` in parallel (each task with a fresh
    /// `new_state()`: scratch buffers).
    pub fn build<S>(
        scene: &Scene,
        stride: usize,
        new_state: impl Fn() -> S + Sync + Send,
        shade: impl Fn(&mut S, &ShadingPoint) -> Rgb + Sync,
    ) -> Lattice {
        let cam = scene.camera;
        let (w, h) = (cam.width as usize, cam.height as usize);
        let s = stride.max(1);
        let (columns, rows) = ((w - 1).div_ceil(s) + 1, (h - 1).div_ceil(s) + 1);
        let nodes = (0..columns * rows)
            .into_par_iter()
            .map_init(new_state, |state, k| {
                let (i, j) = (
                    ((k % columns) * s).min(w - 1),
                    ((k / columns) * s).min(h - 1),
                );
                match scene.see(&cam.centre_ray(i as u32, j as u32)) {
                    Seen::Surface(p) => Some((p, shade(state, &p))),
                    Seen::Radiance(_) => None,
                }
            })
            .collect();
        Lattice {
            stride: s,
            width: w,
            height: h,
            columns,
            nodes,
        }
    }

    /// The value at pixel `(i, j)`, which sees `p`, interpolated from its cell's corners;
    /// `None` where they do not allow it ([`interpolate_cell`]).
    pub fn interpolate(&self, i: usize, j: usize, p: &ShadingPoint) -> Option<Rgb> {
        let (s, w, h) = (self.stride, self.width, self.height);
        interpolate_cell(s, w, h, i, j, p, |a, b| {
            self.nodes.get(b * self.columns + a).copied().flatten()
        })
    }
}

/// The rule of the module docs for pixel `(i, j)` (seeing `p`) of a `w × h` image at
/// spacing `s`, the node at lattice column `a` and row `b` (pixel
/// `(min(a·s, w − 1), min(b·s, h − 1))`) given by `node(a, b)`: its surface point and
/// value, `None` where it sees no surface.
pub fn interpolate_cell(
    s: usize,
    w: usize,
    h: usize,
    i: usize,
    j: usize,
    p: &ShadingPoint,
    mut node: impl FnMut(usize, usize) -> Option<(ShadingPoint, Rgb)>,
) -> Option<Rgb> {
    let axis = |x: usize, n: usize| {
        let a = x / s;
        let (x0, x1) = (a * s, ((a + 1) * s).min(n - 1));
        let f = if x1 > x0 {
            (x - x0) as f64 / (x1 - x0) as f64
        } else {
            0.0
        };
        (a, f)
    };
    let (a, fx) = axis(i, w);
    let (b, fy) = axis(j, h);
    let mut out = [0.0; 3];
    let mut total = 0.0;
    for (da, wx) in [(0, 1.0 - fx), (1, fx)] {
        for (db, wy) in [(0, 1.0 - fy), (1, fy)] {
            let wgt = wx * wy;
            if wgt == 0.0 {
                continue;
            }
            let Some((q, v)) = node(a + da, b + db) else {
                continue;
            };
            if q.object != p.object || q.n.dot(p.n) < NORMAL_COS {
                continue;
            }
            total += wgt;
            for k in 0..3 {
                out[k] += wgt * v[k];
            }
        }
    }
    (total >= MIN_WEIGHT).then(|| out.map(|v| v / total))
}

/// The probe pixels ([`super::probe_pixels`]) shaded as a render at each spacing of
/// [`STRIDE_CANDIDATES`] shades them, for a plan's [`super::plan_choice`]: each probe's
/// cell corners shaded by `shade` (each pixel once) and the rule applied, the probe's own value
/// (`own[k]`, `shade` of probe `k`) where the rule refuses and at spacing 1; `base[k]` (a
/// part every spacing computes alike, such as direct light) added to each.
pub fn strided_probes(
    scene: &Scene,
    probes: &[(usize, usize, ShadingPoint)],
    own: &[Rgb],
    base: &[Rgb],
    mut shade: impl FnMut(&ShadingPoint) -> Rgb,
) -> Vec<Vec<Rgb>> {
    let cam = scene.camera;
    let (w, h) = (cam.width as usize, cam.height as usize);
    // Every pixel shaded once, whichever spacings and probes share it as a corner (the
    // probes themselves with their own values).
    let mut seen: HashMap<(usize, usize), Option<(ShadingPoint, Rgb)>> = probes
        .iter()
        .zip(own)
        .map(|(&(i, j, p), &v)| ((i, j), Some((p, v))))
        .collect();
    STRIDE_CANDIDATES
        .iter()
        .map(|&s| {
            probes
                .iter()
                .zip(own.iter().zip(base))
                .map(|(&(i, j, p), (&mine, b))| {
                    let v = if s == 1 {
                        mine
                    } else {
                        interpolate_cell(s, w, h, i, j, &p, |a, bb| {
                            let (x, y) = ((a * s).min(w - 1), (bb * s).min(h - 1));
                            *seen.entry((x, y)).or_insert_with(|| {
                                match scene.see(&cam.centre_ray(x as u32, y as u32)) {
                                    Seen::Surface(q) => Some((q, shade(&q))),
                                    Seen::Radiance(_) => None,
                                }
                            })
                        })
                        .unwrap_or(mine)
                    };
                    [v[0] + b[0], v[1] + b[1], v[2] + b[2]]
                })
                .collect()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    fn point(object: usize, n: DVec3) -> ShadingPoint {
        ShadingPoint {
            object,
            material: 0,
            x: DVec3::ZERO,
            n,
            wo: DVec3::Z,
        }
    }

    /// The rule is exact on a field bilinear in the pixel coordinates (every pixel of a
    /// 23 × 17 image at spacings 2–5, the last column and row clamped), and takes a
    /// corner's value at the corner itself.
    #[test]
    fn interpolation_is_exact_on_a_bilinear_field() {
        let (w, h) = (23, 17);
        let field = |x: usize, y: usize| {
            let (x, y) = (x as f64, y as f64);
            [
                1.0 + 0.5 * x - 0.25 * y + 0.01 * x * y,
                2.0 - 0.1 * x,
                0.3 * y,
            ]
        };
        let p = point(3, DVec3::Z);
        for s in 2..=5 {
            for j in 0..h {
                for i in 0..w {
                    let got = interpolate_cell(s, w, h, i, j, &p, |a, b| {
                        let (x, y) = ((a * s).min(w - 1), (b * s).min(h - 1));
                        Some((p, field(x, y)))
                    })
                    .unwrap();
                    let want = field(i, j);
                    for c in 0..3 {
                        assert!(
                            (got[c] - want[c]).abs() < 1e-12,
                            "s {s} ({i}, {j}): {got:?} {want:?}"
                        );
                    }
                }
            }
        }
    }

    /// Corners on another object, with a normal beyond `NORMAL_COS` or seeing no surface
    /// are left out and the rest renormalised; under `MIN_WEIGHT` of the weight left the
    /// pixel computes its own (`None`).
    #[test]
    fn interpolation_leaves_out_other_surfaces() {
        let p = point(1, DVec3::Z);
        let tilted = DVec3::new(0.4, 0.0, 1.0).normalize(); // cos 0.93
        // Pixel (1, 1) of a 5 × 5 image at spacing 4: corner weights 9/16, 3/16, 3/16, 1/16.
        let run = |bad: &[(usize, usize)], how: u8| {
            interpolate_cell(4, 5, 5, 1, 1, &p, |a, b| {
                let v = [(1 + a + 2 * b) as f64; 3];
                if !bad.contains(&(a, b)) {
                    return Some((p, v));
                }
                match how {
                    0 => Some((point(2, DVec3::Z), v)),
                    1 => Some((point(1, tilted), v)),
                    _ => None,
                }
            })
        };
        let all = run(&[], 0).unwrap()[0];
        assert!((all - (9.0 * 1.0 + 3.0 * 2.0 + 3.0 * 3.0 + 4.0) / 16.0).abs() < 1e-12);
        for how in 0..3 {
            // Without the far corner (1/16): the other three renormalised over 15/16.
            let v = run(&[(1, 1)], how).unwrap()[0];
            assert!((v - (9.0 + 6.0 + 9.0) / 15.0).abs() < 1e-12, "{how}: {v}");
            // Without the near corner (9/16): 7/16 left, under the least weight.
            assert_eq!(run(&[(0, 0)], how), None, "{how}");
        }
    }
}
