//! Brute-force point location and `f64` area weights for the control-point paper
//! (Chatelier and Malgouyres, GRAPP 2007): the reference of `steradian_core::cp`.

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn unit(d: [f64; 3]) -> [f64; 3] {
    let l = dot(d, d).sqrt();
    [d[0] / l, d[1] / l, d[2] / l]
}

/// Solid angle of the spherical triangle of unit vectors `(a, b, c)` in `f64`, by the
/// Van Oosterom–Strackee form `2·atan2(|a·(b×c)|, 1 + a·b + b·c + c·a)` with the plain
/// triple product (core takes it on edge differences).
pub fn triangle_area(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    let det = dot(a, cross(b, c)).abs();
    2.0 * det.atan2(1.0 + dot(a, b) + dot(b, c) + dot(c, a))
}

/// The triangle of `triangles` that holds direction `d` (any non-zero length), found by
/// scanning all of them (the one whose smallest edge-plane distance is largest), and the
/// area weights `α_i / Σ α_j` of its vertices.
pub fn locate(vertices: &[[f64; 3]], triangles: &[[u32; 3]], d: [f64; 3]) -> (usize, [f64; 3]) {
    let u = unit(d);
    let mut best = (f64::NEG_INFINITY, 0);
    for (t, tri) in triangles.iter().enumerate() {
        let v = tri.map(|k| vertices[k as usize]);
        let m = (0..3)
            .map(|k| dot(u, unit(cross(v[(k + 1) % 3], v[(k + 2) % 3]))))
            .fold(f64::INFINITY, f64::min);
        if m > best.0 {
            best = (m, t);
        }
    }
    let v = triangles[best.1].map(|k| vertices[k as usize]);
    let a = [
        triangle_area(u, v[1], v[2]),
        triangle_area(v[0], u, v[2]),
        triangle_area(v[0], v[1], u),
    ];
    let s = a[0] + a[1] + a[2];
    (best.1, a.map(|x| x / s))
}
