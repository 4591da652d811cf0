//! The one registry of kernels: a description per kernel, from which `steradian eval`
//! (handler and help), the report's main table (batch kernels, metric, bound), the GPU
//! parity tests and the criterion benches are driven, and which the coverage test
//! (`tests/main.rs`, module `coverage`) checks for missing pieces.
//!
//! Adding a kernel means: its scalar source in `core/src/<paper>/`, its SIMD twin at the same
//! path in `simd/src/<paper>/`, its WGSL twin beside the scalar source (listed in
//! `steradian_core::wgsl::ALL` or `CUSTOM`), its f64 reference, one entry in [`KERNELS`],
//! and its tests. A piece a kernel deliberately lacks is [`Piece::Without`] with the reason.

use serde_json::{Map, Value};
use steradian_core::wgsl;

use crate::batch;
use crate::kernels::Kernel;
use crate::{handlers, product, sat, vdt};

/// An `eval` handler: one validated JSON object in, the answer (or the message of the
/// line's `{"error": …}`) out.
pub type EvalFn = fn(&Map<String, Value>) -> Result<Value, String>;

/// One piece of a kernel (its SIMD twin, its reference, …): where it is, or why the kernel
/// deliberately has none.
#[derive(Clone, Copy, Debug)]
pub enum Piece<T> {
    /// The piece.
    At(T),
    /// Deliberately absent, with the reason (the coverage test requires one).
    Without(&'static str),
}

impl<T: Copy> Piece<T> {
    /// The piece, if the kernel has it.
    pub fn get(&self) -> Option<T> {
        match self {
            Piece::At(t) => Some(*t),
            Piece::Without(_) => None,
        }
    }
}

/// The paper a kernel implements (its folder in `core/src` and `simd/src`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Paper {
    /// `lobe/`: cosine lobes, cap → lobe fits, lobe products and sums (Meunier et al.).
    Lobe,
    /// `rsl/`: rotatable square lights, SAT, VDT, shading (Xu et al.).
    Rsl,
    /// `sh/`: real spherical harmonics and the projections of the HVL paper (Mézières et al.).
    Sh,
    /// `cp/`: control-point spherical functions on a subdivided icosahedron (Chatelier and
    /// Malgouyres).
    Cp,
}

impl Paper {
    /// The folder of the paper in `core/src/` and `simd/src/`.
    pub fn folder(self) -> &'static str {
        match self {
            Paper::Lobe => "lobe",
            Paper::Rsl => "rsl",
            Paper::Sh => "sh",
            Paper::Cp => "cp",
        }
    }
}

/// A kernel's WGSL twin: its source (a constant of `steradian_core::wgsl`, which lists it in
/// `ALL`, or in `CUSTOM` when the caller binds a table), its tolerance constant against the
/// scalar kernel, and the element type of binding 3 for a custom kernel.
#[derive(Clone, Copy, Debug)]
pub struct WgslTwin {
    /// The complete shader source.
    pub source: &'static str,
    /// Path of the tolerance constant in `steradian_core::wgsl`.
    pub tolerance: &'static str,
    /// `None` for a built-in kernel (`wgsl::ALL`), else the caller table's element type.
    pub table: Option<&'static str>,
}

/// A kernel's documented error bound against the exact quantity.
#[derive(Clone, Copy, Debug)]
pub struct Bound {
    /// The metric, as `report.json` names it.
    pub metric: &'static str,
    /// Path of the item whose docs state the bound (a constant where it is one number).
    pub item: &'static str,
    /// The bound in `metric`, where it is one number (the report's main table prints it).
    pub value: Option<f64>,
}

/// The description of one kernel.
#[derive(Clone, Copy, Debug)]
pub struct KernelSpec {
    /// Its name in `steradian eval`, `report.json` and the WGSL registry.
    pub name: &'static str,
    /// Its paper (folder).
    pub paper: Paper,
    /// `eval` input → output, for `--help` and the README.
    pub contract: &'static str,
    /// The `eval` handler.
    pub eval: Piece<EvalFn>,
    /// Path of the scalar kernel (the one truth the twins are tested against).
    pub scalar: &'static str,
    /// Path of the SIMD twin.
    pub simd: Piece<&'static str>,
    /// The WGSL twin.
    pub wgsl: Piece<WgslTwin>,
    /// Path of the f64 reference or brute force.
    pub reference: Piece<&'static str>,
    /// The error bound.
    pub bound: Piece<Bound>,
    /// The batch kernel of the backends, for kernels of fixed arity without a caller table:
    /// these fill the report's main table, the backend parity tests and `benches/kernels`.
    pub batch: Option<Kernel>,
    /// The tables a table-driven kernel reads: built-in table names, or what the caller
    /// builds.
    pub tables: &'static [&'static str],
}

/// The bound of both shading kernels: eq. 13 of the RSL paper bounds the multi-product
/// error of eq. 5 (tested against random functions in `steradian_core::rsl::shade`).
const SHADE_BOUND: Bound = Bound {
    metric: "multi-product-abs (eq. 13)",
    item: "steradian_core::rsl::shade::multi_product_bound",
    value: None,
};

/// Every kernel, in report order.
pub const KERNELS: &[KernelSpec] = &[
    KernelSpec {
        name: batch::rsl::HEMISPHERE_MAP.name(),
        paper: Paper::Rsl,
        contract: r#"{"dir": [x,y,z] with z ≥ 0, any non-zero length} -> {"p": [u,v]}"#,
        eval: Piece::At(handlers::hemisphere_map),
        scalar: "steradian_core::rsl::hemisphere::map",
        simd: Piece::At("steradian_simd::rsl::hemisphere::map_slices"),
        wgsl: Piece::At(WgslTwin {
            source: wgsl::HEMISPHERE_MAP,
            tolerance: "steradian_core::wgsl::HEMISPHERE_MAP_ABS_TOL",
            table: None,
        }),
        reference: Piece::At("steradian_reference::rsl::hemisphere_map"),
        bound: Piece::At(Bound {
            metric: "abs",
            item: "steradian_core::rsl::hemisphere::MAP_ABS_ERROR",
            value: Some(steradian_core::rsl::hemisphere::MAP_ABS_ERROR as f64),
        }),
        batch: Some(batch::rsl::HEMISPHERE_MAP),
        tables: &[],
    },
    KernelSpec {
        name: batch::rsl::HEMISPHERE_UNMAP.name(),
        paper: Paper::Rsl,
        contract: r#"{"p": [u,v] with u²+v² ≤ 1} -> {"dir": [x,y,z]}"#,
        eval: Piece::At(handlers::hemisphere_unmap),
        scalar: "steradian_core::rsl::hemisphere::unmap",
        simd: Piece::At("steradian_simd::rsl::hemisphere::unmap_slices"),
        wgsl: Piece::At(WgslTwin {
            source: wgsl::HEMISPHERE_UNMAP,
            tolerance: "steradian_core::wgsl::HEMISPHERE_UNMAP_ABS_TOL",
            table: None,
        }),
        reference: Piece::At("steradian_reference::rsl::hemisphere_unmap"),
        bound: Piece::At(Bound {
            metric: "abs",
            item: "steradian_core::rsl::hemisphere::UNMAP_ABS_ERROR",
            value: Some(steradian_core::rsl::hemisphere::UNMAP_ABS_ERROR as f64),
        }),
        batch: Some(batch::rsl::HEMISPHERE_UNMAP),
        tables: &[],
    },
    KernelSpec {
        name: batch::lobe::LOBE_EVAL.name(),
        paper: Paper::Lobe,
        contract: r#"{"axis": [x,y,z], "exponent": e, "scale": s (default 1), "dir": [x,y,z]} -> {"value": s·max(a·v,0)^e}"#,
        eval: Piece::At(handlers::lobe_eval),
        scalar: "steradian_core::lobe::eval",
        simd: Piece::At("steradian_simd::lobe::eval_slices"),
        wgsl: Piece::At(WgslTwin {
            source: wgsl::LOBE_EVAL,
            tolerance: "steradian_core::wgsl::LOBE_EVAL_REL_TOL",
            table: None,
        }),
        reference: Piece::At("steradian_reference::lobe::lobe_eval"),
        bound: Piece::At(Bound {
            metric: "rel/κ",
            item: "steradian_core::lobe::EVAL_REL_ERROR",
            value: Some(steradian_core::lobe::EVAL_REL_ERROR as f64),
        }),
        batch: Some(batch::lobe::LOBE_EVAL),
        tables: &[],
    },
    KernelSpec {
        name: batch::lobe::LOBE_INTEGRAL.name(),
        paper: Paper::Lobe,
        contract: r#"{"exponent": e, "scale": s (default 1)} -> {"integral": 2πs/(e+1)}"#,
        eval: Piece::At(handlers::lobe_integral),
        scalar: "steradian_core::lobe::integral",
        simd: Piece::At("steradian_simd::lobe::integral_slices"),
        wgsl: Piece::At(WgslTwin {
            source: wgsl::LOBE_INTEGRAL,
            tolerance: "steradian_core::wgsl::LOBE_INTEGRAL_ULP_TOL",
            table: None,
        }),
        reference: Piece::At("steradian_reference::lobe::lobe_integral"),
        bound: Piece::At(Bound {
            metric: "rel",
            item: "steradian_core::lobe::INTEGRAL_REL_ERROR",
            value: Some(steradian_core::lobe::INTEGRAL_REL_ERROR as f64),
        }),
        batch: Some(batch::lobe::LOBE_INTEGRAL),
        tables: &[],
    },
    KernelSpec {
        name: batch::lobe::CAP_EXPONENT.name(),
        paper: Paper::Lobe,
        contract: r#"{"half_angle": α in [1e-18, π/2]} -> {"exponent": e} (L2 fit, from the table)"#,
        eval: Piece::At(handlers::cap_exponent),
        scalar: "steradian_core::lobe::cap::exponent_l2",
        simd: Piece::At("steradian_simd::lobe::cap::exponent_l2_slices"),
        wgsl: Piece::At(WgslTwin {
            source: wgsl::CAP_EXPONENT,
            tolerance: "steradian_core::wgsl::CAP_EXPONENT_REL_TOL",
            table: None,
        }),
        reference: Piece::At("steradian_reference::lobe::cap::optimal_exponent"),
        bound: Piece::At(Bound {
            metric: "excess-L2-rel",
            item: "steradian_core::lobe::cap::EXCESS_L2_REL",
            value: Some(steradian_core::lobe::cap::EXCESS_L2_REL),
        }),
        batch: Some(batch::lobe::CAP_EXPONENT),
        tables: &["cap_exponent.bin"],
    },
    KernelSpec {
        name: "lobe-product",
        paper: Paper::Lobe,
        contract: r#"{"e1": e1, "e2": e2, "alpha": α} -> {"scale": p, "exponent": e_r, "axis_angle": β, "integral": 2πp/(e_r+1)} (unit lobes, a1 = +z, a2 toward +x)"#,
        eval: Piece::At(product::eval_lobe_product),
        scalar: "steradian_core::lobe::product::product_with",
        simd: Piece::At("steradian_simd::lobe::product::product_slices"),
        wgsl: Piece::At(WgslTwin {
            source: wgsl::LOBE_PRODUCT,
            tolerance: "steradian_core::wgsl::LOBE_PRODUCT_TOL",
            table: Some("f32"),
        }),
        reference: Piece::At("steradian_reference::lobe::product::product_integral"),
        bound: Piece::At(Bound {
            metric: "integral-rel-max",
            item: "steradian_core::lobe::product::INTEGRAL_REL_MAX",
            value: Some(steradian_core::lobe::product::INTEGRAL_REL_MAX),
        }),
        batch: None,
        tables: &["lobe_product.bin"],
    },
    KernelSpec {
        name: "sat-box",
        paper: Paper::Rsl,
        contract: r#"{"grid": [[t00, t10, …], …] (rows in v), "queries": [[u0, v0, u1, v1], …] (texel units)} -> {"values": [∫ over each box]}"#,
        eval: Piece::At(sat::eval_sat_box),
        scalar: "steradian_core::rsl::sat::SatView::box_sum",
        simd: Piece::At("steradian_simd::rsl::sat::box_sum_slices"),
        wgsl: Piece::At(WgslTwin {
            source: wgsl::SAT_BOX,
            tolerance: "steradian_core::wgsl::SAT_BOX_REL_TOL",
            table: Some("u32"),
        }),
        reference: Piece::At("steradian_harness::sat::Grid::reference"),
        bound: Piece::At(Bound {
            metric: "abs/(2⁻²⁴·|I| + n·2⁻⁵⁹·T)",
            item: "steradian_harness::sat::error_bound",
            value: None,
        }),
        batch: None,
        tables: &["the caller's grid (steradian_core::rsl::sat::Sat::build)"],
    },
    KernelSpec {
        name: "vdt-box",
        paper: Paper::Rsl,
        contract: r#"{"mask": ["0110…", …] rows of '0'/'1' ('1' visible, row j along v), "queries": [[u, v, r], …] centre and half-diagonal in texel units} -> {"values": [visible fraction, eq. 9], "values_gradient": [straight-edge variant]}"#,
        eval: Piece::At(vdt::eval_vdt_box),
        scalar: "steradian_core::rsl::vdt::VdtView::query",
        simd: Piece::At("steradian_simd::rsl::vdt::query_slices"),
        wgsl: Piece::At(WgslTwin {
            source: wgsl::VDT_QUERY,
            tolerance: "steradian_core::wgsl::VDT_QUERY_TOL",
            table: Some("f32"),
        }),
        reference: Piece::At("steradian_reference::rsl::vdt::brute_force_squares"),
        bound: Piece::At(Bound {
            metric: "visible-fraction-abs",
            item: "steradian_core::rsl::vdt::VdtView::query",
            value: None,
        }),
        batch: None,
        tables: &["the caller's mask (steradian_core::rsl::vdt::Vdt::build)"],
    },
    KernelSpec {
        name: "shade",
        paper: Paper::Rsl,
        contract: "",
        eval: Piece::Without(
            "a shading point needs a decomposed environment, a BRDF SAT and a VDT: the report's \
             shading section and the scenes drive it",
        ),
        scalar: "steradian_core::rsl::shade::shade",
        simd: Piece::At("steradian_simd::rsl::shade::shade_batch"),
        wgsl: Piece::At(WgslTwin {
            source: wgsl::SHADE,
            tolerance: "steradian_core::wgsl::SHADE_REL_TOL",
            table: Some("u32"),
        }),
        reference: Piece::At("steradian_harness::shade::reference"),
        bound: Piece::At(SHADE_BOUND),
        batch: None,
        tables: &[
            "BRDF SATs (steradian_core::rsl::brdf_sat)",
            "one VDT per point",
        ],
    },
    KernelSpec {
        name: "shade-moments",
        paper: Paper::Rsl,
        contract: "",
        eval: Piece::Without(
            "a shading point needs a decomposed environment, a BRDF SAT and visibility \
             moments: the report's shading section and the scenes drive it",
        ),
        scalar: "steradian_core::rsl::shade::shade_moments",
        simd: Piece::At("steradian_simd::rsl::shade::shade_moments_batch"),
        wgsl: Piece::At(WgslTwin {
            source: wgsl::SHADE_MOMENTS,
            tolerance: "steradian_core::wgsl::SHADE_MOMENTS_REL_TOL",
            table: Some("u32"),
        }),
        reference: Piece::At("steradian_harness::shade::reference"),
        bound: Piece::At(SHADE_BOUND),
        batch: None,
        tables: &[
            "BRDF SATs (steradian_core::rsl::brdf_sat)",
            "visibility moments per point (steradian_core::rsl::vis_moments)",
        ],
    },
    KernelSpec {
        name: "sh-eval",
        paper: Paper::Sh,
        contract: r#"{"dir": [x,y,z] non-zero, "bands": n in 1..=128} -> {"y": [n² values, index l²+l+m]}"#,
        eval: Piece::At(handlers::sh_eval),
        scalar: "steradian_core::sh::eval_into",
        simd: Piece::At("steradian_simd::sh::eval_slices"),
        wgsl: Piece::At(WgslTwin {
            source: wgsl::SH_EVAL,
            tolerance: "steradian_core::wgsl::SH_EVAL_TOL",
            table: Some("f32"),
        }),
        reference: Piece::At("steradian_reference::sh::eval"),
        bound: Piece::At(Bound {
            metric: "abs per band",
            item: "steradian_core::sh::eval_abs_error",
            value: None,
        }),
        batch: None,
        tables: &[],
    },
    KernelSpec {
        name: "sh-cap",
        paper: Paper::Sh,
        contract: r#"{"dir": [x,y,z] non-zero, "half_angle": a in [0, π], "bands": n in 1..=128} -> {"coeffs": [n² values of ∫_cap Y_l^m dω]}"#,
        eval: Piece::At(handlers::sh_cap),
        scalar: "steradian_core::sh::cap::coefficients_into",
        simd: Piece::At("steradian_simd::sh::cap::coefficients_slices"),
        wgsl: Piece::At(WgslTwin {
            source: wgsl::SH_CAP,
            tolerance: "steradian_core::wgsl::SH_CAP_TOL",
            table: Some("f32"),
        }),
        reference: Piece::At("steradian_reference::sh::cap_zonal"),
        bound: Piece::At(Bound {
            metric: "rel (zonal)",
            item: "steradian_core::sh::cap::ZONAL_REL_ERROR",
            value: Some(steradian_core::sh::cap::ZONAL_REL_ERROR as f64),
        }),
        batch: None,
        tables: &[],
    },
    KernelSpec {
        name: "sh-irradiance",
        paper: Paper::Sh,
        contract: r#"{"coeffs": [n² radiance coefficients], "normal": [x,y,z] non-zero} -> {"irradiance": E = ∫ L·max(n·ω,0) dω (not /π)}"#,
        eval: Piece::At(handlers::sh_irradiance),
        scalar: "steradian_core::sh::irradiance::irradiance",
        simd: Piece::At("steradian_simd::sh::irradiance::irradiance_slices"),
        wgsl: Piece::At(WgslTwin {
            source: wgsl::SH_IRRADIANCE,
            tolerance: "steradian_core::wgsl::SH_IRRADIANCE_TOL",
            table: Some("f32"),
        }),
        reference: Piece::At("steradian_reference::sh::irradiance"),
        bound: Piece::At(Bound {
            metric: "abs per unit of Σ|L|",
            item: "steradian_core::sh::irradiance::clamped_cosine",
            value: Some(1e-6),
        }),
        batch: None,
        tables: &[],
    },
    KernelSpec {
        name: "sh-rotate",
        paper: Paper::Sh,
        contract: r#"{"coeffs": [n² values], "rotation": [[r00,r01,r02],[r10,r11,r12],[r20,r21,r22]] rows, max|RᵀR−I| ≤ 1e-5, det > 0} -> {"coeffs": [n² values of g(ω) = f(Rᵀω)]}"#,
        eval: Piece::At(handlers::sh_rotate),
        scalar: "steradian_core::sh::rotate::rotate_zxzxz",
        // Four vectors per pass, each with its own rotation; the built operator's twin (one
        // rotation, eight vectors per pass) is steradian_simd::sh::rotate::apply_operator_slices.
        simd: Piece::At("steradian_simd::sh::rotate::rotate_zxzxz_slices"),
        // The twin of the scalar ZXZXZ path (each row its own rotation); the built
        // operator's twin, `wgsl::SH_ROTATE` (one rotation for every row), is also listed
        // under this name in `wgsl::CUSTOM`.
        wgsl: Piece::At(WgslTwin {
            source: wgsl::SH_ROTATE_ZXZXZ,
            tolerance: "steradian_core::wgsl::SH_ROTATE_ZXZXZ_TOL",
            table: Some("f32"),
        }),
        reference: Piece::At("steradian_reference::sh::rotate"),
        bound: Piece::At(Bound {
            metric: "‖error‖/‖c‖",
            item: "steradian_core::sh::rotate::rotate_rel_error",
            value: Some(4e-7),
        }),
        batch: None,
        tables: &[],
    },
    KernelSpec {
        name: "cp-vertices",
        paper: Paper::Cp,
        contract: r#"{"level": L in 0..=4} -> {"vertices": [[x,y,z], …]} (10·4^L + 2 unit vectors, the order values are indexed in)"#,
        eval: Piece::At(handlers::cp_vertices),
        scalar: "steradian_core::cp::mesh::Icosphere::new",
        simd: Piece::Without("a table built once, not a batch kernel"),
        wgsl: Piece::Without("a table built once on the CPU, not a GPU kernel"),
        reference: Piece::Without(
            "the mesh is its own definition; its invariants (counts, unit length, adjacency, \
             nesting) are tested in steradian_core::cp::mesh",
        ),
        bound: Piece::Without("exact up to the f32 rounding of f64 positions"),
        batch: None,
        tables: &[],
    },
    KernelSpec {
        name: "cp-query",
        paper: Paper::Cp,
        contract: r#"{"level": L in 0..=4, "values": [one per vertex], "dirs": [[x,y,z] non-zero, …]} -> {"values": [Σ ω_i v_i per dir, area weights of eq. 2–4]}"#,
        eval: Piece::At(handlers::cp_query),
        scalar: "steradian_core::cp::mesh::Icosphere::query",
        simd: Piece::At("steradian_simd::cp::query_slices"),
        wgsl: Piece::At(WgslTwin {
            source: wgsl::CP_QUERY,
            tolerance: "steradian_core::wgsl::CP_QUERY_TOL",
            table: Some("f32"),
        }),
        reference: Piece::At("steradian_reference::cp::locate"),
        bound: Piece::At(Bound {
            metric: "abs weight error",
            item: "steradian_core::cp::mesh::WEIGHT_ABS_ERROR",
            value: Some(steradian_core::cp::WEIGHT_ABS_ERROR as f64),
        }),
        batch: None,
        tables: &[],
    },
    KernelSpec {
        name: "cp-fit",
        paper: Paper::Cp,
        contract: r#"{"level": L in 0..=4, "samples": [[x,y,z,value] non-zero direction, …]} -> {"values": [one per vertex: a minimiser of Σ (query(d_s) − value_s)², undetermined components 0]}"#,
        eval: Piece::At(handlers::cp_fit),
        scalar: "steradian_core::cp::fit::Design::gram",
        simd: Piece::Without(
            "assembled once per direction set and factored by a sparse Cholesky; the query \
             it fits for has the SIMD twin",
        ),
        wgsl: Piece::Without("a factorisation on the CPU, not a GPU kernel"),
        reference: Piece::At("steradian_harness::cp::fit_dense_reference"),
        bound: Piece::At(Bound {
            metric: "excess residual / ‖f‖",
            item: "steradian_harness::cp::RESIDUAL_REL_ERROR",
            value: Some(crate::cp::RESIDUAL_REL_ERROR),
        }),
        batch: None,
        tables: &[],
    },
];

/// The kernel named `name`.
pub fn find(name: &str) -> Option<&'static KernelSpec> {
    KERNELS.iter().find(|k| k.name == name)
}

/// The description of a batch kernel.
pub fn of(kernel: Kernel) -> &'static KernelSpec {
    KERNELS
        .iter()
        .find(|k| k.batch == Some(kernel))
        .expect("every batch kernel is registered (coverage test)")
}

/// The batch kernels, in report order.
pub fn batch_kernels() -> impl Iterator<Item = Kernel> + Clone {
    KERNELS.iter().filter_map(|k| k.batch)
}

/// What a coverage check found missing: `(kernel, what)`.
pub type Missing = Vec<(&'static str, String)>;

/// The coverage check: for every registered kernel, every piece is present (and the item it
/// names exists in the sources under `root`, the workspace root) or deliberately absent
/// with a reason; every WGSL source of `steradian_core::wgsl` belongs to a registered
/// kernel of the same name; every batch kernel is registered once.
pub fn missing_pieces(kernels: &[KernelSpec], root: &std::path::Path) -> Missing {
    /// A piece as the check sees it: the path it names (if any), or the reason it is absent.
    fn named<T>(
        p: &Piece<T>,
        path: impl Fn(&T) -> Option<&'static str>,
    ) -> Result<Option<&'static str>, &'static str> {
        match p {
            Piece::At(t) => Ok(path(t)),
            Piece::Without(reason) => Err(reason),
        }
    }
    let mut out = Missing::new();
    for k in kernels {
        let folder = k.paper.folder();
        let pieces = [
            ("scalar kernel", Ok(Some(k.scalar))),
            ("eval handler", named(&k.eval, |_| None)),
            ("SIMD twin", named(&k.simd, |p| Some(*p))),
            ("WGSL twin", named(&k.wgsl, |w| Some(w.tolerance))),
            ("reference", named(&k.reference, |p| Some(*p))),
            ("error bound", named(&k.bound, |b| Some(b.item))),
        ];
        for (what, piece) in pieces {
            match piece {
                Ok(Some(path)) => {
                    if let Err(why) = item_exists(root, path) {
                        out.push((k.name, format!("{what} `{path}`: {why}")));
                    }
                }
                Err(reason) if reason.trim().is_empty() => {
                    out.push((k.name, format!("no {what}, and no reason given")))
                }
                Ok(None) | Err(_) => {}
            }
        }
        // The scalar kernel and its SIMD twin sit in the paper's folder of their crate.
        for (krate, path) in [
            ("steradian_core", Some(k.scalar)),
            ("steradian_simd", k.simd.get()),
        ] {
            if let Some(path) = path.filter(|p| !p.starts_with(&format!("{krate}::{folder}::"))) {
                out.push((
                    k.name,
                    format!("`{path}` is not in the paper's folder `{folder}`"),
                ));
            }
        }
        if let Some(w) = k.wgsl.get() {
            let listed = match w.table {
                None => wgsl::ALL
                    .iter()
                    .any(|(n, s)| *n == k.name && *s == w.source),
                Some(t) => wgsl::CUSTOM
                    .iter()
                    .any(|(n, s, e)| *n == k.name && *s == w.source && *e == t),
            };
            if !listed {
                out.push((
                    k.name,
                    "WGSL twin is not listed under this name in steradian_core::wgsl::ALL / CUSTOM"
                        .into(),
                ));
            }
        }
        if k.eval.get().is_some() && k.contract.is_empty() {
            out.push((k.name, "eval handler without a documented contract".into()));
        }
        // The report's main table prints a batch kernel's bound: it must be one number.
        if k.batch.is_some() && k.bound.get().and_then(|b| b.value).is_none() {
            out.push((
                k.name,
                "batch kernel without a numeric bound for the report".into(),
            ));
        }
        // Built-in tables are committed files of the paper's folder.
        for t in k.tables.iter().filter(|t| t.ends_with(".bin")) {
            let file = root.join("core/src").join(folder).join("tables").join(t);
            if !file.is_file() {
                out.push((k.name, format!("table {t} is not at {}", file.display())));
            }
        }
    }
    let wgsl_names = wgsl::ALL
        .iter()
        .map(|(n, _)| *n)
        .chain(wgsl::CUSTOM.iter().map(|(n, _, _)| *n));
    for name in wgsl_names {
        if !kernels.iter().any(|k| k.name == name) {
            out.push((name, "WGSL kernel without a registry entry".into()));
        }
    }
    for k in kernels {
        if let Some(b) = k.batch {
            if b.name() != k.name {
                out.push((k.name, format!("batch kernel named `{}`", b.name())));
            }
            let n = kernels.iter().filter(|o| o.batch == Some(b)).count();
            if n != 1 {
                out.push((k.name, format!("batch kernel registered {n} times")));
            }
        }
    }
    out
}

/// Whether the item at `path` (`steradian_<crate>::module::…::item`, or `…::Type::method`)
/// is defined in the sources under the workspace `root`.
fn item_exists(root: &std::path::Path, path: &str) -> Result<(), String> {
    let mut parts: Vec<&str> = path.split("::").collect();
    let krate = parts.remove(0);
    let dir = match krate {
        "steradian_core" => "core/src",
        "steradian_simd" => "simd/src",
        "steradian_harness" => "harness/src",
        "steradian_reference" => "reference/src",
        other => return Err(format!("unknown crate {other}")),
    };
    // The longest module prefix with a source file; the rest is `item` or `Type::item`.
    for split in (0..parts.len()).rev() {
        let (modules, rest) = parts.split_at(split);
        let base = root.join(dir).join(modules.join("/"));
        let candidates = if modules.is_empty() {
            vec![root.join(dir).join("lib.rs")]
        } else {
            vec![base.with_extension("rs"), base.join("mod.rs")]
        };
        let Some(src) = candidates
            .iter()
            .find_map(|f| std::fs::read_to_string(f).ok())
        else {
            continue;
        };
        let Some((item, owners)) = rest.split_last() else {
            return Err("names a module, not an item".into());
        };
        let defined = ["fn", "const", "static", "struct", "enum", "type"]
            .iter()
            .any(|kw| {
                src.contains(&format!("{kw} {item}("))
                    || src.contains(&format!("{kw} {item}:"))
                    || src.contains(&format!("{kw} {item}<"))
                    || src.contains(&format!("{kw} {item} "))
            });
        let owned = owners
            .iter()
            .all(|o| src.contains(&format!("impl {o}")) || src.contains(&format!("impl<'a> {o}")));
        return if defined && owned {
            Ok(())
        } else {
            Err(format!("not defined in {}", modules.join("/")))
        };
    }
    Err("no such module".into())
}
