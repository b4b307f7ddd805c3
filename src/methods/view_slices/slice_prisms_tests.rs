//! Tests of the slicing twin: analytic polygons, the degenerate cases, crack-free shared edges,
//! a flat shell's cross-section area, and naga validation of the three kernels.

use super::*;

type D3 = [f64; 3];

fn sv(bottom: V3, top: V3) -> ShellVertex {
    ShellVertex { bottom: [bottom[0], bottom[1], bottom[2], 1.0], top: [top[0], top[1], top[2], 1.0] }
}

/// A prism with the bounding sphere `load_prism` reads beside it.
struct P {
    prism: Prism,
    sphere: [f32; 4],
}

impl std::ops::Deref for P {
    type Target = Prism;
    fn deref(&self) -> &Prism {
        &self.prism
    }
}

/// [`slice_prism`] of a test prism.
fn slice(v: &[ShellVertex], p: &P, index: u32, n: V3, d: f32, trivial_reject: bool) -> Polygon {
    slice_prism(v, p, p.sphere, index, n, d, trivial_reject)
}

/// A prism over `ids` with its corner uvs and a bounding sphere of its six corners.
fn prism(vertices: &[ShellVertex], ids: [u32; 3], uv: [[f32; 2]; 3]) -> P {
    let corners: Vec<V3> = ids
        .iter()
        .flat_map(|&i| {
            let v = vertices[i as usize];
            [xyz(v.bottom), xyz(v.top)]
        })
        .collect();
    let mut c = [0.0f32; 3];
    for p in &corners {
        for k in 0..3 {
            c[k] += p[k] / 6.0;
        }
    }
    let r = corners.iter().map(|p| len(sub(*p, c))).fold(0.0, f32::max);
    let prism = Prism {
        vertices: [ids[0], ids[1], ids[2], 0],
        uv01: [uv[0][0], uv[0][1], uv[1][0], uv[1][1]],
        uv2: [uv[2][0], uv[2][1], 0.0, 0.0],
    };
    P { prism, sphere: [c[0], c[1], c[2], r * 1.001 + 1e-6] }
}

fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn len(a: V3) -> f32 {
    dot(a, a).sqrt()
}
fn d3(a: V3) -> D3 {
    [a[0] as f64, a[1] as f64, a[2] as f64]
}
fn sub64(a: D3, b: D3) -> D3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot64(a: D3, b: D3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross64(a: D3, b: D3) -> D3 {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}
fn normalize(a: V3) -> V3 {
    let l = len(a);
    [a[0] / l, a[1] / l, a[2] / l]
}

/// Unit right-triangle prism with vertical unit heights; uv = xy.
fn unit_prism() -> (Vec<ShellVertex>, P) {
    let v = vec![
        sv([0.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
        sv([1.0, 0.0, 0.0], [1.0, 0.0, 1.0]),
        sv([0.0, 1.0, 0.0], [0.0, 1.0, 1.0]),
    ];
    let p = prism(&v, [0, 1, 2], [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
    (v, p)
}

fn positions(poly: &Polygon) -> Vec<V3> {
    poly.as_slice().iter().map(|v| xyz(v.position)).collect()
}

/// Polygon area (f64), from the cross products of consecutive vertices.
fn area(pts: &[V3]) -> f64 {
    let mut s = [0.0; 3];
    for i in 0..pts.len() {
        let c = cross64(d3(pts[i]), d3(pts[(i + 1) % pts.len()]));
        for k in 0..3 {
            s[k] += c[k];
        }
    }
    0.5 * dot64(s, s).sqrt()
}

fn dist_to_segment(p: V3, a: V3, b: V3) -> f64 {
    let (p, a, b) = (d3(p), d3(a), d3(b));
    let ab = sub64(b, a);
    let l2 = dot64(ab, ab);
    let t = if l2 > 0.0 { (dot64(sub64(p, a), ab) / l2).clamp(0.0, 1.0) } else { 0.0 };
    let q = [a[0] + t * ab[0], a[1] + t * ab[1], a[2] + t * ab[2]];
    let r = sub64(p, q);
    dot64(r, r).sqrt()
}

/// Every vertex is finite, on the plane and on one of the prism's nine edges; the polygon has
/// at most five vertices.
fn check_on_plane_and_edges(v: &[ShellVertex], p: &Prism, poly: &Polygon, n: V3, d: f32) {
    assert!(poly.len <= 5);
    let ids = p.vertices;
    let b = |i: usize| xyz(v[ids[i] as usize].bottom);
    let t = |i: usize| xyz(v[ids[i] as usize].top);
    for q in poly.as_slice() {
        assert!(q.position.iter().chain(&q.uvw).all(|x| x.is_finite()), "{poly:?}");
        assert!(q.uvw[2] >= 0.0 && q.uvw[2] <= 1.0);
        let x = xyz(q.position);
        let scale = 1.0 + len(x) as f64;
        let off = (dot64(d3(n), d3(x)) - d as f64).abs();
        assert!(off < 1e-5 * scale, "off plane by {off}: {poly:?}");
        let edge = (0..3)
            .flat_map(|i| {
                let j = (i + 1) % 3;
                [(b(i), t(i)), (t(i), t(j)), (b(i), b(j))]
            })
            .map(|(a, e)| dist_to_segment(x, a, e))
            .fold(f64::MAX, f64::min);
        assert!(edge < 1e-5 * scale, "off the edges by {edge}: {poly:?}");
    }
}

/// Convex and simple in plane coordinates: all turns have one sign and they add up to one turn.
fn check_convex(pts: &[V3], n: V3) {
    let n = d3(n);
    let helper = if n[0].abs() < 0.9 { [1.0, 0.0, 0.0] } else { [0.0, 1.0, 0.0] };
    let e1 = cross64(n, helper);
    let e2 = cross64(n, e1);
    let uv: Vec<[f64; 2]> = pts.iter().map(|p| [dot64(d3(*p), e1), dot64(d3(*p), e2)]).collect();
    let m = uv.len();
    let mut sign = 0.0;
    let mut turning = 0.0;
    for i in 0..m {
        let (a, b, c) = (uv[i], uv[(i + 1) % m], uv[(i + 2) % m]);
        let (u, w) = ([b[0] - a[0], b[1] - a[1]], [c[0] - b[0], c[1] - b[1]]);
        let cr = u[0] * w[1] - u[1] * w[0];
        assert!(cr.abs() > 1e-9, "collinear vertices {pts:?}");
        if sign == 0.0 {
            sign = cr.signum();
        }
        assert_eq!(cr.signum(), sign, "not convex: {pts:?}");
        turning += cr.atan2(u[0] * w[0] + u[1] * w[1]);
    }
    assert!((turning.abs() - std::f64::consts::TAU).abs() < 1e-6, "self-intersecting: {pts:?}");
}

/// The plane through `x` with normal `n` (not necessarily unit), as (unit normal, d).
fn plane(n: V3, x: V3) -> (V3, f32) {
    let n = normalize(n);
    (n, dot(n, x))
}

#[test]
fn plane_parallel_to_base_gives_the_base_triangle_at_that_height() {
    let (v, p) = unit_prism();
    for (n, d, z) in [([0.0, 0.0, 1.0], 0.3, 0.3), ([0.0, 0.0, -1.0], -0.7, 0.7)] {
        let poly = slice(&v, &p, 7, n, d, true);
        assert_eq!(poly.len, 3);
        check_on_plane_and_edges(&v, &p, &poly, n, d);
        check_convex(&positions(&poly), n);
        for (q, corner) in poly.as_slice().iter().zip([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]) {
            assert_eq!(q.position, [corner[0], corner[1], z, f32::from_bits(7)]);
            assert_eq!(q.uvw, [corner[0], corner[1], z, 0.0]);
        }
        assert!((area(&positions(&poly)) - 0.5).abs() < 1e-6);
        assert_eq!(triangulate(&poly).len(), 3);
    }
    // Planes containing the bottom or the top: a zero distance is the positive side, so each is
    // sliced from exactly one side, never both, and never yields NaN.
    for z in [0.0f32, 1.0] {
        let up = slice(&v, &p, 0, [0.0, 0.0, 1.0], z, true).len;
        let down = slice(&v, &p, 0, [0.0, 0.0, -1.0], -z, true).len;
        assert_eq!(up + down, 3, "z = {z}");
    }
    assert_eq!(slice(&v, &p, 0, [0.0, 0.0, 1.0], 1.5, true).len, 0);
    assert_eq!(slice(&v, &p, 0, [0.0, 0.0, 1.0], 1.5, false).len, 0);
}

#[test]
fn tilted_planes_give_quad_and_pentagon() {
    let (v, p) = unit_prism();
    // z = 0.5 + 0.8x cuts edge 1 above its top: a quad. z = 0.5 + 0.8x - 0.8y also cuts edge 2
    // below its bottom: a pentagon (classes b, a, c).
    for (n, x, expect) in [
        ([-0.8, 0.0, 1.0], [0.0, 0.0, 0.5], 4),
        ([-0.8, 0.8, 1.0], [0.0, 0.0, 0.5], 5),
        ([0.8, -0.8, -1.0], [0.0, 0.0, 0.5], 5),
        ([-0.3, -0.2, 1.0], [0.0, 0.0, 0.5], 3),
    ] {
        let (n, d) = plane(n, x);
        let poly = slice(&v, &p, 0, n, d, true);
        assert_eq!(poly.len, expect, "{poly:?}");
        check_on_plane_and_edges(&v, &p, &poly, n, d);
        check_convex(&positions(&poly), n);
        assert_eq!(triangulate(&poly).len(), 3 * (expect - 2));
    }
}

#[test]
fn classify_follows_the_paper() {
    assert_eq!(classify(-1.0, 1.0), EdgeClass::Within);
    assert_eq!(classify(0.0, -1.0), EdgeClass::Within);
    assert_eq!(classify(2.0, 1.0), EdgeClass::Above);
    assert_eq!(classify(-2.0, -1.0), EdgeClass::Above);
    assert_eq!(classify(1.0, 2.0), EdgeClass::Below);
    assert_eq!(classify(1.0, 1.0), EdgeClass::Below);
    assert_eq!(classify(-1.0, -1.0), EdgeClass::Below);
    // The prism-oriented rule agrees whenever the edge rises like its prism.
    for (sb, st) in [(-1.0, 1.0), (2.0, 1.0), (-2.0, -1.0), (1.0, 2.0), (-3.0, -4.0), (0.0, 1.0)] {
        let rising = st - sb >= 0.0;
        assert_eq!(classify_oriented(sb, st, rising), classify(sb, st), "{sb} {st}");
    }
    // Parallel edges: on either side of the plane the classes differ, so the sides are kept.
    assert_eq!(classify_oriented(-1.0, -1.0, true), EdgeClass::Above);
    assert_eq!(classify_oriented(1.0, 1.0, true), EdgeClass::Below);
}

#[test]
fn degenerate_planes_through_vertex_edge_and_normal_edge() {
    let (v, p) = unit_prism();
    let cases: [(V3, V3, Option<usize>); 9] = [
        // Through the top of corner 1 only, the rest below: one point, no polygon.
        ([-1.0, -1.0, -1.0], [1.0, 0.0, 1.0], Some(0)),
        // Through the top of corner 1 and cutting the prism: a triangle with a vertex there.
        ([-1.0, 0.2, 1.0], [1.0, 0.0, 1.0], None),
        // Through the upper edge 1-2 (tilted down into the prism).
        ([1.0, 1.0, 1.0], [0.5, 0.5, 1.0], None),
        // Containing normal edge 0 and cutting through the prism: a rectangle.
        ([1.0, -1.0, 0.0], [0.0, 0.0, 0.5], Some(4)),
        // Containing normal edge 0 and only touching: nothing.
        ([1.0, 1.0, 0.0], [0.0, 0.0, 0.5], Some(0)),
        // Parallel to the heights (prism seen exactly side-on): a rectangle, not nothing.
        ([1.0, 0.0, 0.0], [0.25, 0.0, 0.0], Some(4)),
        ([-1.0, 0.0, 0.0], [0.25, 0.0, 0.0], Some(4)),
        // Containing the side face x = 0 (normal edges 0 and 2).
        ([1.0, 0.0, 0.0], [0.0, 0.0, 0.0], None),
        // Through the bottom of corner 0 and the top of corner 1.
        ([-1.0, 0.0, 1.0], [0.0, 0.0, 0.0], None),
    ];
    for (n, x, expect) in cases {
        let (n, d) = plane(n, x);
        let poly = slice(&v, &p, 0, n, d, true);
        if let Some(e) = expect {
            assert_eq!(poly.len, e, "n {n:?}: {poly:?}");
        }
        check_on_plane_and_edges(&v, &p, &poly, n, d);
        if poly.len >= 3 {
            check_convex(&positions(&poly), n);
        }
    }
    let (n, d) = plane([1.0, 0.0, 0.0], [0.25, 0.0, 0.0]);
    assert!((area(&positions(&slice(&v, &p, 0, n, d, true))) - 0.75).abs() < 1e-6);
    let (n, d) = plane([1.0, -1.0, 0.0], [0.0, 0.0, 0.0]);
    let a = area(&positions(&slice(&v, &p, 0, n, d, true)));
    assert!((a - 0.5f64.sqrt()).abs() < 1e-6, "{a}");
}

/// Small deterministic generator (xorshift), uniform in [0, 1).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
    fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.next()
    }
    fn unit(&mut self) -> V3 {
        loop {
            let v = [self.range(-1.0, 1.0), self.range(-1.0, 1.0), self.range(-1.0, 1.0)];
            if (0.01..1.0).contains(&dot(v, v)) {
                return normalize(v);
            }
        }
    }
}

#[test]
fn degenerate_prisms_give_no_nan_and_points_on_the_plane() {
    let shapes: Vec<Vec<ShellVertex>> = vec![
        // Zero-area base (collinear corners).
        vec![
            sv([0.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
            sv([1.0, 0.0, 0.0], [1.0, 0.0, 1.0]),
            sv([2.0, 0.0, 0.0], [2.0, 0.0, 1.0]),
        ],
        // Zero-length height vector at corner 1.
        vec![
            sv([0.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
            sv([1.0, 0.0, 0.0], [1.0, 0.0, 0.0]),
            sv([0.0, 1.0, 0.0], [0.0, 1.0, 1.0]),
        ],
        // All heights zero (a flat triangle).
        vec![
            sv([0.0, 0.0, 0.0], [0.0, 0.0, 0.0]),
            sv([1.0, 0.0, 0.0], [1.0, 0.0, 0.0]),
            sv([0.0, 1.0, 0.0], [0.0, 1.0, 0.0]),
        ],
        // Everything in one point.
        vec![sv([0.5, 0.5, 0.5], [0.5, 0.5, 0.5]); 3],
        // Twisted: crossing heights.
        vec![
            sv([0.0, 0.0, 0.0], [1.0, 0.0, 1.0]),
            sv([1.0, 0.0, 0.0], [0.0, 1.0, 1.0]),
            sv([0.0, 1.0, 0.0], [0.0, 0.0, 1.0]),
        ],
    ];
    let mut rng = Rng(0x9e3779b97f4a7c15);
    for v in &shapes {
        let p = prism(v, [0, 1, 2], [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
        let mut planes: Vec<(V3, f32)> = Vec::new();
        for _ in 0..300 {
            let n = rng.unit();
            let corner = v[(rng.next() * 3.0) as usize % 3];
            let x = if rng.next() < 0.5 { corner.bottom } else { corner.top };
            // Half through a corner exactly, half anywhere near the prism.
            let d = if rng.next() < 0.5 { dot(n, xyz(x)) } else { dot(n, xyz(x)) + rng.range(-1.0, 1.0) };
            planes.push((n, d));
        }
        for axis in [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]] {
            for d in [-0.5, 0.0, 0.5, 1.0] {
                planes.push((axis, d));
            }
        }
        for (n, d) in planes {
            let poly = slice(v, &p, 3, n, d, false);
            check_on_plane_and_edges(v, &p, &poly, n, d);
            let tris = triangulate(&poly);
            assert_eq!(tris.len() as u32, fan_vertex_count(poly.len));
        }
    }
}

/// How many of the prism's nine edges the plane crosses by sign.
fn crossings(v: &[ShellVertex], p: &Prism, n: V3, d: f32) -> usize {
    let s = |x: [f32; 4]| dot(n, xyz(x)) - d >= 0.0;
    let sb: Vec<bool> = (0..3).map(|i| s(v[p.vertices[i] as usize].bottom)).collect();
    let st: Vec<bool> = (0..3).map(|i| s(v[p.vertices[i] as usize].top)).collect();
    (0..3)
        .map(|i| {
            let j = (i + 1) % 3;
            (sb[i] != st[i]) as usize + (st[i] != st[j]) as usize + (sb[i] != sb[j]) as usize
        })
        .sum()
}

#[test]
fn prisms_sharing_an_edge_get_bit_identical_points() {
    let mut rng = Rng(12345);
    let (mut checked, mut clamped) = (0, 0);
    for _ in 0..200 {
        // Two prisms over the quad 0-1-3-2 sharing welded vertices 1 and 2, listed in opposite
        // orders; heights diverging, and half the planes at grazing angles to them, where the
        // heights' slopes along the view disagree in sign.
        let mut v = Vec::new();
        for (x, y) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)] {
            let b = [x + rng.range(-0.2, 0.2), y + rng.range(-0.2, 0.2), rng.range(-0.2, 0.2)];
            let h = [rng.range(-0.3, 0.3), rng.range(-0.3, 0.3), rng.range(0.5, 1.0)];
            v.push(sv(b, [b[0] + h[0], b[1] + h[1], b[2] + h[2]]));
        }
        let uv = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
        let pa = prism(&v, [0, 1, 2], uv);
        let pb = prism(&v, [2, 1, 3], uv);
        let shared: Vec<(V3, V3)> = [1usize, 2]
            .iter()
            .map(|&i| (xyz(v[i].bottom), xyz(v[i].top)))
            .chain([(xyz(v[1].bottom), xyz(v[2].bottom)), (xyz(v[1].top), xyz(v[2].top))])
            .collect();
        for _ in 0..20 {
            let mut n = rng.unit();
            if rng.next() < 0.5 {
                n = normalize([n[0], n[1], n[2] * 0.05]);
            }
            let d = dot(n, [0.5, 0.5, 0.4]) + rng.range(-0.7, 0.7);
            let a = slice(&v, &pa, 0, n, d, true);
            let b = slice(&v, &pb, 1, n, d, true);
            // Both must be polygons, and neither clamped (twisted: more than five crossed edges).
            if a.len == 0 || b.len == 0 {
                continue;
            }
            if crossings(&v, &pa, n, d) > 5 || crossings(&v, &pb, n, d) > 5 {
                clamped += 1;
                continue;
            }
            for (x, y) in [(&a, &b), (&b, &a)] {
                for q in positions(x) {
                    if shared.iter().any(|(e0, e1)| dist_to_segment(q, *e0, *e1) < 1e-6) {
                        let bits = q.map(f32::to_bits);
                        assert!(
                            positions(y).iter().any(|r| r.map(f32::to_bits) == bits),
                            "{q:?} missing from the neighbour: {x:?} {y:?}"
                        );
                        checked += 1;
                    }
                }
            }
        }
    }
    assert!(checked > 500, "only {checked} shared points checked");
    assert!(clamped < 100, "{clamped} of 4000 slices clamped");
}

/// Vertices and prisms of a flat `cells` x `cells` grid over [0, size]^2 at z = 0 with height h.
fn flat_shell(cells: u32, size: f32, h: f32) -> Shell {
    let m = cells + 1;
    let mut v = Vec::new();
    for j in 0..m {
        for i in 0..m {
            let (x, y) = (size * i as f32 / cells as f32, size * j as f32 / cells as f32);
            v.push(sv([x, y, 0.0], [x, y, h]));
        }
    }
    let mut prisms = Vec::new();
    for j in 0..cells {
        for i in 0..cells {
            let (a, b, c, d) = (j * m + i, j * m + i + 1, (j + 1) * m + i, (j + 1) * m + i + 1);
            let uv = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
            prisms.push(prism(&v, [a, b, c], uv));
            prisms.push(prism(&v, [b, d, c], uv));
        }
    }
    Shell::from_parts(v, prisms.iter().map(|p| p.prism).collect(), prisms.iter().map(|p| p.sphere).collect())
}

#[test]
fn flat_shell_cross_section_area_at_30_degrees() {
    let (size, h) = (4.0f32, 0.5f32);
    let shell = flat_shell(16, size, h);
    let v = &shell.vertices;
    // Plane 30 degrees from the base; it crosses the slab over a length h / sin 30 = 2h in the
    // xz-plane, all inside the box, so the cross-section is a 2h x size rectangle.
    let theta = 30f32.to_radians();
    let n = [theta.sin(), 0.0, theta.cos()];
    let params = SliceParams {
        plane_normal: [n[0], n[1], n[2], 0.0],
        first_plane: dot(n, [2.013, 0.0, 0.25]),
        spacing: 0.0,
        plane_count: 1,
        prism_count: shell.prisms.len() as u32,
        vertex_capacity: u32::MAX,
        _pad: [0; 3],
    };
    let tris = &emit_slices(&shell, &params, true)[0];
    let total: f64 =
        tris.chunks(3).map(|t| area(&t.iter().map(|q| xyz(q.position)).collect::<Vec<_>>())).sum();
    let expect = (2.0 * h * size) as f64;
    assert!((total - expect).abs() < 1e-4 * expect, "area {total} vs {expect}");
    // The same by polygons, each convex.
    let mut by_poly = 0.0;
    for (i, (p, &sphere)) in shell.prisms.iter().zip(&shell.spheres).enumerate() {
        let poly = slice_prism(v, p, sphere, i as u32, n, params.first_plane, true);
        if poly.len > 0 {
            check_convex(&positions(&poly), n);
            check_on_plane_and_edges(v, p, &poly, n, params.first_plane);
        }
        by_poly += area(&positions(&poly));
    }
    assert!((by_poly - expect).abs() < 1e-4 * expect);
}

#[test]
fn counts_scan_and_slices_agree_and_trivial_reject_changes_nothing() {
    let shell = flat_shell(6, 2.0, 0.3);
    let n = normalize([0.3, -0.5, 0.8]);
    let (lo, hi) = (dot(n, [0.0, 2.0, 0.0]), dot(n, [2.0, 0.0, 0.3]));
    let params = SliceParams {
        plane_normal: [n[0], n[1], n[2], 0.0],
        first_plane: hi + 0.01,
        spacing: (hi - lo + 0.02) / 63.0,
        plane_count: 64,
        prism_count: shell.prisms.len() as u32,
        vertex_capacity: 1000,
        _pad: [0; 3],
    };
    let slices = emit_slices(&shell, &params, true);
    assert_eq!(slices, emit_slices(&shell, &params, false));
    let counts = count_slices(&shell, &params, true);
    assert_eq!(counts, slices.iter().map(|s| s.len() as u32).collect::<Vec<_>>());
    assert!(counts.iter().filter(|&&c| c > 0).count() > 50);
    let (offsets, args) = scan_plane_offsets(&counts, params.vertex_capacity);
    let total: u32 = counts.iter().sum();
    assert_eq!(offsets[0], 0);
    assert_eq!(offsets[63] + counts[63], total);
    assert_eq!(args.vertex_count, total.min(1000));
    assert_eq!(args.instance_count, 1);
    // Prism indices ascend within each plane (as emit_slices promises).
    for s in &slices {
        let ids: Vec<u32> = s.iter().map(|q| q.position[3].to_bits()).collect();
        assert!(ids.windows(2).all(|w| w[0] <= w[1]));
    }
}

#[test]
fn kernels_validate_and_declare_the_bound_globals() {
    let root = crate::project_root().join("wgsl");
    for (file, globals) in [
        (
            "view_slices/count_slices.wgsl",
            &["slice_params", "shell_vertices", "prisms", "prism_spheres", "plane_cursors"][..],
        ),
        ("view_slices/scan_plane_offsets.wgsl", &["slice_params", "plane_cursors", "draw_args"][..]),
        (
            "view_slices/emit_slices.wgsl",
            &["slice_params", "shell_vertices", "prisms", "prism_spheres", "plane_cursors", "slice_vertices"][..],
        ),
    ] {
        let kernel = crate::gpu::shader::load(&root, file).unwrap_or_else(|e| panic!("{e}"));
        let names: Vec<&str> =
            kernel.module.global_variables.iter().filter_map(|(_, g)| g.name.as_deref()).collect();
        for g in globals {
            assert!(names.contains(g), "{file} lacks {g}: {names:?}");
        }
        let overrides: Vec<&str> =
            kernel.module.overrides.iter().filter_map(|(_, o)| o.name.as_deref()).collect();
        assert_eq!(overrides.contains(&"trivial_reject"), file != "view_slices/scan_plane_offsets.wgsl");
    }
}
