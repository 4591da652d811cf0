//! Sums of cosine lobes, their products with threshold pruning, and the rendering integral
//! `∫ f_r·L·V` as a sum of closed-form lobe integrals (cosine-lobe paper, sections 4.3,
//! 5.3–5.4, eq. 22–23 and 39–41).
//!
//! # Lobe sums
//!
//! A lobe sum is `S(v) = k + Σ_i s_i·max(a_i·v, 0)^e_i` with a constant term `k` and lobes of
//! any sign. Visibility needs both (eq. 39–41): `V = c_unit − Σ w_k c_k` with
//! `c_unit ≡ 1`, so a sum of occluder lobes is the constant `1` and lobes of scale `−w_k`.
//! [`LobeSum<N>`] holds up to `N` lobes inline (no allocation); with the `alloc` feature,
//! [`LobeVec`] holds any number. Both implement [`LobeTerms`], which every product takes.
//!
//! # Products of sums, pruning and counting (section 4.3)
//!
//! The product of `A = k_a + Σ a_i` and `B = k_b + Σ b_j` is expanded term by term:
//! `k_a·k_b` (a constant), `k_a·b_j` and `a_i·k_b` (a lobe scaled exactly, eq. 41, no kernel
//! call) and `a_i·b_j` (one call of [`crate::lobe::product::product`]). The product kernel is
//! called on *unit-scale* copies of the two lobes and the result is scaled by `s_a·s_b`
//! here, so negative (visibility) and zero scales are exact.
//!
//! A term whose integral is below the threshold `t` in magnitude (`|∫ term| < t`; a constant
//! `k` integrates to `4π·k`) is dropped, as the paper does. Before calling the kernel the
//! exact bound `|∫ a·b| ≤ sup|a|·∫|b| = 2π·|s_a·s_b|/(max(e_a, e_b) + 1)` is checked: when
//! it is below `t` the pair is skipped without computing it. A threshold that is NaN or
//! `≤ 0` prunes nothing (`t = 0` keeps every term, including terms of integral 0).
//!
//! The threshold is absolute, in the units of the integrals (as the paper's `t_i`): pick it
//! relative to the size of the result you expect (e.g. `1e-3` of the unshadowed radiance).
//!
//! [`ProductCounts`] records what happened to every term that the full expansion would
//! contain: `computed` (kernel calls) + `scaled` (exact constant products) +
//! `skipped_bound` + `skipped_chain` = [`ProductCounts::considered`], and of the computed or
//! scaled ones, `pruned` were dropped afterwards.
//!
//! # The rendering integral (eq. 22–23) and ordering (section 5.4)
//!
//! [`triple`] evaluates `∫_{S²} R·L·V dv` for a reflectance sum `R` (BRDF lobes, with the
//! cosine term: see [`Cosine`]), a light sum `L` and a visibility sum `V`. Following
//! section 5.4 it multiplies reflectance and light first, then each surviving term by every
//! visibility term, and sums the closed-form integrals `2π·s/(e + 1)` ([`crate::lobe::integral`])
//! of the results. When a term of `R·L` is pruned, its products with `V` are never formed
//! (`skipped_chain`: "given a product of several lobes, when the first one can be neglected,
//! all the remaining computations can be avoided"). Nothing is stored: the whole chain is a
//! stream of accumulations, so [`triple`] allocates nothing and needs no buffers.
//!
//! **Pruning error bound** (checked in the harness): a dropped term `p` of `R·L` changes
//! the result by `|∫ p·V| ≤ |∫ p|·sup|V| < t·(|k_V| + Σ|w_k|)`, a dropped term of
//! `(R·L)·V` by less than `t`; so, for a kernel whose product integrals are exact,
//! `|triple(t) − triple(0)| ≤ t·(n₁·(|k_V| + Σ|w_k|) + n₂)` plus rounding, with `n₁` the
//! terms of `R·L` that were dropped and `n₂` those of the second stage. With a kernel whose
//! integrals are within a relative `ε`, each `t` becomes `(1 + ε)·t`. The dropped terms
//! of a visibility sum mostly share a sign (occluders subtract), so the pruning error
//! grows like `n·t`, not `√n·t`: on the report's scene (32 occluders) `t = 1e-3` of the
//! brightest pixel gives a max error of `7e-3` of it.
//!
//! **Accuracy of the chain** (harness test `tests/lobe_sum.rs`, against f64 quadrature of
//! the same lobe model with the exact cosine, relative to the unshadowed value), with the
//! built-in product table and [`Cosine::WithLight`]: mean `1.2e-3`, max `2.1e-2` over 40
//! random scenes; worst named cases `3.2e-2` (`e = 0` lobes), `3.1e-2` (a light partly
//! below the horizon), `2.6e-2` (a grazing light). [`Cosine::WithBrdf`] reaches `0.28` on
//! the grazing light. This is the one-lobe shape error of products compounded over the
//! chain; the caps-as-lobes representation (section 5.2–5.3) adds its own, larger error
//! against the physical integral (cap light, exact occluders), reported beside it.
//!
//! # Bad input
//!
//! Nothing panics. NaN anywhere in a term that is kept makes the result NaN (NaN compares
//! false with the threshold, so it is never pruned). A full [`LobeSum`] drops further lobes
//! and counts them in [`ProductCounts::overflowed`]; [`LobeSum::try_push`] returns `false`.

use crate::lobe::cap::{CapFit, SphericalCap};
use crate::lobe::product;
use crate::lobe::{self, CosineLobe, Lafortune, Phong};
use crate::{TWO_PI, Vec3};

/// `4π`: the integral of the constant 1 over the sphere.
const FOUR_PI: f32 = 2.0 * TWO_PI;

/// Read access to a lobe sum `k + Σ lobes`: what every product and [`triple`] takes.
pub trait LobeTerms {
    /// The constant term `k`.
    fn constant(&self) -> f32;
    /// The lobes (any sign of scale).
    fn lobes(&self) -> &[CosineLobe];

    /// Number of terms of the expansion: the lobes, plus one if the constant is non-zero.
    fn terms(&self) -> usize {
        self.lobes().len() + usize::from(self.constant() != 0.0)
    }
    /// `k + Σ s_i·max(a_i·v, 0)^e_i` at unit `v`.
    fn eval(&self, v: Vec3) -> f32 {
        self.lobes()
            .iter()
            .fold(self.constant(), |acc, l| acc + l.eval(v))
    }
    /// `∫_{S²} = 4π·k + Σ 2π·s_i/(e_i + 1)` (exact, closed form).
    fn integral(&self) -> f32 {
        self.lobes()
            .iter()
            .fold(FOUR_PI * self.constant(), |acc, l| acc + l.integral())
    }
    /// `|k| + Σ |s_i|`: a bound on `sup |S|` (used in the pruning error bound).
    fn abs_bound(&self) -> f32 {
        self.lobes()
            .iter()
            .fold(self.constant().abs(), |acc, l| acc + l.scale().abs())
    }
}

/// A borrowed lobe sum: a constant and a slice of lobes (e.g. a caller's own buffer).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SumRef<'a> {
    /// The constant term.
    pub constant: f32,
    /// The lobes.
    pub lobes: &'a [CosineLobe],
}

impl LobeTerms for SumRef<'_> {
    fn constant(&self) -> f32 {
        self.constant
    }
    fn lobes(&self) -> &[CosineLobe] {
        self.lobes
    }
}

/// A lobe sum with room for `N` lobes inline: `k + Σ s_i·max(a_i·v, 0)^e_i`. No allocation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LobeSum<const N: usize> {
    constant: f32,
    len: usize,
    lobes: [CosineLobe; N],
}

impl<const N: usize> Default for LobeSum<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> LobeTerms for LobeSum<N> {
    fn constant(&self) -> f32 {
        self.constant
    }
    fn lobes(&self) -> &[CosineLobe] {
        &self.lobes[..self.len]
    }
}

fn zero_lobe() -> CosineLobe {
    CosineLobe::saturating(Vec3::Z, 0.0, 0.0)
}

impl<const N: usize> LobeSum<N> {
    /// The empty sum (`0`).
    pub fn new() -> Self {
        LobeSum {
            constant: 0.0,
            len: 0,
            lobes: [zero_lobe(); N],
        }
    }

    /// The constant `k` with no lobes.
    pub fn with_constant(k: f32) -> Self {
        let mut s = Self::new();
        s.constant = k;
        s
    }

    /// Unoccluded visibility, `c_unit = 1` (eq. 40): push occluders with
    /// [`LobeSum::push_occluder`].
    pub fn unoccluded() -> Self {
        Self::with_constant(1.0)
    }

    /// Copies `lobes` (those beyond the capacity are dropped: check [`LobeSum::len`]).
    pub fn from_lobes(constant: f32, lobes: &[CosineLobe]) -> Self {
        let mut s = Self::with_constant(constant);
        for l in lobes {
            s.try_push(*l);
        }
        s
    }

    /// Sets the constant term.
    pub fn set_constant(&mut self, k: f32) {
        self.constant = k;
    }
    /// Number of lobes.
    pub fn len(&self) -> usize {
        self.len
    }
    /// Whether there are no lobes (the constant may still be non-zero).
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
    /// `N`.
    pub fn capacity(&self) -> usize {
        N
    }
    /// Removes every lobe and zeroes the constant.
    pub fn clear(&mut self) {
        self.len = 0;
        self.constant = 0.0;
    }

    /// Appends a lobe; `false` (and nothing stored) when the sum is full.
    pub fn try_push(&mut self, lobe: CosineLobe) -> bool {
        match self.lobes.get_mut(self.len) {
            Some(slot) => {
                *slot = lobe;
                self.len += 1;
                true
            }
            None => false,
        }
    }

    /// Appends the lobe of a spherical light `cap` of radiance `radiance` (eq. 31).
    pub fn push_cap(&mut self, cap: &SphericalCap, radiance: f32, fit: CapFit) -> bool {
        self.try_push(cap.lobe(radiance, fit))
    }

    /// Appends an occluder: the lobe of its `cap` with scale `−weight` (eq. 39). Use on
    /// [`LobeSum::unoccluded`]; weight 1 for occluders whose caps do not overlap.
    pub fn push_occluder(&mut self, cap: &SphericalCap, weight: f32, fit: CapFit) -> bool {
        self.try_push(cap.lobe(-weight, fit))
    }

    /// Appends `lobe·max(n·v, 0)` (the cosine term of the rendering equation as an `e = 1`
    /// lobe around the unit normal `n`, eq. 22), computed with the product kernel and
    /// counted in `counts.computed` (never pruned).
    pub fn push_times_cosine(
        &mut self,
        lobe: &CosineLobe,
        normal: Vec3,
        counts: &mut ProductCounts,
    ) -> bool {
        self.push_times_cosine_with(&product::product, lobe, normal, counts)
    }

    /// [`LobeSum::push_times_cosine`] with another two-lobe kernel (e.g. a
    /// [`product::product_with`] on another table).
    pub fn push_times_cosine_with<K>(
        &mut self,
        kernel: &K,
        lobe: &CosineLobe,
        normal: Vec3,
        counts: &mut ProductCounts,
    ) -> bool
    where
        K: Fn(&CosineLobe, &CosineLobe) -> CosineLobe,
    {
        let cos = CosineLobe::saturating(normal, 1.0, 1.0);
        counts.computed += 1;
        let ok = self.try_push(lobe_product_with(kernel, lobe, &cos));
        counts.overflowed += u64::from(!ok);
        ok
    }

    /// `self·other` expanded and pruned at `threshold` into `out` (cleared first); see
    /// the module docs. Terms that do not fit in `out` are counted in `counts.overflowed`.
    pub fn product_into<const M: usize>(
        &self,
        other: &impl LobeTerms,
        threshold: f32,
        out: &mut LobeSum<M>,
        counts: &mut ProductCounts,
    ) {
        product_into(self, other, threshold, out, counts);
    }
}

/// A lobe sum of any length (`alloc` feature).
#[cfg(feature = "alloc")]
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LobeVec {
    /// The constant term.
    pub constant: f32,
    /// The lobes.
    pub lobes: alloc::vec::Vec<CosineLobe>,
}

#[cfg(feature = "alloc")]
impl LobeTerms for LobeVec {
    fn constant(&self) -> f32 {
        self.constant
    }
    fn lobes(&self) -> &[CosineLobe] {
        &self.lobes
    }
}

#[cfg(feature = "alloc")]
impl LobeVec {
    /// A copy of any lobe sum.
    pub fn from_terms(s: &impl LobeTerms) -> Self {
        LobeVec {
            constant: s.constant(),
            lobes: s.lobes().to_vec(),
        }
    }
    /// `a·b` expanded and pruned at `threshold` (see the module docs).
    pub fn product(
        a: &impl LobeTerms,
        b: &impl LobeTerms,
        threshold: f32,
        counts: &mut ProductCounts,
    ) -> Self {
        let mut out = LobeVec::default();
        for_each_term(a, b, threshold, counts, |t| match t {
            Term::Constant(k) => out.constant += k,
            Term::Lobe(l) => out.lobes.push(l),
        });
        out
    }
}

/// What happened to the terms of a product expansion (see the module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ProductCounts {
    /// Lobe × lobe products evaluated with the product kernel.
    pub computed: u64,
    /// Products with a constant term, exact (eq. 41), no kernel call.
    pub scaled: u64,
    /// Computed or scaled terms dropped because `|∫ term| < t`.
    pub pruned: u64,
    /// Lobe pairs not computed because the bound `2π|s_a s_b|/(max(e_a, e_b) + 1)` was `< t`.
    pub skipped_bound: u64,
    /// Products not formed because an earlier factor of their chain was dropped.
    pub skipped_chain: u64,
    /// Kept terms that did not fit in a fixed-capacity output.
    pub overflowed: u64,
}

impl ProductCounts {
    /// Every term of the full expansion: `computed + scaled + skipped_bound + skipped_chain`.
    pub fn considered(&self) -> u64 {
        self.computed + self.scaled + self.skipped_bound + self.skipped_chain
    }
    /// Terms kept: `computed + scaled − pruned`.
    pub fn kept(&self) -> u64 {
        self.computed + self.scaled - self.pruned
    }
    /// Terms not kept (pruned, skipped by the bound or by the chain).
    pub fn dropped(&self) -> u64 {
        self.pruned + self.skipped_bound + self.skipped_chain
    }
}

impl core::ops::AddAssign for ProductCounts {
    fn add_assign(&mut self, o: Self) {
        self.computed += o.computed;
        self.scaled += o.scaled;
        self.pruned += o.pruned;
        self.skipped_bound += o.skipped_bound;
        self.skipped_chain += o.skipped_chain;
        self.overflowed += o.overflowed;
    }
}

/// One term of an expanded product.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Term {
    /// A constant (integral `4π·k`).
    Constant(f32),
    /// A lobe.
    Lobe(CosineLobe),
}

impl Term {
    /// The exact integral over the sphere.
    #[inline]
    pub fn integral(&self) -> f32 {
        match self {
            Term::Constant(k) => FOUR_PI * k,
            Term::Lobe(l) => l.integral(),
        }
    }
}

/// The product of two lobes of any scale (negative and zero included): the kernel
/// [`product::product`] on unit-scale copies, scaled by `s_a·s_b`.
#[inline]
pub fn lobe_product(a: &CosineLobe, b: &CosineLobe) -> CosineLobe {
    lobe_product_with(&product::product, a, b)
}

/// [`lobe_product`] with another two-lobe kernel (e.g. a [`product::product_with`] fit).
#[inline]
pub fn lobe_product_with<K>(kernel: &K, a: &CosineLobe, b: &CosineLobe) -> CosineLobe
where
    K: Fn(&CosineLobe, &CosineLobe) -> CosineLobe,
{
    let ua = CosineLobe::saturating(a.axis(), 1.0, a.exponent());
    let ub = CosineLobe::saturating(b.axis(), 1.0, b.exponent());
    let p = kernel(&ua, &ub);
    CosineLobe::saturating(p.axis(), p.scale() * (a.scale() * b.scale()), p.exponent())
}

/// `true` when the term is dropped: `|∫| < t` (NaN is never dropped).
#[inline]
fn negligible(integral: f32, threshold: f32) -> bool {
    integral.abs() < threshold
}

/// The bound `2π|s_a s_b|/(max(e_a, e_b) + 1) ≥ |∫ a·b|`.
#[inline]
fn pair_bound(a: &CosineLobe, b: &CosineLobe) -> f32 {
    lobe::integral(a.exponent().max(b.exponent()), a.scale() * b.scale()).abs()
}

/// One product term `x·y` with pruning; `None` when dropped (and counted).
#[inline]
fn term_product<K>(
    kernel: &K,
    x: &Term,
    y: &Term,
    threshold: f32,
    counts: &mut ProductCounts,
) -> Option<Term>
where
    K: Fn(&CosineLobe, &CosineLobe) -> CosineLobe,
{
    let t = match (x, y) {
        (Term::Constant(a), Term::Constant(b)) => {
            counts.scaled += 1;
            Term::Constant(a * b)
        }
        (Term::Constant(k), Term::Lobe(l)) | (Term::Lobe(l), Term::Constant(k)) => {
            counts.scaled += 1;
            Term::Lobe(CosineLobe::saturating(
                l.axis(),
                k * l.scale(),
                l.exponent(),
            ))
        }
        (Term::Lobe(a), Term::Lobe(b)) => {
            if pair_bound(a, b) < threshold {
                counts.skipped_bound += 1;
                return None;
            }
            counts.computed += 1;
            Term::Lobe(lobe_product_with(kernel, a, b))
        }
    };
    if negligible(t.integral(), threshold) {
        counts.pruned += 1;
        None
    } else {
        Some(t)
    }
}

/// The terms of a sum in expansion order: the constant (if non-zero), then the lobes.
fn terms_of(s: &impl LobeTerms) -> impl Iterator<Item = Term> + '_ {
    let k = s.constant();
    (k != 0.0)
        .then_some(Term::Constant(k))
        .into_iter()
        .chain(s.lobes().iter().map(|l| Term::Lobe(*l)))
}

/// Calls `emit` with every kept term of `a·b` (see the module docs); no allocation.
pub fn for_each_term(
    a: &impl LobeTerms,
    b: &impl LobeTerms,
    threshold: f32,
    counts: &mut ProductCounts,
    mut emit: impl FnMut(Term),
) {
    for x in terms_of(a) {
        for y in terms_of(b) {
            if let Some(t) = term_product(&product::product, &x, &y, threshold, counts) {
                emit(t);
            }
        }
    }
}

/// `a·b` expanded and pruned into `out` (cleared first; constants are summed into its
/// constant). Kept lobes beyond `out`'s capacity are counted in `counts.overflowed`.
pub fn product_into<const M: usize>(
    a: &impl LobeTerms,
    b: &impl LobeTerms,
    threshold: f32,
    out: &mut LobeSum<M>,
    counts: &mut ProductCounts,
) {
    out.clear();
    let mut overflowed = 0;
    for_each_term(a, b, threshold, counts, |t| match t {
        Term::Constant(k) => out.constant += k,
        Term::Lobe(l) => {
            if !out.try_push(l) {
                overflowed += 1;
            }
        }
    });
    counts.overflowed += overflowed;
}

/// `∫_{S²} R·L·V dv` for lobe sums, as the sum of the closed-form integrals of the kept
/// terms of `(R·L)·V` (eq. 23; ordering of section 5.4; pruning of section 4.3 at
/// `threshold`). See the module docs for the ordering, the counters and the error bound.
/// No allocation, no buffers.
pub fn triple(
    reflectance: &impl LobeTerms,
    light: &impl LobeTerms,
    visibility: &impl LobeTerms,
    threshold: f32,
    counts: &mut ProductCounts,
) -> f32 {
    triple_with(
        &product::product,
        reflectance,
        light,
        visibility,
        threshold,
        counts,
    )
}

/// [`triple`] with another two-lobe kernel, e.g.
/// `|a, b| product::product_with(&table, ProductFit::SphericalGaussian, a, b)`.
pub fn triple_with<K>(
    kernel: &K,
    reflectance: &impl LobeTerms,
    light: &impl LobeTerms,
    visibility: &impl LobeTerms,
    threshold: f32,
    counts: &mut ProductCounts,
) -> f32
where
    K: Fn(&CosineLobe, &CosineLobe) -> CosineLobe,
{
    let vis_terms = visibility.terms() as u64;
    let mut acc = 0.0f32;
    let mut dropped_first = 0u64;
    for x in terms_of(reflectance) {
        for y in terms_of(light) {
            let Some(p) = term_product(kernel, &x, &y, threshold, counts) else {
                dropped_first += 1;
                continue;
            };
            for z in terms_of(visibility) {
                if let Some(q) = term_product(kernel, &p, &z, threshold, counts) {
                    acc += q.integral();
                }
            }
        }
    }
    counts.skipped_chain += dropped_first * vis_terms;
    acc
}

/// Where the cosine factor `max(n·v, 0)` of the rendering equation enters the chain.
///
/// The paper writes the integrand as `f_r·c_in·V·c_n` with `c_n = max(n·v, 0)` an `e = 1`
/// lobe (eq. 22), while its Phong (eq. 24–27) already folds the cosine into the diffuse
/// lobe `k_d·max(n·v, 0)` and has none on the specular lobe. Where the one-lobe
/// approximation of a product is made matters most at grazing angles: multiplying a
/// glossy lobe by the cosine first gives a lobe whose tail toward the horizon is wrong,
/// and a light there sees exactly that tail; multiplying the (usually narrower) light lobe
/// by the cosine first keeps the error small (measured in the harness test
/// `tests/lobe_sum.rs` and the report section "lobe-sum"). Use the same value for
/// [`phong_reflectance`] / [`lafortune_reflectance`] and [`light_with_cosine`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Cosine {
    /// `(f_r·cos)·L·V`: every BRDF lobe is multiplied by `max(n·v, 0)` with the product
    /// kernel (one product per lobe, counted), except Phong's diffuse lobe, which already is
    /// `f_d·max(n·v, 0)` exactly; the light is used as it is.
    WithBrdf,
    /// `f_r·(L·cos)·V`: the reflectance is `f_r` alone (Phong's diffuse term as the constant
    /// `f_d`) and [`light_with_cosine`] multiplies every light lobe by the cosine (a
    /// constant light becomes the exact `e = 1` lobe `k·max(n·v, 0)`).
    #[default]
    WithLight,
    /// No cosine anywhere: the lobes as given (the paper's original Phong shading formula,
    /// eq. 24, whose diffuse lobe has it folded in; a Lafortune lobe without it).
    AsGiven,
}

/// The reflectance sum of a Phong BRDF at normal `n`, view `wo` ([`Phong::lobes`]), with the
/// cosine term treated as `cosine` says. Products are counted in `counts`.
pub fn phong_reflectance(
    phong: &Phong,
    n: Vec3,
    wo: Vec3,
    cosine: Cosine,
    counts: &mut ProductCounts,
) -> LobeSum<2> {
    let [d, s] = phong.lobes(n, wo);
    let mut out = LobeSum::new();
    match cosine {
        Cosine::WithBrdf => {
            out.try_push(d);
            out.push_times_cosine(&s, d.axis(), counts);
        }
        Cosine::WithLight => {
            out.set_constant(d.scale());
            out.try_push(s);
        }
        Cosine::AsGiven => {
            out.try_push(d);
            out.try_push(s);
        }
    }
    out
}

/// The reflectance sum of a Lafortune BRDF in shading `frame` for view `wo`
/// ([`Lafortune::lobes`]), with the cosine term treated as `cosine` says.
pub fn lafortune_reflectance<const N: usize>(
    brdf: &Lafortune<N>,
    frame: &crate::frame::Frame,
    wo: Vec3,
    cosine: Cosine,
    counts: &mut ProductCounts,
) -> LobeSum<N> {
    let mut out = LobeSum::new();
    for l in brdf.lobes(frame, wo) {
        match cosine {
            Cosine::WithBrdf => {
                out.push_times_cosine(&l, frame.normal(), counts);
            }
            Cosine::WithLight | Cosine::AsGiven => {
                out.try_push(l);
            }
        }
    }
    out
}

/// The light sum with the cosine `max(n·v, 0)` multiplied in when `cosine` is
/// [`Cosine::WithLight`] (one counted product per lobe; a constant `k` becomes the exact
/// lobe `k·max(n·v, 0)`), else a copy. A constant light needs one free slot for its lobe
/// (otherwise it is counted in `counts.overflowed`).
pub fn light_with_cosine<const N: usize>(
    light: &LobeSum<N>,
    n: Vec3,
    cosine: Cosine,
    counts: &mut ProductCounts,
) -> LobeSum<N> {
    light_with_cosine_with(&product::product, light, n, cosine, counts)
}

/// [`light_with_cosine`] with another two-lobe kernel (e.g. a [`product::product_with`] on
/// another table).
pub fn light_with_cosine_with<K, const N: usize>(
    kernel: &K,
    light: &LobeSum<N>,
    n: Vec3,
    cosine: Cosine,
    counts: &mut ProductCounts,
) -> LobeSum<N>
where
    K: Fn(&CosineLobe, &CosineLobe) -> CosineLobe,
{
    if cosine != Cosine::WithLight {
        return *light;
    }
    let mut out = LobeSum::new();
    for l in light.lobes() {
        out.push_times_cosine_with(kernel, l, n, counts);
    }
    let k = light.constant();
    if k != 0.0 {
        counts.scaled += 1;
        if !out.try_push(CosineLobe::saturating(n, k, 1.0)) {
            counts.overflowed += 1;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lobe(axis: Vec3, s: f32, e: f32) -> CosineLobe {
        CosineLobe::new(axis, s, e).unwrap()
    }

    #[test]
    fn sums_evaluate_and_integrate() {
        let mut v = LobeSum::<4>::unoccluded();
        let cap = SphericalCap::new(Vec3::Z, 0.2).unwrap();
        assert!(v.push_occluder(&cap, 1.0, CapFit::L2));
        assert_eq!(v.terms(), 2);
        let e = cap.exponent_l2();
        assert!((v.eval(Vec3::Z) - 0.0).abs() < 1e-6);
        assert_eq!(v.eval(-Vec3::Z), 1.0);
        let want = FOUR_PI - TWO_PI / (e + 1.0);
        assert!((v.integral() / want - 1.0).abs() < 1e-6);
        assert!((v.abs_bound() - 2.0).abs() < 1e-6);
    }

    #[test]
    fn capacity_is_respected() {
        let mut s = LobeSum::<1>::new();
        assert!(s.try_push(lobe(Vec3::Z, 1.0, 1.0)));
        assert!(!s.try_push(lobe(Vec3::X, 1.0, 1.0)));
        assert_eq!(s.len(), 1);
        let a = LobeSum::<2>::from_lobes(0.0, &[lobe(Vec3::Z, 1.0, 1.0), lobe(Vec3::X, 1.0, 2.0)]);
        let mut out = LobeSum::<1>::new();
        let mut c = ProductCounts::default();
        a.product_into(&a, 0.0, &mut out, &mut c);
        assert_eq!((out.len(), c.computed, c.overflowed), (1, 4, 3));
        let mut empty = LobeSum::<0>::new();
        assert!(!empty.try_push(lobe(Vec3::Z, 1.0, 1.0)));
    }

    #[test]
    fn constants_multiply_exactly() {
        let a = LobeSum::<1>::from_lobes(2.0, &[lobe(Vec3::Z, -3.0, 5.0)]);
        let b = LobeSum::<0>::with_constant(0.5);
        let mut out = LobeSum::<2>::new();
        let mut c = ProductCounts::default();
        product_into(&a, &b, 0.0, &mut out, &mut c);
        assert_eq!(out.constant(), 1.0);
        assert_eq!(out.lobes()[0].scale(), -1.5);
        assert_eq!(out.lobes()[0].exponent(), 5.0);
        assert_eq!((c.computed, c.scaled, c.considered()), (0, 2, 2));
    }

    #[test]
    fn negative_scales_go_through_the_kernel() {
        let a = lobe(Vec3::Z, -2.0, 10.0);
        let b = lobe(Vec3::new(0.3, 0.0, 1.0), 3.0, 20.0);
        let p = lobe_product(&a, &b);
        let q = lobe_product(&lobe(Vec3::Z, 2.0, 10.0), &b);
        assert!(p.scale() < 0.0 && p.scale().is_finite());
        assert_eq!(p.scale(), -q.scale());
        assert_eq!((p.axis(), p.exponent()), (q.axis(), q.exponent()));
        let z = lobe_product(&lobe(Vec3::Z, 0.0, 10.0), &b);
        assert_eq!(z.scale(), 0.0);
    }

    #[test]
    fn pruning_drops_small_terms_and_stops_chains() {
        let r = LobeSum::<1>::from_lobes(0.0, &[lobe(Vec3::Z, 1.0, 1.0)]);
        // A light far below the normal's lobe: the product is tiny.
        let l = LobeSum::<1>::from_lobes(0.0, &[lobe(Vec3::new(0.0, 0.0, -1.0), 1e-6, 100.0)]);
        let mut v = LobeSum::<3>::unoccluded();
        for _ in 0..3 {
            v.try_push(lobe(Vec3::X, -0.5, 50.0));
        }
        let mut c = ProductCounts::default();
        let x = triple(&r, &l, &v, 1e-3, &mut c);
        assert_eq!(x, 0.0);
        assert_eq!(c.considered(), 1 + 4);
        assert_eq!(c.skipped_bound + c.pruned, 1);
        assert_eq!(c.skipped_chain, 4);
        let mut c0 = ProductCounts::default();
        let _ = triple(&r, &l, &v, 0.0, &mut c0);
        assert_eq!((c0.computed, c0.scaled, c0.dropped()), (4, 1, 0));
    }

    #[test]
    fn nan_is_never_pruned() {
        let r = LobeSum::<1>::from_lobes(f32::NAN, &[]);
        let l = LobeSum::<0>::with_constant(1.0);
        let mut c = ProductCounts::default();
        assert!(triple(&r, &l, &l, 1.0, &mut c).is_nan());
        let r = LobeSum::<1>::from_lobes(0.0, &[CosineLobe::saturating(Vec3::Z, 1.0, f32::NAN)]);
        assert!(triple(&r, &l, &l, 1.0, &mut c).is_nan());
        // A NaN threshold prunes nothing.
        let r = LobeSum::<1>::from_lobes(0.0, &[lobe(Vec3::Z, 1e-9, 1.0)]);
        assert!(triple(&r, &l, &l, f32::NAN, &mut c) > 0.0);
    }

    #[test]
    fn phong_reflectance_folds_the_cosine() {
        let p = Phong::new(0.5, 0.5, 30.0).unwrap();
        let wo = Vec3::new(0.6, 0.0, 0.8);
        let mut c = ProductCounts::default();
        let r = phong_reflectance(&p, Vec3::Z, wo, Cosine::WithBrdf, &mut c);
        assert_eq!((r.len(), c.computed), (2, 1));
        // The specular × cosine lobe is dimmer than the specular lobe (cos ≤ 1).
        let [_, s] = p.lobes(Vec3::Z, wo);
        assert!(r.lobes()[1].integral() < s.integral());
        let g = phong_reflectance(&p, Vec3::Z, wo, Cosine::AsGiven, &mut c);
        assert_eq!(g.lobes(), &p.lobes(Vec3::Z, wo));
        assert_eq!(c.computed, 1);
        // With the light: f_d as a constant, the cosine goes on the light lobes.
        let f = phong_reflectance(&p, Vec3::Z, wo, Cosine::WithLight, &mut c);
        assert_eq!((f.constant(), f.lobes()), (s.scale() * 0.0 + 0.5, &[s][..]));
        let mut l = LobeSum::<2>::with_constant(2.0);
        l.try_push(lobe(Vec3::X, 1.0, 100.0));
        let lc = light_with_cosine(&l, Vec3::Z, Cosine::WithLight, &mut c);
        assert_eq!((lc.constant(), lc.len(), c.computed), (0.0, 2, 2));
        assert_eq!(lc.lobes()[1], lobe(Vec3::Z, 2.0, 1.0));
        assert_eq!(light_with_cosine(&l, Vec3::Z, Cosine::AsGiven, &mut c), l);
    }

    #[cfg(feature = "alloc")]
    #[test]
    fn vec_and_fixed_agree() {
        let a = LobeSum::<2>::from_lobes(0.5, &[lobe(Vec3::Z, 1.0, 3.0), lobe(Vec3::X, -1.0, 8.0)]);
        let b = LobeSum::<1>::from_lobes(1.0, &[lobe(Vec3::Y, 2.0, 1.0)]);
        let mut c1 = ProductCounts::default();
        let mut c2 = ProductCounts::default();
        let mut out = LobeSum::<8>::new();
        a.product_into(&b, 0.0, &mut out, &mut c1);
        let v = LobeVec::product(&a, &b, 0.0, &mut c2);
        assert_eq!(c1, c2);
        assert_eq!(out.constant(), v.constant);
        assert_eq!(out.lobes(), &v.lobes[..]);
        assert_eq!(LobeVec::from_terms(&out), v);
    }
}
