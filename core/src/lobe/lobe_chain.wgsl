// steradian: one chain of the `lobes` method, the integral of reflectance × (light × cosine)
// × visibility with every factor a sum of cosine lobes (mirrors the harness's
// `scene::lobes` chain: `sum::light_with_cosine_with` on the light's one lobe, then
// `sum::triple_with` twice, unshadowed with threshold 0 and shadowed with
// `threshold·|unshadowed|`), products by `lobe_product` of product_lib.wgsl.
//
// Input columns (row i of n at c*n + i):
//   0..2   normal n (unit)
//   3..7   the light's lobe: axis (3), scale, exponent (`SphericalCap::lobe`)
//   8      the reflectance's constant k
//   9      the reflectance's lobe count (0 or 1)
//   10..14 the reflectance's lobe: axis (3), scale, exponent
//   15     the visibility lobes' offset in `table` (u32 bits), 5 words each: axis (3),
//          scale, exponent; the visibility is 1 plus those lobes
//   16     their count (u32 bits)
//   17     the pruning threshold, relative to the unshadowed value
// Output columns: [unshadowed, shadowed, products computed (lobe × lobe, not counting the
// light × cosine)]; with no visibility lobe the shadowed value is the unshadowed one.
// Pruning (`sum::term_product`): a lobe pair whose bound 2π|s_a s_b|/(max(e_a, e_b) + 1) is
// below the threshold is skipped, a term whose integral's magnitude is below it dropped.

const TWO_PI: f32 = 6.283185307179586;
const FOUR_PI: f32 = 12.566370614359172;

// A term of an expanded product: a constant (`scale`, integral 4π·scale) or a lobe.
struct Term {
    constant: bool,
    axis: vec3<f32>,
    scale: f32,
    exponent: f32,
}

struct Kept {
    ok: bool,
    term: Term,
    computed: u32,
}

// `lobe::integral`: 2π·(s/(e + 1)), the exponent clamped to 0.
fn lobe_integral(scale: f32, exponent: f32) -> f32 {
    return TWO_PI * (scale / (max(exponent, 0.0) + 1.0));
}

fn term_integral(t: Term) -> f32 {
    if (t.constant) {
        return FOUR_PI * t.scale;
    }
    return lobe_integral(t.scale, t.exponent);
}

fn constant_term(k: f32) -> Term {
    return Term(true, vec3<f32>(0.0, 0.0, 1.0), k, 0.0);
}

fn lobe_term(axis: vec3<f32>, scale: f32, exponent: f32) -> Term {
    return Term(false, axis, scale, max(exponent, 0.0));
}

// `sum::term_product`: x·y, or not kept (skipped by the pair bound, or its integral below
// the threshold).
fn term_product(x: Term, y: Term, threshold: f32) -> Kept {
    var t: Term;
    var computed = 0u;
    if (x.constant && y.constant) {
        t = constant_term(x.scale * y.scale);
    } else if (x.constant || y.constant) {
        var l = x;
        var k = y.scale;
        if (x.constant) {
            l = y;
            k = x.scale;
        }
        t = lobe_term(normalize_axis(l.axis), k * l.scale, l.exponent);
    } else {
        let bound = abs(lobe_integral(x.scale * y.scale, max(x.exponent, y.exponent)));
        if (bound < threshold) {
            return Kept(false, x, 0u);
        }
        // `lobe_product_with`: the kernel on unit copies, scaled by s_x·s_y.
        let p = lobe_product(x.axis, 1.0, x.exponent, y.axis, 1.0, y.exponent);
        t = lobe_term(normalize_axis(p.axis), p.scale * (x.scale * y.scale), p.exponent);
        computed = 1u;
    }
    return Kept(!(abs(term_integral(t)) < threshold), t, computed);
}

struct Chain {
    value: f32,
    computed: u32,
}

// `sum::triple_with(r, l, v, threshold)` for a reflectance of a constant and at most one
// lobe, a light of one lobe and a visibility of 1 plus `vis_n` lobes at `vis_off` (none
// when `shadowed` is false: the unshadowed chain).
fn triple(r_terms: array<Term, 2>, r_first: u32, l: Term, shadowed: bool, vis_off: u32, vis_n: u32, threshold: f32) -> Chain {
    // A `var` copy: runtime indices into a value array are not portable.
    var rt = r_terms;
    var acc = 0.0;
    var computed = 0u;
    let nz = select(1u, 1u + vis_n, shadowed);
    for (var a = r_first; a < 2u; a = a + 1u) {
        let p = term_product(rt[a], l, threshold);
        computed = computed + p.computed;
        if (!p.ok) {
            continue;
        }
        for (var z = 0u; z < nz; z = z + 1u) {
            var zt = constant_term(1.0);
            if (z > 0u) {
                let o = vis_off + 5u * (z - 1u);
                zt = lobe_term(vec3<f32>(table[o], table[o + 1u], table[o + 2u]), table[o + 3u], table[o + 4u]);
            }
            let q = term_product(p.term, zt, threshold);
            computed = computed + q.computed;
            if (q.ok) {
                acc = acc + term_integral(q.term);
            }
        }
    }
    return Chain(acc, computed);
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = batch_row(gid);
    let n = params.n;
    if (i >= n) {
        return;
    }
    let normal = normalize_axis(vec3<f32>(input[i], input[n + i], input[2u * n + i]));
    let la = vec3<f32>(input[3u * n + i], input[4u * n + i], input[5u * n + i]);
    let ls = input[6u * n + i];
    let le = input[7u * n + i];
    let rk = input[8u * n + i];
    let rn = input[9u * n + i];
    let ra = vec3<f32>(input[10u * n + i], input[11u * n + i], input[12u * n + i]);
    let rs = input[13u * n + i];
    let re = input[14u * n + i];
    let vis_off = bitcast<u32>(input[15u * n + i]);
    let vis_n = bitcast<u32>(input[16u * n + i]);
    let threshold = input[17u * n + i];

    // The light's lobe times the cosine (`push_times_cosine_with`): one product of unit
    // copies, scaled by the light lobe's scale.
    let lc = lobe_product(normalize_axis(la), 1.0, le, normal, 1.0, 1.0);
    let l = lobe_term(normalize_axis(lc.axis), lc.scale * ls, lc.exponent);

    // The reflectance's terms in expansion order: the constant where non-zero, the lobe.
    var r_terms = array<Term, 2>(constant_term(rk), lobe_term(normalize_axis(ra), rs, re));
    var r_first = select(1u, 0u, rk != 0.0);
    let r_end = select(1u, 2u, rn > 0.0);
    if (r_end == 1u) {
        // No lobe: the constant alone, moved to the last slot.
        r_terms[1] = r_terms[0];
        r_first = select(2u, 1u, rk != 0.0);
    }

    let u = triple(r_terms, r_first, l, false, 0u, 0u, 0.0);
    var v = u;
    if (vis_n > 0u) {
        v = triple(r_terms, r_first, l, true, vis_off, vis_n, threshold * abs(u.value));
    }
    output[i] = u.value;
    output[n + i] = v.value;
    output[2u * n + i] = f32(u.computed + select(0u, v.computed, vis_n > 0u));
}
