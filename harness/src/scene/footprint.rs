//! Pixel footprints: from pixel-centre samples toward the pixel means the path tracer
//! computes.
//!
//! The path tracer's pixel is the mean radiance over the pixel's area (a box filter); a
//! method that shades pixel centres differs from it by the footprint term. For radiance `f`
//! smooth over the pixel (pixel units, centre `c`), Taylor's expansion averaged over the
//! unit box gives `mean = f(c) + (f_xx + f_yy)/24 + O(h⁴)`: the first-order terms cancel by
//! symmetry and `∫x² dx = 1/12` per axis, halved by Taylor's `½`. [`refine`] estimates
//! `|Δf|/24` per pixel by the five-point Laplacian over its neighbours on the same object
//! (a missing one counted as the mean of those present, i.e. the sum of the differences
//! scaled by `4/count`), takes the largest channel, and re-shades the pixels where it
//! reaches `threshold` times the image's largest surface value: their value becomes the
//! mean of the 2×2 Gauss–Legendre points `½ ± 1/(2√3)` of the pixel, which is the box mean
//! exactly for any radiance cubic in each pixel coordinate (the harness unit test checks
//! it). Where the radiance changes within a pixel (a glossy highlight, a shadow edge) the
//! centre alone misses the mean by up to the change; elsewhere nothing is re-shaded.
//!
//! **Small objects.** An object seen by fewer than [`SMALL_OBJECT_PIXELS`] pixel centres
//! has all its pixels re-shaded: across a pixel of a sphere of radius 2 pixels the normal
//! turns by about 30°, and its shading can change between centres that all agree. On
//! `cluster` a small sphere in the umbra at each of its pixel centres is lit on a crescent
//! between them: the centres say 0 and the path tracer's box mean does not, and near black
//! the tone mapping magnifies the difference (the rule: test
//! `refine_reshades_small_objects_whole`; its gain: the report's `cluster` rows).
//!
//! **Where to refine.** Re-shading a pixel costs four shading points and removes its
//! footprint term `e` from the squared error; the path tracer's cost at equal error goes as
//! `1/E²` (`E` the image's RMS error). So a pixel is worth it where `e² > 4·E²`, i.e. `e`
//! above about twice the image's RMS error. A method plans `threshold` from its target error
//! (the render's mean |difference| over the maximum radiance) by the factor its own error at
//! pixel centres warrants: `rsl` ([`PLAN_FACTOR`]), whose error is close to the target,
//! twice the target; `lobes` ([`LOBES_PLAN_FACTOR`]), whose error at pixel centres is a
//! fraction of it, a third. The harness tests
//! `rsl_method_against_the_path_tracer_on_a_small_environment_scene` and
//! `lobes_footprint_refinement_against_the_path_tracer` assert the gains against the path
//! tracer.

use rayon::prelude::*;

use super::image::Image;
use super::{Rgb, Scene, Seen, ShadingPoint};

/// The `rsl` method's footprint threshold in units of its target error (module docs): its
/// error is close to the target, so by the rule above the pixels worth re-shading lie
/// above about twice it (test `rsl_method_against_the_path_tracer_on_a_small_environment_scene`
/// asserts the gain).
pub const PLAN_FACTOR: f64 = 2.0;

/// The `lobes` method's footprint threshold in units of its target error (module docs; the
/// `hvl` method refines its direct light, the `lobes` method's, by it too): its
/// error at pixel centres is a fraction of the target (the report's `scenes` rows for
/// `lobes` and `cluster` give it beside the pixel centres alone), so the pixels worth
/// re-shading lie far below twice the target; a third of it (test
/// `lobes_footprint_refinement_against_the_path_tracer` asserts the gain).
pub const LOBES_PLAN_FACTOR: f64 = 1.0 / 3.0;

/// Objects whose surface fewer pixel centres see than this have every pixel re-shaded
/// where refinement is on, whatever its estimate (module docs): about a disc of radius 2
/// pixels, too few for neighbours on the object to resolve its shading.
pub const SMALL_OBJECT_PIXELS: usize = 16;

/// The 2×2 Gauss–Legendre points of the unit interval, `½ ± 1/(2√3)` (weights ½ each).
pub const GAUSS_2: [f64; 2] = [0.5 - 0.288_675_134_594_812_9, 0.5 + 0.288_675_134_594_812_9];

/// The estimated footprint term `max_c |Δf_c|/24` of every pixel of `img` whose centre
/// sees a surface (`objects`, row-major, the centre pass's) with a neighbour on the same
/// object (module docs), `None` for the others.
pub fn footprint_estimates(img: &Image, objects: &[Option<usize>]) -> Vec<Option<f64>> {
    let (w, h) = (img.width, img.height);
    let object = |k: usize| objects.get(k).copied().flatten();
    (0..w * h)
        .map(|k| {
            let own = object(k)?;
            let (i, j) = (k % w, k / w);
            let near = [
                (i > 0).then(|| k - 1),
                (i + 1 < w).then_some(k + 1),
                (j > 0).then(|| k - w),
                (j + 1 < h).then_some(k + w),
            ];
            let (mut sum, mut count) = ([0.0f64; 3], 0usize);
            for n in near.into_iter().flatten() {
                if object(n) == Some(own) {
                    count += 1;
                    for (c, v) in sum.iter_mut().enumerate() {
                        *v += img.data[n][c] - img.data[k][c];
                    }
                }
            }
            if count == 0 {
                return None;
            }
            let scale = 4.0 / count as f64 / 24.0;
            Some(sum.iter().map(|s| (s * scale).abs()).fold(0.0, f64::max))
        })
        .collect()
}

/// Re-shades the pixels of `img` (its centre pass's [`super::Objects`] in `objects`) whose
/// estimated footprint term reaches `threshold` times the image's largest surface value
/// (module docs), and every pixel of an object fewer than [`SMALL_OBJECT_PIXELS`] centres
/// see, at their 2×2 Gauss–Legendre points, through `shade` (any number of surface points
/// in, one radiance each out, in order); a point that sees no surface takes the radiance it
/// sees. Returns the number of pixels
/// re-shaded. Nothing is re-shaded for a `threshold` that is not positive.
///
/// Errors: `shade`'s, or a `shade` that returns another count than it was given.
pub fn refine(
    scene: &Scene,
    img: &mut Image,
    objects: &[Option<usize>],
    threshold: f64,
    shade: impl FnOnce(&[ShadingPoint]) -> Result<Vec<Rgb>, String>,
) -> Result<usize, String> {
    if threshold.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return Ok(0);
    }
    let est = footprint_estimates(img, objects);
    let max = img
        .data
        .iter()
        .zip(&est)
        .filter(|(_, e)| e.is_some())
        .flat_map(|(v, _)| v.iter().copied())
        .fold(0.0, f64::max);
    // Pixels per object: the small objects' pixels are re-shaded whatever their estimate.
    let mut size = std::collections::HashMap::<usize, usize>::new();
    for o in objects.iter().flatten() {
        *size.entry(*o).or_insert(0) += 1;
    }
    let small = |k: usize| {
        let object = objects.get(k).copied().flatten();
        object
            .and_then(|o| size.get(&o))
            .is_some_and(|&n| n < SMALL_OBJECT_PIXELS)
    };
    let chosen: Vec<usize> = (0..est.len())
        .filter(|&k| est[k].is_some_and(|e| e > 0.0 && e >= threshold * max) || small(k))
        .collect();
    if chosen.is_empty() {
        return Ok(0);
    }
    let cam = scene.camera;
    let w = cam.width as usize;
    // Each chosen pixel's four points: what they see.
    let seen: Vec<Seen> = chosen
        .par_iter()
        .flat_map_iter(|&k| {
            let (i, j) = ((k % w) as u32, (k / w) as u32);
            GAUSS_2
                .iter()
                .flat_map(move |&y| GAUSS_2.iter().map(move |&x| cam.ray(i, j, x, y)))
                .map(|r| scene.see(&r))
        })
        .collect();
    let points: Vec<ShadingPoint> = seen
        .iter()
        .filter_map(|s| match s {
            Seen::Surface(p) => Some(*p),
            Seen::Radiance(_) => None,
        })
        .collect();
    let shaded = shade(&points)?;
    if shaded.len() != points.len() {
        return Err(format!(
            "footprint: {} points shaded, {} given",
            shaded.len(),
            points.len()
        ));
    }
    let mut next = shaded.into_iter();
    for (&k, four) in chosen.iter().zip(seen.chunks(4)) {
        let mut mean = [0.0; 3];
        for s in four {
            let v = match s {
                Seen::Radiance(l) => *l,
                Seen::Surface(_) => next.next().unwrap_or([0.0; 3]),
            };
            for c in 0..3 {
                mean[c] += 0.25 * v[c];
            }
        }
        img.data[k] = mean;
    }
    Ok(chosen.len())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every surface pixel of `scene`'s image on one object (none small), `None` elsewhere.
    fn one_object(scene: &Scene) -> Vec<Option<usize>> {
        let cam = scene.camera;
        (0..cam.pixels())
            .map(|k| {
                let (i, j) = (
                    (k % cam.width as usize) as u32,
                    (k / cam.width as usize) as u32,
                );
                matches!(scene.see(&cam.centre_ray(i, j)), Seen::Surface(_)).then_some(0)
            })
            .collect()
    }

    /// [`refine`] with every point shaded `v`: the pixels re-shaded and the points given.
    fn refine_to(
        scene: &Scene,
        img: &mut Image,
        objects: &[Option<usize>],
        threshold: f64,
        v: f64,
    ) -> (usize, usize) {
        let mut given = 0;
        let n = refine(scene, img, objects, threshold, |pts| {
            given = pts.len();
            Ok(vec![[v; 3]; pts.len()])
        })
        .unwrap();
        (n, given)
    }

    /// The contract of [`refine`] on a small `lobes` scene: a flat image re-shades nothing
    /// (the shading closure is not called), nor does a threshold that is not positive; a
    /// step across the image re-shades exactly the surface pixels beside it whose
    /// estimate reaches the threshold, four points each (fewer where a point sees no
    /// surface), and each takes the mean of its four; a closure that answers another
    /// count is an error. (Every surface is one object here: none is small.)
    #[test]
    fn refine_reshades_only_where_the_estimate_reaches_the_threshold() {
        let mut scene = Scene::load("builtin:lobes").unwrap();
        scene.camera = scene.camera.resized(24).unwrap();
        let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
        let flat = |v: f64| {
            let mut img = Image::new(w, h);
            img.data.iter_mut().for_each(|p| *p = [v; 3]);
            img
        };
        let objects = one_object(&scene);
        let never = |_: &[ShadingPoint]| -> Result<Vec<Rgb>, String> {
            panic!("nothing should be re-shaded")
        };
        assert_eq!(refine(&scene, &mut flat(1.0), &objects, 1e-3, never), Ok(0));
        // A step between columns 11 and 12.
        let mut step = flat(1.0);
        for (k, p) in step.data.iter_mut().enumerate() {
            if k % w >= 12 {
                *p = [2.0; 3];
            }
        }
        assert_eq!(
            refine(&scene, &mut step.clone(), &objects, 0.0, never),
            Ok(0)
        );
        assert_eq!(
            refine(&scene, &mut step.clone(), &objects, -1.0, never),
            Ok(0)
        );
        let est = footprint_estimates(&step, &objects);
        let want: Vec<usize> = (0..w * h)
            .filter(|&k| est[k].is_some_and(|e| e >= 0.01 * 2.0))
            .collect();
        assert!(!want.is_empty());
        assert!(want.iter().all(|&k| k % w == 11 || k % w == 12), "{want:?}");
        let mut refined = step.clone();
        let (n, given) = refine_to(&scene, &mut refined, &objects, 0.01, 8.0);
        assert_eq!(n, want.len());
        assert!(given <= 4 * n && given > 0, "{given} points for {n} pixels");
        for k in 0..w * h {
            if want.contains(&k) {
                // The mean of four values, each 8 or what a point sees off the surfaces.
                assert_ne!(refined.data[k], step.data[k], "pixel {k}");
            } else {
                assert_eq!(refined.data[k], step.data[k], "pixel {k}");
            }
        }
        let short = refine(
            &scene,
            &mut step.clone(),
            &objects,
            0.01,
            |_| Ok(Vec::new()),
        );
        assert!(short.is_err());
    }

    /// An object seen by fewer than [`SMALL_OBJECT_PIXELS`] pixel centres is re-shaded at
    /// every pixel even where the image is flat (its estimate 0); the large objects of the
    /// same flat image are not.
    #[test]
    fn refine_reshades_small_objects_whole() {
        let mut scene = Scene::load("builtin:lobes").unwrap();
        scene.camera = scene.camera.resized(24).unwrap();
        let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
        // Every surface one large object but for a 3 × 2 block, a small object of its own.
        let mut objects = one_object(&scene);
        let small = usize::MAX;
        let block: Vec<usize> = (10..12)
            .flat_map(|j| (8..11).map(move |i| j * w + i))
            .collect();
        assert!(block.iter().all(|&k| objects[k].is_some()));
        for &k in &block {
            objects[k] = Some(small);
        }
        let mut img = Image::new(w, h);
        img.data.iter_mut().for_each(|p| *p = [1.0; 3]);
        let (n, given) = refine_to(&scene, &mut img, &objects, 1e-3, 3.0);
        assert_eq!(n, block.len());
        assert!(given <= 4 * n && given > 0, "{given} points for {n} pixels");
        for k in 0..w * h {
            if block.contains(&k) {
                assert_ne!(img.data[k], [1.0; 3], "pixel {k}");
            } else {
                assert_eq!(img.data[k], [1.0; 3], "pixel {k}");
            }
        }
    }

    /// The 2×2 Gauss–Legendre mean is the unit box's mean of every monomial `x^a·y^b` with
    /// `a, b ≤ 3` (`1/((a + 1)(b + 1))`), and not of `x⁴` (degree 4 is past its exactness).
    #[test]
    fn gauss_points_give_the_box_mean_of_bicubics() {
        let mean = |f: &dyn Fn(f64, f64) -> f64| {
            GAUSS_2
                .iter()
                .flat_map(|&y| GAUSS_2.iter().map(move |&x| (x, y)))
                .map(|(x, y)| 0.25 * f(x, y))
                .sum::<f64>()
        };
        for a in 0..=3 {
            for b in 0..=3 {
                let got = mean(&|x, y| x.powi(a) * y.powi(b));
                let want = 1.0 / f64::from((a + 1) * (b + 1));
                assert!((got - want).abs() < 1e-15, "x^{a} y^{b}: {got} vs {want}");
            }
        }
        assert!((mean(&|x, _| x.powi(4)) - 0.2).abs() > 1e-3);
    }
}
