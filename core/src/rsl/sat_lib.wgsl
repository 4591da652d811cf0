// steradian: summed-area table box sums, shared by the SAT-box and shade kernels (`wgsl.rs`
// concatenates it into both). A kernel that includes it declares `table: array<u32>` at
// binding 3; a table's entry S(k, l) of a (w + 1)-wide grid is at word
// base + 2*(l*(w + 1) + k) as the (low, high) words of a two's complement i64, in quanta of
// 2^exponent (the layout of `SatView::gpu_words` after its header).

fn sat_entry(base: u32, at: u32) -> vec2<u32> {
    return vec2<u32>(table[base + 2u * at], table[base + 2u * at + 1u]);
}

// a - b in 64-bit two's complement (x = low word, y = high word): exact.
fn sub64(a: vec2<u32>, b: vec2<u32>) -> vec2<u32> {
    let borrow = select(0u, 1u, a.x < b.x);
    return vec2<u32>(a.x - b.x, a.y - b.y - borrow);
}

// A 64-bit two's complement integer (|x| < 2^63) to f32. The magnitude is converted, so
// the two words never cancel (hi*2^32 + lo of a small negative number would).
fn i64_to_f32(a: vec2<u32>) -> f32 {
    let neg = (a.y & 0x80000000u) != 0u;
    var m = a;
    if (neg) {
        m = sub64(vec2<u32>(0u, 0u), a);
    }
    let v = f32(m.y) * 4294967296.0 + f32(m.x);
    return select(v, -v, neg);
}

struct Axis {
    i0: u32,
    a0: f32,
    i1: u32,
    a1: f32,
}

// The ordered, clipped interval [lo, hi] of [0, n] as lo = i0 + a0, hi = i1 + a1,
// i <= n - 1 (every step exact, as in the scalar kernel).
fn sat_axis(c0: f32, c1: f32, n: u32) -> Axis {
    let nf = f32(n);
    let lo = clamp(min(c0, c1), 0.0, nf);
    let hi = clamp(max(c0, c1), 0.0, nf);
    let last = f32(n - 1u);
    let i0 = min(floor(lo), last);
    let i1 = min(floor(hi), last);
    return Axis(u32(i0), lo - i0, u32(i1), hi - i1);
}

// [S(I0), S(I0+1), S(I1), S(I1+1)] of row l.
fn sat_row(base: u32, l: u32, w1: u32, i0: u32, i1: u32) -> array<vec2<u32>, 4> {
    let b = l * w1;
    return array<vec2<u32>, 4>(
        sat_entry(base, b + i0),
        sat_entry(base, b + i0 + 1u),
        sat_entry(base, b + i1),
        sat_entry(base, b + i1 + 1u),
    );
}

// X(l, m) = P + a1*E1 - a0*E0 from exact 64-bit double differences.
fn sat_x(l: array<vec2<u32>, 4>, m: array<vec2<u32>, 4>, a0: f32, a1: f32) -> f32 {
    let p = sub64(sub64(m[2], m[0]), sub64(l[2], l[0]));
    let e1 = sub64(sub64(m[3], m[2]), sub64(l[3], l[2]));
    let e0 = sub64(sub64(m[1], m[0]), sub64(l[1], l[0]));
    return (i64_to_f32(p) + a1 * i64_to_f32(e1)) - a0 * i64_to_f32(e0);
}

// Box sum over the axes `ax`, `ay` of the w-wide table whose entries start at word `base`,
// with exponent `e`: the nine sub-box sums combined in f32, then scaled by 2^e.
fn sat_box_sum(base: u32, e: i32, w: u32, ax: Axis, ay: Axis) -> f32 {
    let w1 = w + 1u;
    let r0 = sat_row(base, ay.i0, w1, ax.i0, ax.i1);
    let r0p = sat_row(base, ay.i0 + 1u, w1, ax.i0, ax.i1);
    let r1 = sat_row(base, ay.i1, w1, ax.i0, ax.i1);
    let r1p = sat_row(base, ay.i1 + 1u, w1, ax.i0, ax.i1);
    let x_box = sat_x(r0, r1, ax.a0, ax.a1);
    let x_top = sat_x(r1, r1p, ax.a0, ax.a1);
    let x_bottom = sat_x(r0, r0p, ax.a0, ax.a1);
    return scale2((x_box + ay.a1 * x_top) - ay.a0 * x_bottom, e);
}

// x * 2^e in two steps: WGSL's ldexp needs its exponent within [-126, 127].
fn scale2(x: f32, e: i32) -> f32 {
    let e_half = e / 2;
    return ldexp(ldexp(x, e_half), e - e_half);
}
