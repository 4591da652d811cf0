// steradian: summed-area table box query (mirrors `sat::SatView::box_sum`).
// Input columns [u0, v0, u1, v1] (texel units, corners in any order), output [value].
// Binding 3 is the table in the layout of `SatView::gpu_words`: the header
// [width, height, exponent (i32 bits), 0], then entry S(k, l) at word 4 + 2*(l*(width+1) + k)
// as the (low, high) words of a two's complement i64, in quanta of 2^exponent.
// Specified for finite inputs only; see `steradian_core::wgsl`.

@group(0) @binding(3) var<storage, read> table: array<u32>;

fn sat_entry(at: u32) -> vec2<u32> {
    return vec2<u32>(table[4u + 2u * at], table[5u + 2u * at]);
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
fn sat_row(l: u32, w1: u32, i0: u32, i1: u32) -> array<vec2<u32>, 4> {
    let base = l * w1;
    return array<vec2<u32>, 4>(
        sat_entry(base + i0),
        sat_entry(base + i0 + 1u),
        sat_entry(base + i1),
        sat_entry(base + i1 + 1u),
    );
}

// X(l, m) = P + a1*E1 - a0*E0 from exact 64-bit double differences.
fn sat_x(l: array<vec2<u32>, 4>, m: array<vec2<u32>, 4>, a0: f32, a1: f32) -> f32 {
    let p = sub64(sub64(m[2], m[0]), sub64(l[2], l[0]));
    let e1 = sub64(sub64(m[3], m[2]), sub64(l[3], l[2]));
    let e0 = sub64(sub64(m[1], m[0]), sub64(l[1], l[0]));
    return (i64_to_f32(p) + a1 * i64_to_f32(e1)) - a0 * i64_to_f32(e0);
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = batch_row(gid);
    let n = params.n;
    if (i >= n) {
        return;
    }
    let w = table[0];
    let h = table[1];
    let e = bitcast<i32>(table[2]);
    let ax = sat_axis(input[i], input[2u * n + i], w);
    let ay = sat_axis(input[n + i], input[3u * n + i], h);
    let w1 = w + 1u;
    let r0 = sat_row(ay.i0, w1, ax.i0, ax.i1);
    let r0p = sat_row(ay.i0 + 1u, w1, ax.i0, ax.i1);
    let r1 = sat_row(ay.i1, w1, ax.i0, ax.i1);
    let r1p = sat_row(ay.i1 + 1u, w1, ax.i0, ax.i1);
    let x_box = sat_x(r0, r1, ax.a0, ax.a1);
    let x_top = sat_x(r1, r1p, ax.a0, ax.a1);
    let x_bottom = sat_x(r0, r0p, ax.a0, ax.a1);
    let q = (x_box + ay.a1 * x_top) - ay.a0 * x_bottom;
    // q * 2^e in two steps: WGSL's ldexp needs its exponent within [-126, 127].
    let e_half = e / 2;
    output[i] = ldexp(ldexp(q, e_half), e - e_half);
}
