// ShellMarch's prisms along one pixel's ray (included by march_shell.wgsl, which declares the
// ray and the held intervals): crossings of the prism's boundary with the exact map there, and
// the intervals between them with their samples and interpolation pieces.

#include "shared/shell_prism.wgsl"

// This invocation's crossings of the current prism, sorted: ray distance and (b0, b1, b2, w), the
// exact inverse map there. In workgroup memory (a slice per invocation) rather than a private
// array: llvmpipe pays for every private array at each dispatch, even one that ends at once.
fn add_crossing(t: f32, c: vec4<f32>) {
    let base = slot * MAX_CROSSINGS;
    var k = crossing_count;
    while (k > 0u && crossing_t[base + k - 1u] > t) {
        crossing_t[base + k] = crossing_t[base + k - 1u];
        crossing_c[base + k] = crossing_c[base + k - 1u];
        k -= 1u;
    }
    crossing_t[base + k] = t;
    crossing_c[base + k] = c;
    crossing_count += 1u;
}

// ray_triangle (prism_map.wgsl) with where it hits: (t, u, v), hit = a + u (b - a) + v (c - a);
// t = -1 on a miss.
fn triangle_hit(a: vec3<f32>, b: vec3<f32>, c: vec3<f32>) -> vec3<f32> {
    let e1 = b - a;
    let e2 = c - a;
    let p = cross(ray, e2);
    let det = dot(e1, p);
    let u = dot(-a, p) / det;
    let q = cross(-a, e1);
    let v = dot(ray, q) / det;
    let hit = det != 0.0 && u >= 0.0 && v >= 0.0 && u + v <= 1.0;
    return select(vec3<f32>(-1.0, 0.0, 0.0), vec3<f32>(dot(e2, q) / det, u, v), hit);
}

// ray_patch (prism_map.wgsl), the same arithmetic, with where it crosses: corner i's weight
// 1 - u, corner j's u, and w = v. Corners in canonical (welded id) order give both prisms
// sharing the side the same crossings.
fn patch_crossings(i: u32, j: u32, p: ptr<function, PrismShape>) {
    let q00 = (*p).bottom[i];
    let q10 = (*p).bottom[j];
    let e10 = q10 - q00;
    let e00 = (*p).top[i] - q00;
    let e11 = (*p).top[j] - q10;
    let c0 = dot(cross(q00, ray), e00);
    let c2 = dot(cross(e10, ray), e11 - e00);
    let c1 = dot(cross(q10, ray), e11) - c0 - c2;
    let roots = quadratic_roots(c0, c1, c2);
    for (var k = 0u; k < roots.count; k++) {
        let u = roots.r[k];
        if (!(u >= 0.0 && u <= 1.0)) {
            continue;
        }
        let a = q00 + e10 * u;
        let b = e00 + (e11 - e00) * u;
        let n = cross(ray, b);
        let nn = dot(n, n);
        if (nn == 0.0) {
            continue;
        }
        let v = dot(cross(a, ray), n) / nn;
        if (v >= 0.0 && v <= 1.0) {
            var c = vec4<f32>(0.0, 0.0, 0.0, v);
            c[i] = 1.0 - u;
            c[j] = u;
            add_crossing(dot(cross(a, b), n) / nn, c);
        }
    }
}

// The crossing of the ray with the prism's flat section at height w (its bottom at 0, its top at 1).
fn section_crossing(p: ptr<function, PrismShape>, w: f32) {
    let hit = triangle_hit(mix((*p).bottom[0], (*p).top[0], w), mix((*p).bottom[1], (*p).top[1], w), mix((*p).bottom[2], (*p).top[2], w));
    if (hit.x >= 0.0) {
        add_crossing(hit.x, vec4<f32>(1.0 - hit.y - hit.z, hit.y, hit.z, w));
    }
}

// Every crossing of the ray with the prism's boundary and with the sections bounding its band
// (where they are inside it), sorted, with the map's value there.
fn crossings(p: ptr<function, PrismShape>, band: vec2<f32>) {
    crossing_count = 0u;
    section_crossing(p, 0.0);
    section_crossing(p, 1.0);
    if (band.x > 0.0) {
        section_crossing(p, band.x);
    }
    if (band.y < 1.0) {
        section_crossing(p, band.y);
    }
    for (var e = 0u; e < 3u; e++) {
        var i = e;
        var j = (e + 1u) % 3u;
        if ((*p).ids[j] < (*p).ids[i]) {
            i = j;
            j = e;
        }
        patch_crossings(i, j, p);
    }
}

// (s, t, w) in voxels of the prism's texel at map value c.
fn voxels(index: u32, c: vec4<f32>) -> vec3<f32> {
    let prism = shell_prisms[index];
    let res = vec3<f32>(shell_objects[prism.vertices.w].resolution.xyz);
    let st = c.x * prism.uv01.xy + c.y * prism.uv01.zw + c.z * prism.uv2.xy;
    return vec3<f32>(st, c.w) * res;
}

// Newton steps of `prism_near` and how close (relative to the prism's size) its point must come.
const NEAR_STEPS: u32 = 4u;
const NEAR_RESIDUAL: f32 = 1e-5;

// The inverse map at x by Newton steps on the prism map from `guess`, a nearby map value (b0, b1,
// b2, w): where the map is one to one (prisms that do not fold) a point near the guess has one
// preimage, found in a fixed few steps without the cubic of `prism_inverse`. w = -1 where the
// steps do not settle on x inside the prism (the caller then maps exactly).
fn prism_near(x: vec3<f32>, p: ptr<function, PrismShape>, guess: vec4<f32>) -> vec4<f32> {
    let h0 = (*p).top[0] - (*p).bottom[0];
    let h1 = (*p).top[1] - (*p).bottom[1];
    let h2 = (*p).top[2] - (*p).bottom[2];
    var b = guess.yz;
    var w = guess.w;
    var r = vec3<f32>(0.0);
    for (var k = 0u; k < NEAR_STEPS; k++) {
        let q0 = (*p).bottom[0] + h0 * w;
        let e1 = (*p).bottom[1] + h1 * w - q0;
        let e2 = (*p).bottom[2] + h2 * w - q0;
        let dw = h0 + (h1 - h0) * b.x + (h2 - h0) * b.y;
        r = q0 + e1 * b.x + e2 * b.y - x;
        // Solves [e1 e2 dw] d = r by Cramer's rule.
        let det = dot(e1, cross(e2, dw));
        let d = vec3<f32>(dot(r, cross(e2, dw)), dot(e1, cross(r, dw)), dot(e1, cross(e2, r))) / det;
        b -= d.xy;
        w -= d.z;
    }
    let q0 = (*p).bottom[0] + h0 * w;
    r = q0 + ((*p).bottom[1] + h1 * w - q0) * b.x + ((*p).bottom[2] + h2 * w - q0) * b.y - x;
    let size = length((*p).top[0] - (*p).bottom[1]) + length((*p).bottom[2] - (*p).bottom[0]);
    let c = vec4<f32>(1.0 - b.x - b.y, b, w);
    let inside = all(c >= vec4<f32>(-INSIDE_EPS)) && w <= 1.0 + INSIDE_EPS;
    return select(vec4<f32>(0.0, 0.0, 0.0, -1.0), c, inside && length(r) <= NEAR_RESIDUAL * size);
}

fn max3(v: vec3<f32>) -> f32 {
    return max(max(v.x, v.y), v.z);
}

// How far (voxels, largest axis) the straight line from ca to cb strays from the exact map at
// the thirds of [ta, tb]; FAR where the exact map fails there.
fn line_error(index: u32, shape: ptr<function, PrismShape>, ta: f32, tb: f32, ca: vec4<f32>, cb: vec4<f32>) -> f32 {
    var err = 0.0;
    for (var k = 1u; k < 3u; k++) {
        let f = f32(k) / 3.0;
        let exact = prism_near(ray * mix(ta, tb, f), shape, mix(ca, cb, f));
        err = max(err, select(FAR, max3(abs(voxels(index, exact) - voxels(index, mix(ca, cb, f)))), exact.w >= 0.0));
    }
    return err;
}

// Makes piece j the current piece of interval s: its ends mapped exactly (the interval's own
// ends from its crossings), the line between them checked unless it is the whole interval.
// `next`: piece j follows the current one, whose end (the same t, bit for bit) is its start.
fn set_piece(s: u32, j: u32, ca_known: vec4<f32>, next: bool) {
    budget -= PIECE_COST;
    let m = iv_pieces[s];
    iv_piece[s] = j;
    if (m == 0u) {
        iv_exact[s] = true;
        iv_ta[s] = iv_t0[s];
        iv_tb[s] = iv_t1[s];
        return;
    }
    let t0 = iv_t0[s];
    let t1 = iv_t1[s];
    let ta = select(t0 + (t1 - t0) * f32(j) / f32(m), t0, j == 0u);
    let tb = select(t0 + (t1 - t0) * f32(j + 1u) / f32(m), t1, j + 1u == m);
    var shape = load_shape(iv_prism[s]);
    var ca = ca_known;
    if (next) {
        ca = iv_cb[s];
    }
    var cb = iv_c1[s];
    // The ends mapped exactly, through one call: llvmpipe inlines every call of the solver
    // whole, and the larger kernel ran 12% slower.
    for (var e = 0u; e < 2u; e++) {
        let start = e == 0u;
        if (select(j + 1u < m, !next && j > 0u, start)) {
            let c = prism_inverse(ray * select(tb, ta, start), &shape);
            if (start) {
                ca = c;
            } else {
                cb = c;
            }
        }
    }
    var exact = ca.w < 0.0 || cb.w < 0.0;
    if (m > 1u && !exact) {
        exact = line_error(iv_prism[s], &shape, ta, tb, ca, cb) > shell_objects[shell_prisms[iv_prism[s]].vertices.w].params.z;
    }
    exact_pieces += u32(exact);
    iv_exact[s] = exact;
    iv_ta[s] = ta;
    iv_tb[s] = tb;
    iv_ca[s] = ca;
    iv_cb[s] = cb;
}

// The MIP level (fractional, from 0 to the last) that a sample in prism `index` at distance t reads:
// log2 of the pixel's footprint there in voxels of s and t, plus the bias; 0 without filtering.
fn footprint_level(index: u32, t: f32) -> f32 {
    let prism = shell_prisms[index];
    let footprint = shell_filters[prism.vertices.w];
    if (!filtering || footprint.levels <= 1u) {
        return 0.0;
    }
    return clamp(log2(cone * t * prism.uv2.w) + footprint.bias, 0.0, f32(footprint.levels - 1u));
}

// Holds the ray's stretch [t0, t1] inside prism `index` (map values c0, c1 at its ends, c3 at
// its first third): its samples, how its interpolation is split, and where it resumes.
fn add_interval(index: u32, t0: f32, t1: f32, c0: vec4<f32>, c1: vec4<f32>, c3: vec4<f32>, shape: ptr<function, PrismShape>) {
    if (t0 >= t_opaque) {
        return;
    }
    if (held >= MAX_ACTIVE) {
        dropped += 1u;
        return;
    }
    let object = shell_objects[shell_prisms[index].vertices.w];
    let c6 = prism_inverse(ray * mix(t0, t1, 2.0 / 3.0), shape);
    let folded = shell_prisms[index].uv2.z != 0.0;
    let v3 = voxels(index, c3);
    let v1 = voxels(index, c1);
    let v0 = select(v3, voxels(index, c0), c0.w >= 0.0);
    let v6 = select(mix(v3, v1, 0.5), voxels(index, c6), c6.w >= 0.0);
    // Filtered, the samples read the level of the footprint at the interval's middle, whose
    // voxels are 2^level wide in s and t.
    let level = footprint_level(index, 0.5 * (t0 + t1));
    let coarse = vec3<f32>(vec2<f32>(exp2(-floor(level))), 1.0);
    // Samples: the path through (s, t, w) in voxels over `step`, and at least one per w-voxel.
    let path = max3(abs(v3 - v0) * coarse) + max3(abs(v6 - v3) * coarse) + max3(abs(v1 - v6) * coarse);
    let path_w = abs(v3.z - v0.z) + abs(v6.z - v3.z) + abs(v1.z - v6.z);
    let n = u32(clamp(ceil(max(path / object.params.y, path_w)), 1.0, MAX_SAMPLES));
    let h = (t1 - t0) / f32(n);
    // The first sample not composited by an earlier dispatch.
    var k = u32(clamp(ceil((t_resume - t0) / h - 0.5), 0.0, f32(n)));
    while (k > 0u && t0 + (f32(k) - 0.5) * h >= t_resume) {
        k -= 1u;
    }
    while (k < n && t0 + (f32(k) + 0.5) * h < t_resume) {
        k += 1u;
    }
    if (k >= n) {
        return;
    }
    var pieces = 0u;
    if (!folded && c0.w >= 0.0 && c6.w >= 0.0) {
        let err = max(max3(abs(v3 - mix(v0, v1, 1.0 / 3.0))), max3(abs(v6 - mix(v0, v1, 2.0 / 3.0))));
        pieces = u32(clamp(ceil(sqrt(err / object.params.z)), 1.0, f32(MAX_PIECES)));
    }
    let s = held;
    held += 1u;
    iv_prism[s] = index;
    iv_t0[s] = t0;
    iv_t1[s] = t1;
    iv_h[s] = h;
    iv_n[s] = n;
    iv_k[s] = k;
    iv_next[s] = t0 + (f32(k) + 0.5) * h;
    iv_pieces[s] = pieces;
    iv_c1[s] = c1;
    iv_level[s] = level;
    var j = 0u;
    if (pieces > 1u) {
        j = min(u32((iv_next[s] - t0) / (t1 - t0) * f32(pieces)), pieces - 1u);
    }
    // The piece a sample falls in is found by `t >= tb` as the march goes: agree with it, moving
    // on while the next sample is past the piece's end, else back while it is before its start
    // (one call of `set_piece`, for the size of the kernel).
    var next = false;
    var forward = false;
    loop {
        set_piece(s, j, c0, next);
        if (iv_next[s] >= iv_tb[s] && j + 1u < pieces) {
            j += 1u;
            next = true;
            forward = true;
        } else if (!forward && j > 0u && iv_next[s] < iv_ta[s]) {
            j -= 1u;
            next = false;
        } else {
            break;
        }
    }
}

// The intervals of the ray inside prism `index` (after the near plane) join the held ones; a
// crossing of an opaque base from above ends the ray there.
fn expand_prism(index: u32) {
    budget -= PRISM_COST;
    var shape = load_shape(index);
    let object = shell_objects[shell_prisms[index].vertices.w];
    if ((object.resolution.w & 2u) != 0u) {
        let n = cross(shape.bottom[1] - shape.bottom[0], shape.bottom[2] - shape.bottom[0]);
        let tb = ray_triangle(ray, shape.bottom[0], shape.bottom[1], shape.bottom[2]);
        if (dot(ray, n) < 0.0 && tb > t_near) {
            t_opaque = min(t_opaque, tb);
        }
    }
    let band = shell_bands[index];
    if (band.x > band.y) {
        return;
    }
    crossings(&shape, band);
    let base = slot * MAX_CROSSINGS;
    // The ray starts inside only if the near point is in the corners' box.
    let near = ray * t_near;
    var lo = min(min(shape.bottom[0], shape.bottom[1]), min(shape.bottom[2], min(min(shape.top[0], shape.top[1]), shape.top[2])));
    var hi = max(max(shape.bottom[0], shape.bottom[1]), max(shape.bottom[2], max(max(shape.top[0], shape.top[1]), shape.top[2])));
    let may_start_inside = all(near >= lo) && all(near <= hi);
    var t0 = t_near;
    var c0 = vec4<f32>(0.0, 0.0, 0.0, -1.0);
    var at_near = true;
    for (var k = 0u; k < crossing_count; k++) {
        let t1 = crossing_t[base + k];
        if (t1 <= t0) {
            continue;
        }
        // Between consecutive crossings the ray is wholly inside or outside: test a third in;
        // also wholly below, in or above the band. At the near plane, the start is mapped too
        // (one call of the solver for both).
        var c3 = vec4<f32>(0.0, 0.0, 0.0, -1.0);
        for (var e = 0u; e < 2u; e++) {
            let third = e == 0u;
            if (select(at_near && c3.w >= band.x && c3.w <= band.y, !at_near || may_start_inside, third)) {
                let c = prism_inverse(ray * select(t0, mix(t0, t1, 1.0 / 3.0), third), &shape);
                if (third) {
                    c3 = c;
                } else {
                    c0 = c;
                }
            }
        }
        if (c3.w >= band.x && c3.w <= band.y) {
            add_interval(index, t0, t1, c0, crossing_c[base + k], c3, &shape);
        }
        t0 = t1;
        c0 = crossing_c[base + k];
        at_near = false;
    }
}
