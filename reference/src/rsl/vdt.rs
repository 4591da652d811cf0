//! Signed distances to the visibility boundary and exact clipped areas, in `f64`: the
//! references of `steradian_core::rsl::vdt` (texel units; texel `(i, j)` covers
//! `[i, i+1]×[j, j+1]`, row `j` along `v`; positive distances on the visible side).

/// `±√d2` (`+` visible; `±∞` when there is no boundary).
fn signed(d2: f64, visible: bool) -> f64 {
    let d = d2.sqrt();
    if visible { d } else { -d }
}

/// Brute-force signed distance from every texel centre to the boundary (the union of the
/// texel edges between the two classes): the minimum over every such edge of the `f64`
/// point-to-segment distance, `±∞` without a boundary.
/// `O(texels × edges)`: small maps only.
pub fn brute_force_edges(w: usize, h: usize, mask: &[bool]) -> Vec<f64> {
    let m = |i: usize, j: usize| mask[j * w + i];
    // Segments as (x0, y0, x1, y1).
    let mut segs = Vec::new();
    for j in 0..h {
        for x in 1..w {
            if m(x - 1, j) != m(x, j) {
                segs.push((x as f64, j as f64, x as f64, j as f64 + 1.0));
            }
        }
    }
    for y in 1..h {
        for i in 0..w {
            if m(i, y - 1) != m(i, y) {
                segs.push((i as f64, y as f64, i as f64 + 1.0, y as f64));
            }
        }
    }
    let mut out = vec![0.0f64; w * h];
    for j in 0..h {
        for i in 0..w {
            let (px, py) = (i as f64 + 0.5, j as f64 + 0.5);
            let mut best = f64::INFINITY;
            for &(x0, y0, x1, y1) in &segs {
                let dx = px - px.clamp(x0, x1);
                let dy = py - py.clamp(y0, y1);
                best = best.min(dx * dx + dy * dy);
            }
            out[j * w + i] = signed(best, m(i, j));
        }
    }
    out
}

/// Brute-force signed distance by another route: from each texel centre to the nearest
/// closed texel square of the other class (`O(texels²)`).
pub fn brute_force_squares(w: usize, h: usize, mask: &[bool]) -> Vec<f64> {
    let mut out = vec![0.0f64; w * h];
    for j in 0..h {
        for i in 0..w {
            let me = mask[j * w + i];
            let (px, py) = (i as f64 + 0.5, j as f64 + 0.5);
            let mut best = f64::INFINITY;
            for l in 0..h {
                for k in 0..w {
                    if mask[l * w + k] != me {
                        let dx = px - px.clamp(k as f64, k as f64 + 1.0);
                        let dy = py - py.clamp(l as f64, l as f64 + 1.0);
                        best = best.min(dx * dx + dy * dy);
                    }
                }
            }
            out[j * w + i] = signed(best, me);
        }
    }
    out
}

/// A convex polygon clipped to the half-plane `n·x ≥ c` (Sutherland–Hodgman, `f64`).
pub fn clip(poly: &[[f64; 2]], n: [f64; 2], c: f64) -> Vec<[f64; 2]> {
    let s = |p: [f64; 2]| n[0] * p[0] + n[1] * p[1] - c;
    let mut out = Vec::with_capacity(poly.len() + 1);
    for k in 0..poly.len() {
        let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
        let (sa, sb) = (s(a), s(b));
        if sa >= 0.0 {
            out.push(a);
        }
        if (sa >= 0.0) != (sb >= 0.0) {
            let t = sa / (sa - sb);
            out.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
        }
    }
    out
}

/// Area of a simple polygon (shoelace, `f64`).
pub fn polygon_area(p: &[[f64; 2]]) -> f64 {
    let mut a = 0.0;
    for k in 0..p.len() {
        let (u, v) = (p[k], p[(k + 1) % p.len()]);
        a += u[0] * v[1] - v[0] * u[1];
    }
    0.5 * a.abs()
}
