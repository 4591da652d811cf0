//! The `hvl` method (HVL paper, section 5.2): one bounce of indirect light from harmonics
//! virtual lights placed from a reflective shadow map of each spherical light, plus the
//! direct light of the `lobes` method.
//!
//! **Placement.** A sphere of radius `r` and radiance `L` radiates the intensity
//! `I = L·πr²` in every direction (its projected area is `πr²` from anywhere), so a cube
//! map of `6·s²` texels around its centre (field of view 90° per face) sends the power
//! `Φ = I·Ω_texel` (the texel's exact solid angle) along each texel's
//! centre ray; the first surface hit `y` (normal `n_y` toward the light) receives it and
//! becomes an HVL of radius `r2 = k·t·tan γ` (eq. 24–25, `t` the ray's length, `γ` the
//! diagonal angle of an `s × s` face of field of view 90°, `k = 1`). Rays that escape or
//! hit another light place nothing.
//!
//! **Emission and reception** (eq. 19–22, `steradian_core::sh::hvl::contribution`): an HVL
//! reflects its surface's *diffuse* albedo (Lambertian emission, exact in one band); a
//! receiver's diffuse albedo times the Lambert table (its first [`Options::bands`]), and
//! each of its glossy parts times a BRDF SH table generated for it ([`Glossy`]). All are
//! linear, so the scalar contribution of a unit HVL is computed once per pair and part and
//! scaled in RGB by the light's radiance, the HVL's albedo and the part's scale. HVLs do
//! not emit their glossy parts: emitting them (each part's `F′` at the HVL's light
//! direction, as one more HVL at the same spot) was tried on `room`, where it barely moved
//! the error while each HVL's sharp emission lobe made the plan ask for many more HVLs.
//! The paper does not test
//! visibility between an HVL and the receiver; here a shadow ray per pair does by default
//! ([`Options::visibility`]), which the harness measures on the `room` scene.
//!
//! **Lattice** (not in the paper). The indirect light is computed on a lattice of every
//! [`Options::stride`]-th pixel, split where a cell's corners differ, and interpolated
//! between on the same object and normal ([`super::lattice`]); the plan takes the coarsest
//! spacing whose probes stay within its share of the target ([`choose_stride`]).
//! `stride = 1` is the paper's every pixel.

use std::f64::consts::FRAC_PI_2;

use glam::DVec3;
use indicatif::ProgressBar;
use steradian_core::lobe::sum::ProductCounts;
use steradian_core::sh::{brdf, hvl as core_hvl};

use super::image::Image;
use super::{Kind, Ray, Rgb, Scene, ShadingPoint, Shape, lattice, lobes, path};

/// Settings of the `hvl` method.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    /// Cube-map face side of each light's reflective shadow map (`6·side²` rays).
    pub side: usize,
    /// The `lobes` method's settings for the direct light.
    pub direct: lobes::Options,
    /// Test each HVL–receiver pair with a shadow ray (the paper does not: `false`).
    pub visibility: bool,
    /// Carry the receivers' glossy parts (Phong, Lafortune) through BRDF SH tables built
    /// for the scene's materials ([`Glossy`]); `false` keeps only the diffuse part.
    pub glossy: bool,
    /// SH bands of the receivers' diffuse part: the first `bands` of the committed Lambert
    /// table (at most its 5; planned by [`choose_bands`]).
    pub bands: usize,
    /// Sum each receiver's HVLs with the SIMD kernels (`steradian_simd::sh::hvl`: the
    /// diffuse part by `contributions_zonal`, eight HVLs at a time, within its `ZONAL_TOL`
    /// of the scalar kernel; the glossy parts by `contributions`, four at a time, bit for
    /// bit) and shade the direct light by the `lobes` method's SIMD path
    /// ([`lobes::shade_x8`]); `false` the scalar kernels, one HVL and point at a time.
    pub simd: bool,
    /// Pixel spacing of the lattice the indirect light is computed on and interpolated
    /// between ([`lattice::Lattice`], planned by [`choose_stride`]); 1 computes it at every
    /// pixel (the paper).
    pub stride: usize,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            side: 8,
            direct: lobes::Options::default(),
            visibility: true,
            glossy: true,
            bands: brdf::lambert().bands(),
            simd: true,
            stride: 1,
        }
    }
}

/// One placed HVL: the core light (unit power) and its RGB power × albedo.
#[derive(Clone, Copy, Debug)]
pub struct Placed {
    /// The core HVL with unit power.
    pub hvl: core_hvl::Hvl,
    /// `Φ·albedo` in RGB: what multiplies the unit contribution.
    pub weight: Rgb,
    /// The scene object the HVL lies on (a shadow ray toward it, from a receiver it faces,
    /// cannot meet that object before its end: the object is convex or a plane).
    pub object: usize,
}

/// The HVLs of every spherical light.
pub fn place(scene: &Scene, side: usize) -> Vec<Placed> {
    let side = side.max(1);
    let m = (side * side) as u32;
    let du = 2.0 / side as f64;
    let mut out = Vec::new();
    for light in &scene.lights {
        let intensity = light
            .radiance
            .map(|l| l * std::f64::consts::PI * light.radius.powi(2));
        for face in 0..6 {
            let (axis, t, b) = face_frame(face);
            for i in 0..side {
                for j in 0..side {
                    let (u, v) = (-1.0 + (i as f64 + 0.5) * du, -1.0 + (j as f64 + 0.5) * du);
                    let omega = texel_solid_angle(u - du / 2.0, v - du / 2.0, du);
                    let d = (axis + u * t + v * b).normalize();
                    let ray = Ray {
                        o: light.center + d * light.radius * (1.0 + 1e-9),
                        d,
                    };
                    let Some(hit) = scene.intersect(&ray, 0.0, f64::INFINITY) else {
                        continue;
                    };
                    let obj = scene.objects[hit.object];
                    let Kind::Surface(mi) = obj.kind else {
                        continue;
                    };
                    let y = ray.o + hit.t * d;
                    let mut n = obj.shape.normal(y);
                    if n.dot(d) > 0.0 {
                        n = -n;
                    }
                    let dist = (y - light.center).length();
                    let r = core_hvl::radius_from_fov(dist as f32, FRAC_PI_2 as f32, m, 1.0);
                    let Ok(h) = core_hvl::Hvl::new(
                        y.as_vec3(),
                        n.as_vec3(),
                        (-d).as_vec3(),
                        r.max(1e-6),
                        1.0,
                    ) else {
                        continue;
                    };
                    let albedo = scene.materials[mi].diffuse();
                    let mut w = [0.0; 3];
                    for c in 0..3 {
                        w[c] = intensity[c] * omega * albedo[c];
                    }
                    out.push(Placed {
                        hvl: h,
                        weight: w,
                        object: hit.object,
                    });
                }
            }
        }
    }
    out
}

/// The exact solid angle of the cube-face texel `[u, u + du] × [v, v + du]` at unit
/// distance: `F(u₁, v₁) − F(u₀, v₁) − F(u₁, v₀) + F(u₀, v₀)`, `F = atan(uv/√(1 + u² + v²))`
/// (the solid angle of the rectangle from the face centre to `(u, v)`), so a face sums to
/// `4·F(1, 1) = 4π/6` exactly.
fn texel_solid_angle(u: f64, v: f64, du: f64) -> f64 {
    let f = |a: f64, b: f64| (a * b / (1.0 + a * a + b * b).sqrt()).atan();
    f(u + du, v + du) - f(u, v + du) - f(u + du, v) + f(u, v)
}

/// Axis, and two tangents, of cube face `f` (±x, ±y, ±z).
fn face_frame(f: usize) -> (DVec3, DVec3, DVec3) {
    let axis = match f {
        0 => DVec3::X,
        1 => -DVec3::X,
        2 => DVec3::Y,
        3 => -DVec3::Y,
        4 => DVec3::Z,
        _ => -DVec3::Z,
    };
    let (t, b) = super::material::basis(axis);
    (axis, t, b)
}

/// Per-thread buffers of [`indirect`]: the receiver's coefficients, their zonal part and
/// the SH scratch.
pub struct Scratch {
    coeffs: Vec<f32>,
    zonal: Vec<f32>,
    sh: Vec<f32>,
    /// `F` of each glossy part of the current receiver, `n²` each.
    glossy: Vec<Vec<f32>>,
    /// The SIMD path's per-HVL contributions: the diffuse part's, then each glossy part's.
    diffuse_c: Vec<f32>,
    glossy_c: Vec<Vec<f32>>,
    sh4: Vec<[f32; 4]>,
    /// The objects the current receiver's shadow rays test.
    cull: ShadowCull,
}

/// A placement of HVLs as receivers shade with it, built once per render: the placed HVLs
/// ordered by the object they lie on, their core HVLs side by side (the SIMD kernels'
/// input), the range of each object's HVLs, and per scene object how far
/// behind a plane its farthest HVL lies (`δ = max(0, max_h −n·(h − p))`, a rounding of the
/// `f32` positions for the HVLs on the plane itself; `∞` for spheres), from which the
/// shadow rays leave out planes no segment can cross.
pub struct Placement {
    /// The placed HVLs, ordered by object (stably).
    pub placed: Vec<Placed>,
    lights: Vec<core_hvl::Hvl>,
    /// Per scene object, the range of `placed` on it. A receiver skips its own object's
    /// HVLs: they send it nothing, as each object is convex or a plane (toward an HVL at
    /// `h` with normal `n_h` on a sphere of centre `c` through the receiver `x`,
    /// `(h − x)·n_h = (r² − (x − c)·(h − c))/r ≥ 0`, so the HVL faces away; on a plane
    /// `(h − x)·n_h = 0`), where the `f32` kernels would leave a rounding's worth.
    own: Vec<std::ops::Range<usize>>,
    behind: Vec<f64>,
}

impl Placement {
    /// The placement of `placed` in `scene`.
    pub fn new(scene: &Scene, mut placed: Vec<Placed>) -> Placement {
        placed.sort_by_key(|h| h.object);
        let own = (0..scene.objects.len())
            .map(|id| {
                let start = placed.partition_point(|h| h.object < id);
                start..placed.partition_point(|h| h.object <= id)
            })
            .collect();
        let lights = placed.iter().map(|h| h.hvl).collect();
        let behind = scene
            .objects
            .iter()
            .map(|obj| match obj.shape {
                Shape::Plane { point, normal } => placed.iter().fold(0.0, |m: f64, h| {
                    m.max(-normal.dot(h.hvl.position().as_dvec3() - point))
                }),
                Shape::Sphere { .. } => f64::INFINITY,
            })
            .collect();
        Placement {
            placed,
            lights,
            own,
            behind,
        }
    }
}

/// The shadow ray from a receiver's `origin` toward an HVL, unit direction, and its end
/// `ε = SHADOW_EPS` short of the HVL (which lies on a surface).
fn shadow_ray(origin: DVec3, h: &Placed) -> (Ray, f64) {
    let to = h.hvl.position().as_dvec3() - origin;
    let d = to.length();
    (
        Ray {
            o: origin,
            d: to / d,
        },
        d * (1.0 - f64::from(SHADOW_EPS)),
    )
}

/// The objects the shadow rays from one receiver toward a [`Placement`] test (refilled per
/// receiver). From an origin in front of a plane by
/// `s > 2δ/ε`, a segment toward an HVL crosses the plane, if at all, beyond the fraction
/// `s/(s + δ) > 1 − ε/2` of its length (`n·(x − p)` is linear along it), past the ray's
/// `t_max`, which stops `ε = 1e-4` short of the HVL (far above the rounding of the hit
/// distance): the plane holds no hit and is left out. In a closed convex room no wall is
/// tested.
///
/// A sphere is tested first by the cone of directions it subtends from the receiver: a
/// unit direction `d` can meet it ahead only if `(c − o)·d ≥ √(|c − o|² − r²)` (the ray's
/// closest approach within `r`, on the near side); the exact test runs only there
/// (receivers inside a sphere always run it). The cone is widened by `1e-9` of the
/// sphere's distance, far above the rounding of either side.
#[derive(Default)]
struct ShadowCull {
    /// Per tested object: its index, and for a sphere `c − o` and the cone's threshold
    /// (`−∞` where the receiver is inside or the object is a plane).
    tests: Vec<(usize, DVec3, f64)>,
}

impl ShadowCull {
    /// The objects a shadow ray from `origin` toward the HVLs of `at` tests, in
    /// `self.tests`.
    fn receiver(&mut self, scene: &Scene, at: &Placement, origin: DVec3) {
        self.tests.clear();
        for (id, obj) in scene.objects.iter().enumerate() {
            match obj.shape {
                Shape::Plane { point, normal } => {
                    if at.behind[id] >= 0.5 * f64::from(SHADOW_EPS) * normal.dot(origin - point) {
                        self.tests.push((id, DVec3::ZERO, f64::NEG_INFINITY));
                    }
                }
                Shape::Sphere { center, radius } => {
                    let cmo = center - origin;
                    let d2 = cmo.length_squared();
                    let cone = if d2 > radius * radius {
                        (d2 - radius * radius).sqrt() - 1e-9 * (d2.sqrt() + radius)
                    } else {
                        f64::NEG_INFINITY
                    };
                    self.tests.push((id, cmo, cone));
                }
            }
        }
    }

    /// Whether the ray from the receiver's origin along `ray.d` (unit) meets a tested
    /// object in `(0, t_max)`.
    fn blocked(&self, scene: &Scene, ray: &Ray, t_max: f64) -> bool {
        self.tests.iter().any(|&(id, cmo, cone)| {
            cmo.dot(ray.d) >= cone && scene.objects[id].shape.intersect(ray, 0.0, t_max).is_some()
        })
    }
}

impl Default for Scratch {
    fn default() -> Self {
        let n = brdf::lambert().bands();
        Scratch {
            coeffs: vec![0.0; n * n],
            zonal: vec![0.0; n],
            sh: vec![0.0; n * n],
            glossy: Vec::new(),
            diffuse_c: Vec::new(),
            glossy_c: Vec::new(),
            sh4: Vec::new(),
            cull: ShadowCull::default(),
        }
    }
}

/// Truncation target of the receivers' glossy tables: relative L2 of `F` at `θₒ = 45°`,
/// the built-in tables' (`generate::brdf_sh::TARGET`).
pub const GLOSSY_TARGET: f64 = crate::generate::brdf_sh::TARGET;

/// One glossy part of a material as a receiver: its BRDF SH table (unit scale) and the RGB
/// that scales it.
pub struct GlossyPart {
    /// The table's file bytes (`steradian_core::sh::brdf` format).
    pub table: Vec<u8>,
    /// Phong's `specular`, a Lafortune lobe's `ρ`.
    pub scale: Rgb,
}

/// The glossy parts of every material of a scene, by material index: the specular parts of
/// [`super::rsl::specular_parts`] (a modified Phong material's specular term with `k_s = 1`,
/// each lobe of a Lafortune material with `ρ = 1`), each projected by `generate::brdf_sh`
/// with the fewest bands and views that meet [`GLOSSY_TARGET`] (tables shared between
/// identical parts). Lambert materials have none; GGX is not carried by this method.
pub struct Glossy {
    /// Per material, its parts.
    pub parts: Vec<Vec<GlossyPart>>,
}

impl Glossy {
    /// The tables of `scene`'s materials with `o.glossy` ([`Glossy::build`]), none without.
    pub fn of(scene: &Scene, o: &Options) -> Glossy {
        if o.glossy {
            Glossy::build(scene)
        } else {
            Glossy::none(scene)
        }
    }

    /// No glossy part anywhere (the diffuse-only receiver).
    pub fn none(scene: &Scene) -> Glossy {
        Glossy {
            parts: scene.materials.iter().map(|_| Vec::new()).collect(),
        }
    }

    /// The tables of `scene`'s materials (module docs of [`Glossy`]).
    pub fn build(scene: &Scene) -> Glossy {
        use super::rsl::{SpecKey, specular_parts};
        use crate::generate::brdf_sh as gen_sh;
        use steradian_reference::lobe::brdf::Model;
        // One table per distinct part and process: the plan's probes and the render use the
        // same tables, and a generation costs seconds.
        static BUILT: std::sync::Mutex<Vec<(SpecKey, Vec<u8>)>> = std::sync::Mutex::new(Vec::new());
        let table_of = |key: SpecKey| -> Option<Vec<u8>> {
            let f = f64::from_bits;
            let model = match key {
                SpecKey::Phong(e) => Model::Phong {
                    kd: 0.0,
                    ks: 1.0,
                    e: f(e),
                },
                SpecKey::Lafortune(c, cz, e) => Model::Lafortune {
                    lobes: [[f(c), f(c), f(cz), f(e), 1.0], [0.0; 5]],
                },
                SpecKey::Ggx(..) => return None,
            };
            let mut built = BUILT.lock().unwrap_or_else(|e| e.into_inner());
            if let Some((_, bytes)) = built.iter().find(|b| b.0 == key) {
                return Some(bytes.clone());
            }
            let n = gen_sh::choose_bands(&model, GLOSSY_TARGET);
            let (_, bytes) = gen_sh::choose_table(&model, n, GLOSSY_TARGET);
            built.push((key, bytes.clone()));
            Some(bytes)
        };
        let parts = scene
            .materials
            .iter()
            .map(|m| {
                specular_parts(m)
                    .filter_map(|(key, scale)| {
                        Some(GlossyPart {
                            table: table_of(key)?,
                            scale,
                        })
                    })
                    .collect()
            })
            .collect();
        Glossy { parts }
    }

    /// The parts' tables read once (validated), for [`indirect`]: per material, each part's
    /// table and RGB scale. A table that fails validation is left out (the tables come from
    /// the generator, so none does).
    pub fn views(&self) -> GlossyViews<'_> {
        GlossyViews {
            parts: self
                .parts
                .iter()
                .map(|ps| {
                    ps.iter()
                        .filter_map(|p| Some((brdf::BrdfSh::from_bytes(&p.table).ok()?, p.scale)))
                        .collect()
                })
                .collect(),
        }
    }
}

/// [`Glossy`]'s tables, read: per material, each part's table and RGB scale.
pub struct GlossyViews<'a> {
    /// Per material, its parts.
    pub parts: Vec<Vec<(brdf::BrdfSh<'a>, Rgb)>>,
}

/// The indirect radiance at a shading point from the placed HVLs.
///
/// The receiver's diffuse part has Lambert coefficients that are zonal in its view frame
/// (the table's `m ≠ 0` entries are below `1e-6` of `F_0^0`, asserted in core), so each HVL
/// goes through [`core_hvl::contribution_zonal`] with the `m = 0` entries: `n` basis values
/// per HVL instead of `n²`. Each glossy part of `glossy` (its `F` looked up at the view's
/// `θₒ`) goes through the full [`core_hvl::contribution`]. One HVL's share is clamped at 0
/// per part (an HVL sends no negative light; the truncated SH can ring below 0), and its
/// shadow ray is cast once for all parts.
pub fn indirect(
    scene: &Scene,
    p: &ShadingPoint,
    at: &Placement,
    o: &Options,
    glossy: &GlossyViews<'_>,
    scratch: &mut Scratch,
) -> Rgb {
    indirect_parts(scene, p, at, o, glossy, true, scratch)
}

/// A receiver's view frame and `θₒ`, with the first `n` (clamped to 1 ..= the committed
/// Lambert table's bands) zonal coefficients `F_l = F_l^0` of that table at `θₒ` in
/// `zonal[..n]` (`coeffs`: scratch of at least `n²`); `None` where the point has no view
/// frame.
fn lambert_zonal(
    p: &ShadingPoint,
    n: usize,
    coeffs: &mut [f32],
    zonal: &mut [f32],
) -> Option<(steradian_core::frame::Frame, f32, usize)> {
    let table = brdf::lambert();
    let frame = brdf::view_frame(p.n.as_vec3(), p.wo.as_vec3()).ok()?;
    let theta = frame.to_local(p.wo.as_vec3()).z.clamp(-1.0, 1.0).acos();
    let n = n.clamp(1, table.bands());
    table
        .lookup_into(brdf::Part::WithCosine, theta, n, coeffs)
        .ok()?;
    for (l, z) in zonal.iter_mut().enumerate().take(n) {
        *z = coeffs[l * l + l];
    }
    Some((frame, theta, n))
}

/// [`indirect`] with the diffuse part left out where `diffuse` is false (the wgpu path
/// sums it on the GPU and only the glossy parts here).
fn indirect_parts(
    scene: &Scene,
    p: &ShadingPoint,
    at: &Placement,
    o: &Options,
    glossy: &GlossyViews<'_>,
    diffuse: bool,
    scratch: &mut Scratch,
) -> Rgb {
    let albedo = if diffuse {
        scene.materials[p.material].diffuse()
    } else {
        [0.0; 3]
    };
    let parts = glossy
        .parts
        .get(p.material)
        .map_or(&[][..], |v| v.as_slice());
    let Scratch {
        coeffs,
        zonal,
        sh,
        glossy: gcoeffs,
        diffuse_c,
        glossy_c,
        sh4,
        cull,
    } = scratch;
    let Some((frame, theta, n)) = lambert_zonal(p, o.bands, coeffs, zonal) else {
        return [0.0; 3];
    };
    // Each glossy part's `F` in the view frame (a part whose table cannot be read or looked
    // up is left out: the tables are built by `Glossy::build`, so this does not happen).
    gcoeffs.resize_with(parts.len(), Vec::new);
    let mut live = [false; super::material::MAX_LOBES];
    for (((t, _), f), on) in parts.iter().zip(gcoeffs.iter_mut()).zip(live.iter_mut()) {
        let nb = t.bands();
        f.resize(nb * nb, 0.0);
        if sh.len() < f.len() {
            sh.resize(f.len(), 0.0);
        }
        *on = t.lookup_into(brdf::Part::WithCosine, theta, nb, f).is_ok();
    }
    let diffuse = albedo.iter().any(|&a| a != 0.0);
    if !diffuse && !live.iter().any(|&on| on) {
        return [0.0; 3];
    }
    let rx = core_hvl::ZonalReceiver {
        point: p.x.as_vec3(),
        frame,
        coeffs: &zonal[..n],
    };
    let emission = core_hvl::lambert_emission(1.0);
    // The SIMD path: every HVL's share of each part first, batched, but for the
    // receiver's own object's HVLs (`Placement::own`), which stay 0.
    let (lights, hvls) = (&at.lights[..], &at.placed[..]);
    let own = at.own.get(p.object).cloned().unwrap_or(0..0);
    let batched = o.simd && !hvls.is_empty();
    // `kernel(lights, out)` over the HVLs before and after the own range; all 0 on error.
    let around = |out: &mut [f32], kernel: &mut dyn FnMut(&[core_hvl::Hvl], &mut [f32]) -> bool| {
        let (before, rest) = out.split_at_mut(own.start);
        let (mine, after) = rest.split_at_mut(own.len());
        mine.fill(0.0);
        if !(kernel(&lights[..own.start], before) && kernel(&lights[own.end..], after)) {
            out.fill(0.0);
        }
    };
    if batched {
        let horizon = core_hvl::Horizon::Smoothstep;
        diffuse_c.resize(hvls.len(), 0.0);
        if diffuse {
            around(diffuse_c, &mut |l, out| {
                steradian_simd::sh::hvl::contributions_zonal(l, &emission, &rx, horizon, sh, out)
                    .is_ok()
            });
        } else {
            diffuse_c.fill(0.0);
        }
        glossy_c.resize_with(parts.len(), Vec::new);
        for ((f, on), out) in gcoeffs.iter().zip(&live).zip(glossy_c.iter_mut()) {
            out.resize(hvls.len(), 0.0);
            let grx = core_hvl::Receiver {
                point: p.x.as_vec3(),
                frame,
                coeffs: f,
            };
            sh4.resize(f.len().max(1), [0.0; 4]);
            if *on {
                around(out, &mut |l, o| {
                    steradian_simd::sh::hvl::contributions(l, &emission, &grx, horizon, sh4, o)
                        .is_ok()
                });
            } else {
                out.fill(0.0);
            }
        }
    }
    let origin = path::offset(p.x, p.n);
    if o.visibility {
        cull.receiver(scene, at, origin);
    }
    let mut acc = [0.0f64; 3];
    let mut gacc = [[0.0f64; 3]; super::material::MAX_LOBES];
    let mut shares = [0.0f64; super::material::MAX_LOBES];
    for (j, h) in hvls.iter().enumerate() {
        if own.contains(&j) {
            continue;
        }
        let c = if batched {
            f64::from(diffuse_c[j].max(0.0))
        } else if diffuse {
            core_hvl::contribution_zonal(&h.hvl, &emission, &rx, core_hvl::Horizon::Smoothstep, sh)
                .unwrap_or(0.0)
                .max(0.0) as f64
        } else {
            0.0
        };
        let mut any = c > 0.0;
        for (k, ((f, on), share)) in gcoeffs.iter().zip(&live).zip(shares.iter_mut()).enumerate() {
            *share = 0.0;
            if batched {
                *share = f64::from(glossy_c.get(k).map_or(0.0, |g| g[j]).max(0.0));
                any |= *share > 0.0;
            } else if *on {
                let grx = core_hvl::Receiver {
                    point: p.x.as_vec3(),
                    frame,
                    coeffs: f,
                };
                *share = core_hvl::contribution(
                    &h.hvl,
                    &emission,
                    &grx,
                    core_hvl::Horizon::Smoothstep,
                    sh,
                )
                .unwrap_or(0.0)
                .max(0.0) as f64;
                any |= *share > 0.0;
            }
        }
        if !any {
            continue;
        }
        if o.visibility {
            let (ray, t_max) = shadow_ray(origin, h);
            if cull.blocked(scene, &ray, t_max) {
                continue;
            }
        }
        for (a, w) in acc.iter_mut().zip(h.weight) {
            *a += c * w;
        }
        for (g, share) in gacc.iter_mut().zip(&shares).take(parts.len()) {
            for (a, w) in g.iter_mut().zip(h.weight) {
                *a += share * w;
            }
        }
    }
    let mut out: Rgb = core::array::from_fn(|k| acc[k] * albedo[k]);
    for ((_, scale), g) in parts.iter().zip(&gacc) {
        for k in 0..3 {
            out[k] += g[k] * scale[k];
        }
    }
    out
}

/// The shadow rays of both paths stop at `d·(1 − ε)` before the HVL (which lies on a
/// surface the ray would otherwise end on).
const SHADOW_EPS: f32 = 1e-4;

/// Receivers per dispatch of the wgpu path.
pub const GPU_BATCH: usize = 4096;

/// The table of `steradian_core::wgsl::SH_HVL_SUM`: the HVLs (Lambertian emitters, each with
/// the object it lies on, which its shadow rays skip) and every object of the scene as an
/// occluder.
fn gpu_sum_table(scene: &Scene, hvls: &[Placed], bands: usize, visibility: bool) -> Vec<f32> {
    let mut t = vec![
        hvls.len() as f32,
        scene.objects.len() as f32,
        bands as f32,
        if visibility { 1.0 } else { 0.0 },
        SHADOW_EPS,
    ];
    for h in hvls {
        let (p, n) = (h.hvl.position(), h.hvl.frame().normal());
        t.extend([p.x, p.y, p.z, n.x, n.y, n.z, h.hvl.radius(), h.hvl.power()]);
        t.extend(h.weight.map(|w| w as f32));
        t.push(h.object as f32);
    }
    for obj in &scene.objects {
        t.extend(match obj.shape {
            super::Shape::Sphere { center: c, radius } => {
                [0.0, c.x, c.y, c.z, radius, 0.0, 0.0].map(|v| v as f32)
            }
            super::Shape::Plane {
                point: a,
                normal: n,
            } => [1.0, a.x, a.y, a.z, n.x, n.y, n.z].map(|v| v as f32),
        });
    }
    t
}

/// [`render`] with the diffuse indirect light and the direct light on the wgpu backend: the
/// direct light by the `lobes` method's wgpu path ([`lobes::render_gpu`], within
/// `steradian_core::wgsl::LOBE_CHAIN_REL_TOL` of its scalar path), the receivers' glossy
/// parts on the CPU as [`render`] computes them, and each receiver's diffuse sum over the
/// HVLs by `steradian_core::wgsl::SH_HVL_SUM` ([`GPU_BATCH`] receivers per dispatch, the
/// shadow rays against the scene's spheres and planes in `f32` from the CPU path's origin,
/// skipping the object the HVL lies on: in `f32` a ray grazing a plane toward an HVL on it
/// meets the plane before its end), times the receiver's diffuse albedo; it sums the
/// receiver's own object's HVLs too, which the CPU skips ([`Placement`]: they send a
/// rounding's worth). Each receiver's sum is within `steradian_core::wgsl::SH_HVL_SUM_TOL`
/// of the CPU's wherever no shadow ray flips between `f32` and `f64` (harness test
/// `hvl_gpu_path_matches_the_cpu_path` in `tests/scene.rs`). Every pixel is computed,
/// whatever `o.stride` (the plan sets it to 1 with `--gpu`).
///
/// Errors: the kernel's.
pub fn render_gpu(
    scene: &Scene,
    o: &Options,
    gpu: &mut crate::backend::gpu::Gpu,
    bar: &ProgressBar,
) -> Result<(Image, usize), String> {
    use crate::backend::gpu::Custom;
    use crate::kernels::Columns;
    let glossy = Glossy::of(scene, o);
    let views = glossy.views();
    let at = Placement::new(scene, place(scene, o.side));
    let hvls = &at.placed;
    let nb = o.bands.clamp(1, brdf::lambert().bands());
    let table = gpu_sum_table(scene, hvls, nb, o.visibility);
    // The direct light by the `lobes` method's wgpu path, the glossy indirect parts on the
    // CPU beside it.
    let (direct, _) = lobes::render_gpu(scene, &o.direct, gpu, &ProgressBar::hidden())?;
    let width = scene.camera.width as usize;
    let (mut img, _, _) = super::render_centres_x8_at(
        scene,
        bar,
        Scratch::default,
        |scratch, pixels, points, out| {
            for ((&(i, j), p), o_k) in pixels.iter().zip(points).zip(out.iter_mut()) {
                let d = direct.data[j * width + i];
                let g = indirect_parts(scene, p, &at, o, &views, false, scratch);
                *o_k = [d[0] + g[0], d[1] + g[1], d[2] + g[2]];
            }
        },
    );
    // The receivers with a diffuse part: pixel, albedo and the kernel's input row.
    let cam = scene.camera;
    let (w, h) = (cam.width as usize, cam.height as usize);
    let mut rows: Vec<(usize, Rgb, Vec<f32>)> = Vec::new();
    let (mut coeffs, mut zonal) = (vec![0.0f32; nb * nb], vec![0.0f32; nb]);
    for j in 0..h {
        for i in 0..w {
            let super::Seen::Surface(p) = scene.see(&cam.centre_ray(i as u32, j as u32)) else {
                continue;
            };
            let albedo = scene.materials[p.material].diffuse();
            if albedo.iter().all(|&a| a == 0.0) {
                continue;
            }
            let Some((frame, _, _)) = lambert_zonal(&p, nb, &mut coeffs, &mut zonal) else {
                continue;
            };
            let origin = path::offset(p.x, p.n);
            let (x, n) = (p.x.as_vec3(), frame.normal());
            let mut row = vec![x.x, x.y, x.z, n.x, n.y, n.z];
            row.extend([origin.x as f32, origin.y as f32, origin.z as f32]);
            row.extend(&zonal[..nb]);
            rows.push((j * w + i, albedo, row));
        }
    }
    let arity = 9 + nb;
    let custom = Custom {
        label: "hvl-sum",
        source: steradian_core::wgsl::SH_HVL_SUM,
        table: Some(&table),
    };
    for chunk in rows.chunks(GPU_BATCH) {
        let mut input = Columns::zeros(arity, chunk.len());
        for (r, (_, _, row)) in chunk.iter().enumerate() {
            for (c, v) in row.iter().enumerate() {
                input.col_mut(c)[r] = *v;
            }
        }
        let mut out = Columns::zeros(3, chunk.len());
        gpu.run_custom(&custom, &input, &mut out)
            .map_err(|e| format!("hvl-sum kernel: {e}"))?;
        for (r, (k, albedo, _)) in chunk.iter().enumerate() {
            for (c, (px, a)) in img.data[*k].iter_mut().zip(albedo).enumerate() {
                *px += f64::from(out.col(c)[r]) * a;
            }
        }
    }
    Ok((img, hvls.len()))
}

/// The reflective-shadow-map face sides a plan tries, smallest first ([`choose_side`]):
/// `6·side²` HVLs per light.
pub const SIDE_CANDIDATES: [usize; 5] = [2, 4, 8, 12, 16];

/// What [`choose_side`] chose and what it measured.
#[derive(Clone, Debug)]
pub struct SideChoice {
    /// The chosen face side.
    pub side: usize,
    /// `(side, estimate)`: the probes' mean |difference| from the largest candidate over its
    /// largest value ([`super::probe_estimates`]).
    pub estimates: Vec<(usize, f64)>,
}

/// The smallest face side of [`SIDE_CANDIDATES`] whose HVLs keep the shaded probes within
/// [`super::PLAN_SHARE`] of `target` (mean |difference| over the maximum radiance, the
/// render's measure) of the largest candidate's. The probes are the [`super::probe_points`] grid; each is lit by
/// the same direct light (`o.direct`) for every side, so the difference is the HVL count's
/// alone, and the largest value includes the direct light as the render's does. The rest
/// of the target is left to the direct light and to the HVL approximation itself. The
/// largest candidate if none is within.
pub fn choose_side(scene: &Scene, o: &Options, target: f64) -> SideChoice {
    let images = probe_images(scene, o, &SIDE_CANDIDATES, |side| {
        (place(scene, side), o.bands)
    });
    let (side, estimates) = super::plan_choice(&SIDE_CANDIDATES, &images, target)
        .unwrap_or((SIDE_CANDIDATES[0], Vec::new()));
    SideChoice { side, estimates }
}

/// The probes ([`super::probe_points`]) shaded with the direct light of `o` plus the
/// indirect light of each candidate's HVLs and receiver bands (`setting(candidate)`).
fn probe_images<T: Copy>(
    scene: &Scene,
    o: &Options,
    candidates: &[T],
    setting: impl Fn(T) -> (Vec<Placed>, usize),
) -> Vec<Vec<Rgb>> {
    let probes = super::probe_points(scene);
    let mut counts = ProductCounts::default();
    let direct: Vec<Rgb> = probes
        .iter()
        .map(|p| lobes::shade(scene, p, &o.direct, &mut counts))
        .collect();
    let mut scratch = Scratch::default();
    let glossy = Glossy::of(scene, o);
    let glossy = glossy.views();
    candidates
        .iter()
        .map(|&c| {
            let (placed, bands) = setting(c);
            let at = Placement::new(scene, placed);
            let oc = Options { bands, ..*o };
            probes
                .iter()
                .zip(&direct)
                .map(|(p, d)| {
                    let i = indirect(scene, p, &at, &oc, &glossy, &mut scratch);
                    [d[0] + i[0], d[1] + i[1], d[2] + i[2]]
                })
                .collect()
        })
        .collect()
}

/// What [`choose_bands`] chose and what it measured.
#[derive(Clone, Debug)]
pub struct BandsChoice {
    /// The chosen band count.
    pub bands: usize,
    /// `(bands, estimate)`: the probes' mean |difference| from the committed table's full 5
    /// bands over its largest value ([`super::probe_estimates`]).
    pub estimates: Vec<(usize, f64)>,
}

/// The fewest bands (1 to the committed Lambert table's 5) of the receivers' diffuse part
/// that keep the probes within [`super::PLAN_SHARE`] of `target` of the full table's, with
/// `o`'s HVLs (the rule of [`choose_side`]): the clamped cosine's zonal coefficients fall as
/// `l^−2.5` and vanish for odd `l > 1`, so a loose target needs fewer bands than the
/// paper's.
pub fn choose_bands(scene: &Scene, o: &Options, target: f64) -> BandsChoice {
    let full = brdf::lambert().bands();
    let candidates: Vec<usize> = (1..=full).collect();
    let hvls = place(scene, o.side);
    let images = probe_images(scene, o, &candidates, |b| (hvls.clone(), b));
    let (bands, estimates) =
        super::plan_choice(&candidates, &images, target).unwrap_or((full, Vec::new()));
    BandsChoice { bands, estimates }
}

/// What [`choose_stride`] chose and what it measured.
#[derive(Clone, Debug)]
pub struct StrideChoice {
    /// The chosen lattice spacing.
    pub stride: usize,
    /// `(stride, estimate)`: the probes' mean |difference| from every pixel computed over
    /// the largest value ([`super::probe_estimates`]).
    pub estimates: Vec<(usize, f64)>,
}

/// The coarsest lattice spacing of [`lattice::STRIDE_CANDIDATES`] whose interpolation of
/// the indirect light keeps the probe pixels within [`super::PLAN_SHARE`] of `target` of
/// every pixel computed (the rule of [`choose_side`]), each probe shaded as a strided
/// render shades it ([`lattice::strided_probes`]), the direct light added to every
/// candidate alike.
pub fn choose_stride(scene: &Scene, o: &Options, target: f64) -> StrideChoice {
    let probes = super::probe_pixels(scene);
    let at = Placement::new(scene, place(scene, o.side));
    let glossy = Glossy::of(scene, o);
    let glossy = glossy.views();
    let mut scratch = Scratch::default();
    let mut counts = ProductCounts::default();
    let direct: Vec<Rgb> = probes
        .iter()
        .map(|(_, _, p)| lobes::shade(scene, p, &o.direct, &mut counts))
        .collect();
    let own: Vec<Rgb> = probes
        .iter()
        .map(|(_, _, p)| indirect(scene, p, &at, o, &glossy, &mut scratch))
        .collect();
    let images = lattice::strided_probes(scene, &probes, &own, &direct, |p| {
        indirect(scene, p, &at, o, &glossy, &mut scratch)
    });
    let (stride, estimates) =
        super::plan_choice(&lattice::STRIDE_CANDIDATES, &images, target).unwrap_or((1, Vec::new()));
    StrideChoice { stride, estimates }
}

/// Direct light by the `lobes` method ([`lobes::shade_x8`], or [`lobes::shade`] without
/// `o.simd`, refined at `o.direct.footprint` by [`lobes::refine_image`]) plus one bounce
/// from HVLs at pixel centres, the indirect light interpolated on a [`lattice::Lattice`] of
/// spacing `o.stride` when it is above 1 (indirect light from hundreds of HVLs varies
/// slowly across a surface: each HVL's share is smooth in the receiver's position and
/// normal, and the glossy parts are band-limited by their SH tables; so a pixel's mean
/// takes its centre's); returns the image and the HVL count.
pub fn render(scene: &Scene, o: &Options, bar: &ProgressBar) -> (Image, usize) {
    let at = Placement::new(scene, place(scene, o.side));
    let glossy = Glossy::of(scene, o);
    let glossy = glossy.views();
    let lattice = (o.stride > 1).then(|| {
        lattice::Lattice::build(scene, o.stride, Scratch::default, |scratch, p| {
            indirect(scene, p, &at, o, &glossy, scratch)
        })
    });
    let width = scene.camera.width as usize;
    // One centre pass: the direct light into the image, each pixel's indirect light beside
    // it (row by row); the direct light refined, then the indirect light added.
    let new_state = || (ProductCounts::default(), Scratch::default(), Vec::new());
    let (mut img, rows, objects) = super::render_centres_x8_at(
        scene,
        bar,
        new_state,
        |(counts, scratch, ind), pix, ps, out| {
            if o.simd {
                lobes::shade_x8(scene, ps, &o.direct, counts, out);
            } else {
                for (p, d) in ps.iter().zip(out.iter_mut()) {
                    *d = lobes::shade(scene, p, &o.direct, counts);
                }
            }
            for (&(i, j), p) in pix.iter().zip(ps) {
                let v = lattice
                    .as_ref()
                    .and_then(|l| l.interpolate(i, j, p))
                    .unwrap_or_else(|| indirect(scene, p, &at, o, &glossy, scratch));
                ind.push((j * width + i, v));
            }
        },
    );
    lobes::refine_image(scene, &mut img, &objects, &o.direct, o.simd);
    for (_, _, ind) in rows {
        for (k, v) in ind {
            let d = &mut img.data[k];
            *d = [d[0] + v[0], d[1] + v[1], d[2] + v[2]];
        }
    }
    (img, at.placed.len())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The culled shadow test against `Scene::occluded` on every object, for every HVL of a
    /// placement from probe points: on the closed `room` (every wall culled), on `room`
    /// with one wall turned outward (its HVLs behind it: never culled), and on `lobes`
    /// (an open floor).
    #[test]
    fn culled_shadow_rays_match_every_object_tested() {
        let mut flipped = Scene::load("builtin:room").unwrap();
        let wall = flipped
            .objects
            .iter()
            .position(|o| matches!(o.shape, Shape::Plane { .. }))
            .unwrap();
        if let Shape::Plane { normal, .. } = &mut flipped.objects[wall].shape {
            *normal = -*normal;
        }
        let mut culled_walls = 0;
        for scene in [
            Scene::load("builtin:room").unwrap(),
            flipped,
            Scene::load("builtin:lobes").unwrap(),
        ] {
            let at = Placement::new(&scene, place(&scene, 4));
            let mut cull = ShadowCull::default();
            let (mut pairs, mut blocked) = (0, 0);
            for p in super::super::probe_points(&scene) {
                let origin = path::offset(p.x, p.n);
                cull.receiver(&scene, &at, origin);
                culled_walls += scene.objects.len() - cull.tests.len();
                for h in &at.placed {
                    let (ray, t_max) = shadow_ray(origin, h);
                    let all = scene.occluded(&ray, 0.0, t_max);
                    let some = cull.blocked(&scene, &ray, t_max);
                    assert_eq!(all, some, "HVL on object {} from {origin}", h.object);
                    pairs += 1;
                    blocked += usize::from(all);
                }
            }
            assert!(
                pairs > 10_000 && blocked > 100,
                "{pairs} pairs, {blocked} blocked"
            );
        }
        assert!(culled_walls > 1000, "{culled_walls}");
    }

    /// A receiver's own object's HVLs, which `indirect` skips, send it at most a rounding's
    /// worth by the kernel (at most `1e-5` of the largest other HVL's share), on every
    /// surface pixel of `room` at 32 columns (planes and spheres); the placement's ranges
    /// hold exactly each object's HVLs.
    #[test]
    fn own_object_hvls_send_nothing() {
        let mut scene = Scene::load("builtin:room").unwrap();
        scene.camera = scene.camera.resized(32).unwrap();
        let at = Placement::new(&scene, place(&scene, 4));
        for (id, r) in at.own.iter().enumerate() {
            assert!(at.placed[r.clone()].iter().all(|h| h.object == id));
        }
        assert_eq!(
            at.own.iter().map(|r| r.len()).sum::<usize>(),
            at.placed.len()
        );
        let emission = core_hvl::lambert_emission(1.0);
        let (mut coeffs, mut zonal, mut sh) = (vec![0.0; 25], vec![0.0; 5], vec![0.0; 25]);
        let mut receivers = 0;
        for j in 0..scene.camera.height {
            for i in 0..scene.camera.width {
                let super::super::Seen::Surface(p) = scene.see(&scene.camera.centre_ray(i, j))
                else {
                    continue;
                };
                let Some((frame, _, n)) = lambert_zonal(&p, 3, &mut coeffs, &mut zonal) else {
                    continue;
                };
                let rx = core_hvl::ZonalReceiver {
                    point: p.x.as_vec3(),
                    frame,
                    coeffs: &zonal[..n],
                };
                let mut share = |h: &Placed| {
                    core_hvl::contribution_zonal(
                        &h.hvl,
                        &emission,
                        &rx,
                        core_hvl::Horizon::Smoothstep,
                        &mut sh,
                    )
                    .unwrap_or(0.0)
                };
                let (mut mine, mut others) = (0.0f32, 0.0f32);
                for h in &at.placed {
                    let c = share(h);
                    if h.object == p.object {
                        mine = mine.max(c);
                    } else {
                        others = others.max(c);
                    }
                }
                assert!(
                    others > 0.0 && mine <= 1e-5 * others,
                    "({i}, {j}): {mine:e} {others:e}"
                );
                receivers += 1;
            }
        }
        assert!(receivers > 300, "{receivers}");
    }
}
