//! Shading on an adaptive lattice of pixels, interpolated between: what a method computes
//! where its result varies slowly across a surface (the `hvl` method's indirect light) at
//! every `s`-th pixel across and down, more densely where it does not, and what each other
//! pixel takes from its cell's corners.
//!
//! **The rule** ([`interpolate_adaptive`]). The lattice's nodes are first the pixels
//! `(a·s, b·s)`, the last column and row clamped to the image. A cell whose corners are not
//! alike (one sees no surface or another object, a normal lies beyond [`NORMAL_COS`] of
//! another's, or a colour channel spreads by more than [`SPLIT_SPREAD`] of its largest
//! value) is split at its middle pixel along each side longer than [`LEAF_SPACING`], and
//! its parts by the same rule, down to that spacing. A pixel takes the bilinear
//! interpolation, by pixel distance, of those corners of its smallest cell that see its
//! own object with a normal within [`NORMAL_COS`] of its own, renormalised over them, when
//! they hold at least [`MIN_WEIGHT`] of its weight; any other pixel (at an object's edge or
//! a crease, beside a light or the environment) computes its own. The interpolation is
//! exact where the shaded value is bilinear across a cell (unit test); a method's plan
//! chooses `s` by what it costs elsewhere ([`strided_probes`]), and `s = 1` computes every
//! pixel.
//!
//! Why split: a plain lattice interpolated pixels near an object's edge from the far
//! corners of their cell, and missed the indirect light's contact shadows inside a cell.
//! The report's `room` rows give the split lattice's error and time at each spacing beside
//! every pixel computed.
//!
//! Not for the `rsl` method's environment light, where a plain lattice was tried: on
//! `environment` the city's sun casts sharp shadows on the floor, and the probes' estimate
//! at a spacing of 2 was several times a plan's share of the default target.

use std::collections::HashMap;

use rayon::prelude::*;

use super::{Rgb, Scene, Seen, ShadingPoint};

/// Smallest cosine between the normals of a pixel and a lattice node it interpolates from.
pub const NORMAL_COS: f64 = 0.95;

/// Least bilinear weight of a pixel's usable lattice corners.
pub const MIN_WEIGHT: f64 = 0.5;

/// Largest spread of a colour channel over a cell's corners, as a fraction of the channel's
/// largest corner value, for the cell to stay whole (chosen on `room`: smaller spreads
/// split more cells for little less error).
pub const SPLIT_SPREAD: f64 = 0.5;

/// The spacing cells are split down to (split to single pixels, an object's edge costs
/// every pixel along it; pixels the rule refuses compute their own anyway).
pub const LEAF_SPACING: usize = 2;

/// The lattice spacings a plan tries, coarsest first (1 is every pixel): powers of two, so
/// that splits land on [`LEAF_SPACING`].
pub const STRIDE_CANDIDATES: [usize; 3] = [4, 2, 1];

/// A node: the surface point its pixel centre sees and its value; `None` where it sees no
/// surface.
pub type Node = Option<(ShadingPoint, Rgb)>;

/// A cell of the lattice: its first and last pixel column and row (`x0 ≤ x1`, `y0 ≤ y1`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Cell {
    x: (usize, usize),
    y: (usize, usize),
}

impl Cell {
    /// The spacing-`s` cell of pixel `(i, j)` in a `w × h` image.
    fn of(s: usize, w: usize, h: usize, i: usize, j: usize) -> Cell {
        let axis = |x: usize, n: usize| {
            let a = x / s * s;
            (a, (a + s).min(n - 1))
        };
        Cell {
            x: axis(i, w),
            y: axis(j, h),
        }
    }

    /// Its corners' pixels, top-left, top-right, bottom-left, bottom-right.
    fn corners(self) -> [(usize, usize); 4] {
        let Cell {
            x: (x0, x1),
            y: (y0, y1),
        } = self;
        [(x0, y0), (x1, y0), (x0, y1), (x1, y1)]
    }

    /// Whether it is not split (no side longer than [`LEAF_SPACING`]).
    fn is_leaf(self) -> bool {
        self.x.1 - self.x.0 <= LEAF_SPACING && self.y.1 - self.y.0 <= LEAF_SPACING
    }

    /// Its halves (quarters) along each side longer than [`LEAF_SPACING`], split at the
    /// middle pixel, which both halves share.
    fn children(self) -> impl Iterator<Item = Cell> {
        let halves = |(a, b): (usize, usize)| {
            if b - a <= LEAF_SPACING {
                [Some((a, b)), None]
            } else {
                let m = a + (b - a) / 2;
                [Some((a, m)), Some((m, b))]
            }
        };
        let (xs, ys) = (halves(self.x), halves(self.y));
        ys.into_iter()
            .flatten()
            .flat_map(move |y| xs.into_iter().flatten().map(move |x| Cell { x, y }))
    }

    /// The child holding pixel `(i, j)`: of [`Cell::children`], the last that does (the
    /// later half at the shared middle pixel).
    fn child_of(self, i: usize, j: usize) -> Cell {
        self.children()
            .filter(|c| (c.x.0..=c.x.1).contains(&i) && (c.y.0..=c.y.1).contains(&j))
            .last()
            .unwrap_or(self)
    }
}

/// Whether a cell with these corners is not split: every corner sees the same object, the
/// normals lie within [`NORMAL_COS`] of the first's, and each channel spreads by at most
/// [`SPLIT_SPREAD`] of its largest value.
fn alike(corners: &[Node; 4]) -> bool {
    let Some((first, _)) = corners[0] else {
        return false;
    };
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for c in corners {
        let Some((q, v)) = c else {
            return false;
        };
        if q.object != first.object || q.n.dot(first.n) < NORMAL_COS {
            return false;
        }
        for k in 0..3 {
            lo[k] = lo[k].min(v[k]);
            hi[k] = hi[k].max(v[k]);
        }
    }
    (0..3).all(|k| hi[k] - lo[k] <= SPLIT_SPREAD * hi[k].abs())
}

/// The shaded nodes of an adaptive lattice over a scene's image (module docs).
pub struct Lattice {
    stride: usize,
    width: usize,
    height: usize,
    /// Per pixel, its node where the lattice computed one.
    nodes: Vec<Option<Node>>,
    /// How many nodes it computed.
    pub computed: usize,
}

impl Lattice {
    /// The lattice of spacing `stride` (at least 1) over `scene`'s image, split by the rule
    /// of the module docs, the surface point each node sees shaded by `shade(state, point)`
    /// in parallel, one level of splits at a time (each task with a fresh `new_state()`:
    /// scratch buffers).
    pub fn build<S>(
        scene: &Scene,
        stride: usize,
        new_state: impl Fn() -> S + Sync + Send,
        shade: impl Fn(&mut S, &ShadingPoint) -> Rgb + Sync,
    ) -> Lattice {
        let cam = scene.camera;
        let (w, h) = (cam.width as usize, cam.height as usize);
        let s = stride.max(1);
        let mut nodes: Vec<Option<Node>> = vec![None; w * h];
        let mut cells: Vec<Cell> = (0..h)
            .step_by(s)
            .flat_map(|j| (0..w).step_by(s).map(move |i| Cell::of(s, w, h, i, j)))
            .collect();
        let mut computed = 0;
        loop {
            // The corners of this level's cells not computed yet, each once.
            let mut todo: Vec<(usize, usize)> = cells
                .iter()
                .flat_map(|c| c.corners())
                .filter(|&(x, y)| nodes[y * w + x].is_none())
                .collect();
            todo.sort_unstable_by_key(|&(x, y)| (y, x));
            todo.dedup();
            let shaded: Vec<Node> = todo
                .par_iter()
                .map_init(&new_state, |state, &(x, y)| {
                    match scene.see(&cam.centre_ray(x as u32, y as u32)) {
                        Seen::Surface(p) => Some((p, shade(state, &p))),
                        Seen::Radiance(_) => None,
                    }
                })
                .collect();
            computed += todo.len();
            for (&(x, y), n) in todo.iter().zip(shaded) {
                nodes[y * w + x] = Some(n);
            }
            cells = cells
                .into_iter()
                .filter(|c| {
                    !c.is_leaf() && !alike(&c.corners().map(|(x, y)| nodes[y * w + x].flatten()))
                })
                .flat_map(Cell::children)
                .collect();
            if cells.is_empty() {
                break;
            }
        }
        Lattice {
            stride: s,
            width: w,
            height: h,
            nodes,
            computed,
        }
    }

    /// The value at pixel `(i, j)`, which sees `p`, interpolated from its smallest cell's
    /// corners; `None` where they do not allow it ([`interpolate_adaptive`]).
    pub fn interpolate(&self, i: usize, j: usize, p: &ShadingPoint) -> Option<Rgb> {
        let (s, w, h) = (self.stride, self.width, self.height);
        interpolate_adaptive(s, w, h, i, j, p, |x, y| {
            self.nodes.get(y * w + x).copied().flatten().flatten()
        })
    }
}

/// The rule of the module docs for pixel `(i, j)` (seeing `p`) of a `w × h` image at
/// spacing `s`, the node of pixel `(x, y)` given by `node(x, y)`: from the spacing-`s`
/// cell of the pixel, the cell holding it split while its corners are not alike, then the
/// smallest cell's corners interpolated.
pub fn interpolate_adaptive(
    s: usize,
    w: usize,
    h: usize,
    i: usize,
    j: usize,
    p: &ShadingPoint,
    mut node: impl FnMut(usize, usize) -> Node,
) -> Option<Rgb> {
    let mut cell = Cell::of(s.max(1), w, h, i, j);
    let mut corners = cell.corners().map(|(x, y)| node(x, y));
    while !cell.is_leaf() && !alike(&corners) {
        cell = cell.child_of(i, j);
        corners = cell.corners().map(|(x, y)| node(x, y));
    }
    interpolate_in(cell, i, j, p, &corners)
}

/// Pixel `(i, j)` of `cell`, seeing `p`, from the cell's `corners` (in [`Cell::corners`]'
/// order): the bilinear weights by pixel distance of the corners on `p`'s object with a
/// normal within [`NORMAL_COS`] of `p`'s, renormalised, or `None` under [`MIN_WEIGHT`].
fn interpolate_in(
    cell: Cell,
    i: usize,
    j: usize,
    p: &ShadingPoint,
    corners: &[Node; 4],
) -> Option<Rgb> {
    let weight = |v: usize, (a, b): (usize, usize)| {
        let f = if b > a {
            (v - a) as f64 / (b - a) as f64
        } else {
            0.0
        };
        [1.0 - f, f]
    };
    let (wx, wy) = (weight(i, cell.x), weight(j, cell.y));
    let mut out = [0.0; 3];
    let mut total = 0.0;
    for (k, c) in corners.iter().enumerate() {
        let wgt = wx[k % 2] * wy[k / 2];
        if wgt == 0.0 {
            continue;
        }
        let Some((q, v)) = c else {
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
    (total >= MIN_WEIGHT).then(|| out.map(|v| v / total))
}

/// The probe pixels ([`super::probe_pixels`]) shaded as a render at each spacing of
/// [`STRIDE_CANDIDATES`] shades them, for a plan's [`super::plan_choice`]: the nodes each
/// probe's cells need shaded by `shade` (each pixel once) and the rule applied, the
/// probe's own value (`own[k]`, `shade` of probe `k`) where the rule refuses and at
/// spacing 1; `base[k]` (a part every spacing computes alike, such as direct light) added
/// to each.
pub fn strided_probes(
    scene: &Scene,
    probes: &[(usize, usize, ShadingPoint)],
    own: &[Rgb],
    base: &[Rgb],
    mut shade: impl FnMut(&ShadingPoint) -> Rgb,
) -> Vec<Vec<Rgb>> {
    let cam = scene.camera;
    let (w, h) = (cam.width as usize, cam.height as usize);
    // Every pixel shaded once, whichever spacings and probes share it as a node (the
    // probes themselves with their own values).
    let mut seen: HashMap<(usize, usize), Node> = probes
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
                        interpolate_adaptive(s, w, h, i, j, &p, |x, y| {
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
    /// 23 × 17 image at spacings 2–5, the last column and row clamped, cells split or
    /// not), and takes a corner's value at the corner itself.
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
                    let got =
                        interpolate_adaptive(s, w, h, i, j, &p, |x, y| Some((p, field(x, y))))
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

    /// The pixels whose node the rule asks for, and its value, at pixel `(i, j)` of a 9 × 9
    /// image at spacing 8 under `node`.
    fn asked(
        i: usize,
        j: usize,
        p: &ShadingPoint,
        node: impl Fn(usize, usize) -> Node,
    ) -> (Vec<(usize, usize)>, Option<Rgb>) {
        let mut seen = Vec::new();
        let v = interpolate_adaptive(8, 9, 9, i, j, p, |x, y| {
            seen.push((x, y));
            node(x, y)
        });
        seen.sort_unstable();
        seen.dedup();
        (seen, v)
    }

    /// A cell whose corners spread by at most `SPLIT_SPREAD` stays whole; by more, it is
    /// split down to `LEAF_SPACING` around the pixel, each part whose corners are alike
    /// kept whole: a bump at the centre of a 9 × 9 image splits the cell of spacing 8
    /// into spacing 4, and the quarter holding the bump into spacing 2.
    #[test]
    fn cells_split_where_their_corners_spread() {
        let p = point(1, DVec3::Z);
        let flat = |_: usize, _: usize| Some((p, [1.0, 2.0, 3.0]));
        let (seen, v) = asked(3, 5, &p, flat);
        assert_eq!(seen, vec![(0, 0), (0, 8), (8, 0), (8, 8)]);
        assert_eq!(v, Some([1.0, 2.0, 3.0]));
        // The corners within the spread (1 and 1 + SPLIT_SPREAD): still whole.
        let edge = |x: usize, _: usize| {
            Some((
                p,
                [1.0 + SPLIT_SPREAD * (x / 8) as f64 / (1.0 - SPLIT_SPREAD); 3],
            ))
        };
        assert_eq!(asked(3, 5, &p, edge).0.len(), 4);
        // A bump of one channel at the corner pixel (8, 8).
        let bump =
            |x: usize, y: usize| Some((p, [1.0, if (x, y) == (8, 8) { 3.0 } else { 1.0 }, 1.0]));
        // Spacing 8 split; the quarter (0..4, 4..8) holding (3, 5) is alike.
        let (seen, v) = asked(3, 5, &p, bump);
        let want = vec![(0, 0), (0, 4), (0, 8), (4, 4), (4, 8), (8, 0), (8, 8)];
        assert_eq!(seen, want);
        assert_eq!(v, Some([1.0; 3]));
        // The quarter (4..8, 4..8) holds the bump: split again into (6..8, 6..8), a leaf,
        // where (7, 7) takes a quarter of each corner.
        let (seen, v) = asked(7, 7, &p, bump);
        let want = vec![
            (0, 0),
            (0, 8),
            (4, 4),
            (4, 8),
            (6, 6),
            (6, 8),
            (8, 0),
            (8, 4),
            (8, 6),
            (8, 8),
        ];
        assert_eq!(seen, want);
        assert_eq!(v, Some([1.0, 1.5, 1.0]));
    }

    /// Corners on another object, with a normal beyond `NORMAL_COS` or seeing no surface
    /// split the cell; in a cell of `LEAF_SPACING` they are left out and the rest
    /// renormalised, and under `MIN_WEIGHT` of the weight left the pixel computes its own
    /// (`None`).
    #[test]
    fn interpolation_leaves_out_other_surfaces() {
        let p = point(1, DVec3::Z);
        let tilted = DVec3::new(0.4, 0.0, 1.0).normalize(); // cos 0.93
        let value = |x: usize, y: usize| [(100 + x + 2 * y) as f64; 3];
        for how in 0..3 {
            let node = |x: usize, y: usize| {
                if (x, y) != (8, 8) {
                    return Some((p, value(x, y)));
                }
                match how {
                    0 => Some((point(2, DVec3::Z), value(x, y))),
                    1 => Some((point(1, tilted), value(x, y))),
                    _ => None,
                }
            };
            // Away from the odd corner the parts are alike and exact.
            let (seen, v) = asked(1, 1, &p, node);
            assert_eq!(
                seen,
                vec![(0, 0), (0, 4), (0, 8), (4, 0), (4, 4), (8, 0), (8, 8)],
                "{how}"
            );
            assert_eq!(v, Some(value(1, 1)), "{how}");
            // Beside it: the cell (6..8, 6..8) holds it; pixel (7, 7) weighs each corner
            // 1/4, and the three left are renormalised.
            let (_, v) = asked(7, 7, &p, node);
            let want = (value(6, 6)[0] + value(8, 6)[0] + value(6, 8)[0]) / 3.0;
            assert!((v.unwrap()[0] - want).abs() < 1e-12, "{how}: {v:?}");
            // At (8, 7) half its weight is the odd corner's: the other half is enough.
            assert!(asked(8, 7, &p, node).1.is_some(), "{how}");
        }
        // In a leaf, a pixel nearest a corner of another object computes its own.
        let cell = Cell {
            x: (0, 2),
            y: (0, 2),
        };
        let other = Some((point(2, DVec3::Z), [1.0; 3]));
        let mine = Some((p, [2.0; 3]));
        assert_eq!(
            interpolate_in(cell, 1, 0, &p, &[other, mine, other, mine]),
            Some([2.0; 3])
        );
        assert_eq!(
            interpolate_in(cell, 1, 0, &p, &[other, other, other, mine]),
            None
        );
    }

    /// The lattice a render builds holds every node the rule asks for, with the value
    /// shading it directly gives: every pixel of `room` at 48 columns, spacing 4, the
    /// indirect light stood in for by a field with steps across objects and a contact-like
    /// falloff.
    #[test]
    fn build_holds_every_node_the_rule_asks_for() {
        let mut scene = Scene::load("builtin:room").unwrap();
        scene.camera = scene.camera.resized(48).unwrap();
        let shade = |p: &ShadingPoint| -> Rgb {
            let r = p.x.length();
            [1.0 / (0.05 + r * r), p.object as f64, p.n.z.abs()]
        };
        let lattice = Lattice::build(&scene, 4, || (), |_, p| shade(p));
        let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
        let mut fresh = 0;
        for j in 0..h {
            for i in 0..w {
                let Seen::Surface(p) = scene.see(&scene.camera.centre_ray(i as u32, j as u32))
                else {
                    continue;
                };
                let want = interpolate_adaptive(4, w, h, i, j, &p, |x, y| {
                    match scene.see(&scene.camera.centre_ray(x as u32, y as u32)) {
                        Seen::Surface(q) => Some((q, shade(&q))),
                        Seen::Radiance(_) => None,
                    }
                });
                assert_eq!(lattice.interpolate(i, j, &p), want, "({i}, {j})");
                fresh += usize::from(want.is_none());
            }
        }
        // The splits did their work: few pixels compute their own, and the lattice
        // computed more nodes than the plain one's but far fewer than the pixels.
        let plain = ((w - 1).div_ceil(4) + 1) * ((h - 1).div_ceil(4) + 1);
        assert!(fresh < w * h / 20, "{fresh}");
        assert!(
            lattice.computed > plain && lattice.computed < w * h / 2,
            "{}",
            lattice.computed
        );
    }
}
