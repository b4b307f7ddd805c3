// Rays against prisms and the inverse prism map; f32 port of src/cpu/prism_map.rs, function for
// function. Prism corners go by pointer (by-value arrays are slow on lavapipe).
#include "shared/barycentrics.wgsl"

// A point counts as inside a prism when its barycentrics are at least -INSIDE_EPS.
const INSIDE_EPS: f32 = 1e-5;
// Relative to the section cubic's coefficients, what counts as a root at w = 0 or 1.
const ZERO_TOL: f32 = 1e-6;

struct PrismShape {
    bottom: array<vec3<f32>, 3>,
    top: array<vec3<f32>, 3>,
    ids: array<u32, 3>,
}

struct Roots {
    count: u32,
    r: array<f32, 2>,
}

// Roots of c0 + c1 x + c2 x^2 without dividing by a coefficient that may vanish.
fn quadratic_roots(c0: f32, c1: f32, c2: f32) -> Roots {
    var out: Roots;
    out.count = 0u;
    let disc = c1 * c1 - 4.0 * c2 * c0;
    if (disc >= 0.0) {
        let sq = sqrt(disc);
        let q = -0.5 * (c1 + select(-sq, sq, c1 >= 0.0));
        if (c2 != 0.0) {
            out.r[out.count] = q / c2;
            out.count += 1u;
        }
        if (q != 0.0) {
            out.r[out.count] = c0 / q;
            out.count += 1u;
        }
    }
    return out;
}

// Ray (origin 0, direction d) against triangle a b c, two-sided; -1 on a miss.
fn ray_triangle(d: vec3<f32>, a: vec3<f32>, b: vec3<f32>, c: vec3<f32>) -> f32 {
    let e1 = b - a;
    let e2 = c - a;
    let p = cross(d, e2);
    let det = dot(e1, p);
    let s = -a;
    let u = dot(s, p) / det;
    let q = cross(s, e1);
    let v = dot(d, q) / det;
    // det = 0: the ray lies in the triangle's plane and only grazes the prism.
    let hit = det != 0.0 && u >= 0.0 && v >= 0.0 && u + v <= 1.0;
    return select(-1.0, dot(e2, q) / det, hit);
}

struct Hits {
    count: u32,
    t: array<f32, 8>,
}

// Adds the crossings of the ray with the bilinear patch q00 q10 (bottom edge) q01 q11 (top edge).
fn ray_patch(d: vec3<f32>, q00: vec3<f32>, q10: vec3<f32>, q01: vec3<f32>, q11: vec3<f32>, hits: ptr<function, Hits>) {
    let e10 = q10 - q00;
    let e00 = q01 - q00;
    let e11 = q11 - q10;
    let c0 = dot(cross(q00, d), e00);
    let c2 = dot(cross(e10, d), e11 - e00);
    let c1 = dot(cross(q10, d), e11) - c0 - c2;
    let roots = quadratic_roots(c0, c1, c2);
    for (var k = 0u; k < roots.count; k++) {
        let u = roots.r[k];
        if (!(u >= 0.0 && u <= 1.0)) {
            continue;
        }
        let a = q00 + e10 * u;
        let b = e00 + (e11 - e00) * u;
        let n = cross(d, b);
        let nn = dot(n, n);
        if (nn == 0.0) {
            continue;
        }
        let v = dot(cross(a, d), n) / nn;
        if (v >= 0.0 && v <= 1.0) {
            (*hits).t[(*hits).count] = dot(cross(a, b), n) / nn;
            (*hits).count += 1u;
        }
    }
}

// Every distance at which the ray crosses the prism's boundary, sorted.
fn boundary_hits(d: vec3<f32>, p: ptr<function, PrismShape>) -> Hits {
    var hits: Hits;
    hits.count = 0u;
    let tb = ray_triangle(d, (*p).bottom[0], (*p).bottom[1], (*p).bottom[2]);
    if (tb >= 0.0) {
        hits.t[hits.count] = tb;
        hits.count += 1u;
    }
    let tt = ray_triangle(d, (*p).top[0], (*p).top[1], (*p).top[2]);
    if (tt >= 0.0) {
        hits.t[hits.count] = tt;
        hits.count += 1u;
    }
    for (var e = 0u; e < 3u; e++) {
        var i = e;
        var j = (e + 1u) % 3u;
        // Canonical order (welded ids), so both prisms sharing the patch get identical hits.
        if ((*p).ids[j] < (*p).ids[i]) {
            i = j;
            j = e;
        }
        ray_patch(d, (*p).bottom[i], (*p).bottom[j], (*p).top[i], (*p).top[j], &hits);
    }
    for (var a = 1u; a < hits.count; a++) {
        let t = hits.t[a];
        var b = a;
        while (b > 0u && hits.t[b - 1u] > t) {
            hits.t[b] = hits.t[b - 1u];
            b -= 1u;
        }
        hits.t[b] = t;
    }
    return hits;
}

fn cubic(c: vec4<f32>, w: f32) -> f32 {
    return ((c.w * w + c.z) * w + c.y) * w + c.x;
}

// Coefficients (x + y w + z w^2 + w w^3) of det(q1 - q0, q2 - q0, x - q0) over the section
// q_i = p_i + w h_i, relative to p_0.
fn section_cubic(x: vec3<f32>, p: ptr<function, PrismShape>) -> vec4<f32> {
    let h0 = (*p).top[0] - (*p).bottom[0];
    let h1 = (*p).top[1] - (*p).bottom[1];
    let h2 = (*p).top[2] - (*p).bottom[2];
    let e1 = (*p).bottom[1] - (*p).bottom[0];
    let e2 = (*p).bottom[2] - (*p).bottom[0];
    let g1 = h1 - h0;
    let g2 = h2 - h0;
    let r = x - (*p).bottom[0];
    let n0 = cross(e1, e2);
    let n1 = cross(e1, g2) + cross(g1, e2);
    let n2 = cross(g1, g2);
    return vec4<f32>(dot(n0, r), dot(n1, r) - dot(n0, h0), dot(n2, r) - dot(n1, h0), -dot(n2, h0));
}

// Root in [lo, hi] given a sign change: Newton steps kept inside the bracket, else bisection
// (24 halvings reach f32 precision on [0, 1]; Newton usually converges in a few steps).
fn bracketed_root(c: vec4<f32>, lo_in: f32, hi_in: f32) -> f32 {
    var lo = lo_in;
    var hi = hi_in;
    var f_lo = cubic(c, lo);
    var w = 0.5 * (lo + hi);
    var done = false;
    for (var k = 0; k < 24 && !done; k++) {
        let f = cubic(c, w);
        if ((f < 0.0) == (f_lo < 0.0)) {
            lo = w;
            f_lo = f;
        } else {
            hi = w;
        }
        let df = (3.0 * c.w * w + 2.0 * c.z) * w + c.y;
        let newton = w - f / df;
        var next = 0.5 * (lo + hi);
        if (newton > lo && newton < hi) {
            next = newton;
        }
        done = f == 0.0 || abs(next - w) <= 1e-7 * (1.0 + abs(w)) || hi - lo <= 1e-7;
        w = select(next, w, f == 0.0);
    }
    return w;
}

// The inverse prism map: (b, w) with x = sum_i b_i (p_i + w h_i); w < 0 when x is outside.
// [0, 1] is cut at the cubic's critical points into monotone pieces; the first root whose
// barycentrics lie in the section wins. No division by the leading coefficient, so parallel
// height vectors (a quadratic or linear equation) take the same path.
fn prism_inverse(x: vec3<f32>, p: ptr<function, PrismShape>) -> vec4<f32> {
    let c = section_cubic(x, p);
    var cuts = array<f32, 4>(0.0, 1.0, 1.0, 1.0);
    var n = 1u;
    let crit = quadratic_roots(c.y, 2.0 * c.z, 3.0 * c.w);
    var c0 = 2.0;
    var c1 = 2.0;
    if (crit.count > 0u && crit.r[0] > 0.0 && crit.r[0] < 1.0) {
        c0 = crit.r[0];
    }
    if (crit.count > 1u && crit.r[1] > 0.0 && crit.r[1] < 1.0) {
        c1 = crit.r[1];
    }
    let lo_c = min(c0, c1);
    let hi_c = max(c0, c1);
    if (lo_c < 1.0) {
        cuts[n] = lo_c;
        n += 1u;
    }
    if (hi_c < 1.0) {
        cuts[n] = hi_c;
        n += 1u;
    }
    cuts[n] = 1.0;
    // Points on the bottom or top face give f(0) or f(1) = 0 up to rounding.
    let tol = ZERO_TOL * dot(abs(c), vec4<f32>(1.0));
    var result = vec4<f32>(0.0, 0.0, 0.0, -1.0);
    for (var k = 0u; k < n; k++) {
        let lo = cuts[k];
        let hi = cuts[k + 1u];
        let f_lo = cubic(c, lo);
        let f_hi = cubic(c, hi);
        var w = -1.0;
        if (abs(f_lo) <= tol) {
            w = lo;
        } else if (abs(f_hi) <= tol) {
            w = hi;
        } else if ((f_lo < 0.0) != (f_hi < 0.0)) {
            w = bracketed_root(c, lo, hi);
        }
        if (w < 0.0) {
            continue;
        }
        let q0 = mix((*p).bottom[0], (*p).top[0], w);
        let q1 = mix((*p).bottom[1], (*p).top[1], w);
        let q2 = mix((*p).bottom[2], (*p).top[2], w);
        let b = barycentrics(x, q0, q1, q2, vec3<f32>(-2.0));
        if (all(b >= vec3<f32>(-INSIDE_EPS))) {
            result = vec4<f32>(b, w);
            break;
        }
    }
    return result;
}
