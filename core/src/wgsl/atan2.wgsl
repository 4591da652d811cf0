// steradian: atan2 with full relative precision, shared by the lobe-product and HVL kernels
// (`wgsl.rs` concatenates it into both).

// atan2(y, x) for y >= 0 (Cephes' atanf polynomial after reduction to [0, tan(π/8)]):
// full relative precision for small results, which WGSL's atan2 does not promise.
fn atan2_(y: f32, x: f32) -> f32 {
    if (y == 0.0) {
        return select(0.0, 3.1415927, x < 0.0);
    }
    let ax = abs(x);
    let swap = y > ax;
    let t = select(y, ax, swap) / select(ax, y, swap);
    var z = t;
    var base = 0.0;
    if (t > 0.41421357) {
        z = (t - 1.0) / (t + 1.0);
        base = 0.7853982;
    }
    let zz = z * z;
    let p = ((0.0805374449538 * zz - 0.138776856032) * zz + 0.199777106478) * zz - 0.333329491539;
    var r = base + (z + z * zz * p);
    if (swap) {
        r = 1.5707964 - r;
    }
    if (x < 0.0) {
        r = 3.1415927 - r;
    }
    return r;
}
