// steradian: SH rotation of one coefficient vector per invocation by ZXZXZ (mirrors
// `sh::rotate::rotate_zxzxz`, in f32: WGSL has no f64), each row with its own rotation.
// Input: bands² coefficient columns (coefficient k of row i at k·n + i), then the seven
// columns of `sh::rotate::Rotation::gpu_row` ([mode, cos α, sin α, cos β, sin β, cos γ,
// sin γ]); output: bands² columns. The table (binding 3) is [bands, the blocks of
// `sh::rotate::x90_into`] (block l: (2l+1)² row-major entries from offset 1 + l·(4l²−1)/3);
// bands from 32 on come out NaN.
//
// Per band l, as the scalar kernel: mode 0 is Z(α); mode 1 multiplies by (−1)^l, and −1
// more for m < 0 (M(Ry(π))), then Z(α); mode 2 is Z(γ), J, Z(β), Jᵀ, Z(α). Z(θ) turns each
// pair (m, −m) at (l + m, l − m) by mθ, cos mθ and sin mθ by angle addition from (cos θ,
// sin θ).

@group(0) @binding(3) var<storage, read> table: array<f32>;

// Z(θ) on one band in place.
fn zx_rotate_z(l: u32, c1: f32, s1: f32, band: ptr<function, array<f32, 64>>) {
    var c = 1.0;
    var s = 0.0;
    for (var m = 1u; m <= l; m++) {
        let c2 = c * c1 - s * s1;
        s = c * s1 + s * c1;
        c = c2;
        let p = (*band)[l + m];
        let q = (*band)[l - m];
        (*band)[l + m] = p * c - q * s;
        (*band)[l - m] = p * s + q * c;
    }
}

// y = J·x (transpose false) or Jᵀ·x for band l's block, four terms per iteration (with one
// term per iteration, lavapipe stopped this shader's loops partway through band 28 of 29:
// its loop limiter counts about 65 000 iterations per shader in all). Entries of x from w on are 0 (the bands run in increasing size and
// nothing is written there before), so the padded terms add exact zeros.
fn zx_apply(l: u32, transpose: bool, x: ptr<function, array<f32, 64>>, y: ptr<function, array<f32, 64>>) {
    let w = 2u * l + 1u;
    let base = 1u + l * (4u * l * l - 1u) / 3u;
    let last = base + w * w - 1u;
    for (var r = 0u; r < w; r++) {
        var acc = 0.0;
        for (var c = 0u; c < w; c += 4u) {
            var at = vec4<u32>(base + r * w + c) + vec4<u32>(0u, 1u, 2u, 3u);
            if (transpose) {
                at = vec4<u32>(base + r) + vec4<u32>(c, c + 1u, c + 2u, c + 3u) * w;
            }
            // Indices past the block (their x is 0) read its last entry instead.
            at = min(at, vec4<u32>(last));
            acc = acc + table[at.x] * (*x)[c];
            acc = acc + table[at.y] * (*x)[c + 1u];
            acc = acc + table[at.z] * (*x)[c + 2u];
            acc = acc + table[at.w] * (*x)[c + 3u];
        }
        (*y)[r] = acc;
    }
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = batch_row(gid);
    let n = params.n;
    if (i >= n) {
        return;
    }
    let bands = u32(table[0]);
    let nn = bands * bands;
    let mode = input[nn * n + i];
    let ca = input[(nn + 1u) * n + i];
    let sa = input[(nn + 2u) * n + i];
    let cb = input[(nn + 3u) * n + i];
    let sb = input[(nn + 4u) * n + i];
    let cg = input[(nn + 5u) * n + i];
    let sg = input[(nn + 6u) * n + i];
    var a: array<f32, 64>;
    var b: array<f32, 64>;
    for (var l = 0u; l < bands; l++) {
        let w = 2u * l + 1u;
        let first = l * l;
        if (l >= 32u) {
            // Past the supported bands (the scratch arrays' size): NaN, not a silently
            // missing band.
            for (var t = 0u; t < w; t++) {
                output[(first + t) * n + i] = bitcast<f32>(0x7fc00000u);
            }
            continue;
        }
        for (var t = 0u; t < w; t++) {
            a[t] = input[(first + t) * n + i];
        }
        if (mode < 0.5) {
            zx_rotate_z(l, ca, sa, &a);
        } else if (mode < 1.5) {
            var sl = 1.0;
            if (l % 2u == 1u) {
                sl = -1.0;
            }
            for (var t = 0u; t < w; t++) {
                if (t < l) {
                    a[t] = -sl * a[t];
                } else {
                    a[t] = sl * a[t];
                }
            }
            zx_rotate_z(l, ca, sa, &a);
        } else {
            zx_rotate_z(l, cg, sg, &a);
            zx_apply(l, false, &a, &b);
            zx_rotate_z(l, cb, sb, &b);
            zx_apply(l, true, &b, &a);
            zx_rotate_z(l, ca, sa, &a);
        }
        for (var t = 0u; t < w; t++) {
            output[(first + t) * n + i] = a[t];
        }
    }
}
