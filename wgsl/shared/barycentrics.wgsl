// Barycentrics of a point in a triangle, shared by prism_map.wgsl (the inverse prism map) and
// draw_slices.wgsl (per-pixel lighting). CPU twin: `barycentrics` in src/cpu/prism_map.rs.

// Barycentrics of x (in the triangle's plane) in q0 q1 q2; `fallback` when the triangle is degenerate.
// Area ratios against n = e1 x e2: rounding grows as 1/sin of the smallest angle, not 1/sin^2 as
// with the normal equations (which lost every digit of a sliver's barycentrics in f32).
fn barycentrics(x: vec3<f32>, q0: vec3<f32>, q1: vec3<f32>, q2: vec3<f32>, fallback: vec3<f32>) -> vec3<f32> {
    let e1 = q1 - q0;
    let e2 = q2 - q0;
    let e = x - q0;
    let n = cross(e1, e2);
    let nn = dot(n, n);
    let b1 = dot(cross(e, e2), n) / nn;
    let b2 = dot(cross(e1, e), n) / nn;
    let degenerate = nn <= 1e-12 * dot(e1, e1) * dot(e2, e2) || nn == 0.0;
    return select(vec3<f32>(1.0 - b1 - b2, b1, b2), fallback, degenerate);
}
