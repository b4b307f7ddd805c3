// ShellMarch: per-pixel ray casting through the shell, made for speed at a measured error; CPU twin in src/methods/shell_march/march_shell.rs.
//
// Per pixel: one best-first walk of the BVH over prism bounds (nodes taken in order of where the
// ray enters their box), so every sample before the nearest unvisited box is known; the
// intervals of the ray inside each prism, with the exact inverse map where the ray enters and
// leaves (from the crossing itself); between them (b, w), hence (s, t, w), interpolated in pieces
// checked against the exact map at two interior points; the samples of all intervals composited
// in depth order; bricks of the texel without opacity jumped over in whole steps; the ray stopped
// once its transmittance is below `min_transmittance`.
#include "shared/types.wgsl"
#include "shared/prism_map.wgsl"
#include "shared/shading.wgsl"
// Only bvh.wgsl's node layout is used: the walk here is best-first (the heap below), not its stack.
const STACK_SIZE: u32 = 1u;
#include "shared/bvh.wgsl"

// Work per dispatch, in budget units (a sample is one; see the costs below): the pass is
// dispatched `shell_march_dispatches` times and each pixel resumes from `shell_march_state`,
// because lavapipe ends every loop of an invocation after 65535 iterations in all.
override samples_per_dispatch: u32 = 2048u;
override min_transmittance: f32 = 1e-3;
override skip_empty: bool = true;
const NODE_COST: i32 = 4;
const PRISM_COST: i32 = 32;
const PIECE_COST: i32 = 16;
const EXACT_COST: i32 = 6;
// Pending BVH nodes, and intervals held at once (more are dropped and counted).
const HEAP_SIZE: u32 = 64u;
const MAX_ACTIVE: u32 = 16u;
// Most pieces an interval's interpolation is split into; beyond, pieces use the exact map.
const MAX_PIECES: u32 = 8u;
const MAX_SAMPLES: f32 = 1048576.0;
const MAX_ALPHA: f32 = 0.999999;
const FAR: f32 = 3.4e38;
// Raster depth is coarse far from the camera: opaque surfaces from the depth buffer are moved
// back by this relative margin (the objects' own bases are hit exactly).
const DEPTH_SLACK: f32 = 2e-3;

@group(0) @binding(0) var<uniform> frame: FrameParams;
@group(0) @binding(1) var<uniform> shell_params: ReferenceParams;
@group(0) @binding(2) var<storage, read> shell_nodes: array<BvhNode>;
@group(0) @binding(3) var<storage, read> shell_prisms: array<ReferencePrism>;
@group(0) @binding(4) var<storage, read> shell_objects: array<ReferenceObject>;
@group(0) @binding(5) var<storage, read> shell_vertices: array<ShellVertex>;
@group(0) @binding(6) var<storage, read> vertex_frames: array<VertexFrame>;
@group(0) @binding(7) var<storage, read> texel_atlas: array<u32>;
@group(0) @binding(8) var<storage, read> normal_atlas: array<u32>;
// Per object, levels of bricks of 4, 16 and 64 voxels: non-zero where some voxel within one
// voxel of the brick (the trilinear filter's reach from half a voxel outside it) has opacity.
@group(0) @binding(9) var<storage, read> shell_occupancy: array<u32>;
@group(0) @binding(10) var depth: texture_depth_2d;
@group(0) @binding(11) var shell_march_rgba: texture_storage_2d<rgba32float, write>;
@group(0) @binding(12) var<storage, read_write> shell_march_state: array<ReferenceState>;
// Samples taken, samples skipped, intervals or nodes dropped (a full list), pieces mapped exactly.
@group(0) @binding(13) var<storage, read_write> shell_march_counts: array<atomic<u32>>;
@group(0) @binding(14) var<storage, read_write> aov_opaque_depth: array<atomic<u32>>;

#include "shared/aov_depth.wgsl"

var<private> heap_t: array<f32, HEAP_SIZE>;
var<private> heap_node: array<u32, HEAP_SIZE>;
var<private> heap_count: u32;

// The intervals held: span, sample spacing and count, next sample, and the current piece of the
// interpolation (its span and (b, w) at both ends, or `exact`).
var<private> iv_prism: array<u32, MAX_ACTIVE>;
var<private> iv_t0: array<f32, MAX_ACTIVE>;
var<private> iv_t1: array<f32, MAX_ACTIVE>;
var<private> iv_h: array<f32, MAX_ACTIVE>;
var<private> iv_n: array<u32, MAX_ACTIVE>;
var<private> iv_k: array<u32, MAX_ACTIVE>;
var<private> iv_next: array<f32, MAX_ACTIVE>;
var<private> iv_pieces: array<u32, MAX_ACTIVE>;
var<private> iv_piece: array<u32, MAX_ACTIVE>;
var<private> iv_exact: array<bool, MAX_ACTIVE>;
var<private> iv_ta: array<f32, MAX_ACTIVE>;
var<private> iv_tb: array<f32, MAX_ACTIVE>;
var<private> iv_ca: array<vec4<f32>, MAX_ACTIVE>;
var<private> iv_cb: array<vec4<f32>, MAX_ACTIVE>;
var<private> iv_c1: array<vec4<f32>, MAX_ACTIVE>;
var<private> held: u32;

var<private> ray: vec3<f32>;
var<private> t_near: f32;
var<private> t_resume: f32;
var<private> t_opaque: f32;
var<private> budget: i32;
var<private> rgb: vec3<f32>;
var<private> transmittance: f32;
var<private> pixel: u32;
var<private> opaque_found: bool;
var<private> taken: u32;
var<private> skipped: u32;
var<private> dropped: u32;
var<private> exact_pieces: u32;

fn load_shape(index: u32) -> PrismShape {
    let ids = shell_prisms[index].vertices.xyz;
    let a = shell_vertices[ids.x];
    let b = shell_vertices[ids.y];
    let c = shell_vertices[ids.z];
    return PrismShape(
        array<vec3<f32>, 3>(a.bottom.xyz, b.bottom.xyz, c.bottom.xyz),
        array<vec3<f32>, 3>(a.top.xyz, b.top.xyz, c.top.xyz),
        array<u32, 3>(ids.x, ids.y, ids.z),
    );
}

struct Crossings {
    count: u32,
    t: array<f32, 8>,
    // (b0, b1, b2, w) where the ray crosses: the exact inverse map there.
    c: array<vec4<f32>, 8>,
}

fn add_crossing(x: ptr<function, Crossings>, t: f32, c: vec4<f32>) {
    var k = (*x).count;
    while (k > 0u && (*x).t[k - 1u] > t) {
        (*x).t[k] = (*x).t[k - 1u];
        (*x).c[k] = (*x).c[k - 1u];
        k -= 1u;
    }
    (*x).t[k] = t;
    (*x).c[k] = c;
    (*x).count += 1u;
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
fn patch_crossings(i: u32, j: u32, p: ptr<function, PrismShape>, x: ptr<function, Crossings>) {
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
            add_crossing(x, dot(cross(a, b), n) / nn, c);
        }
    }
}

// Every crossing of the ray with the prism's boundary, sorted, with the map's value there.
fn crossings(p: ptr<function, PrismShape>) -> Crossings {
    var x: Crossings;
    x.count = 0u;
    let bottom = triangle_hit((*p).bottom[0], (*p).bottom[1], (*p).bottom[2]);
    if (bottom.x >= 0.0) {
        add_crossing(&x, bottom.x, vec4<f32>(1.0 - bottom.y - bottom.z, bottom.y, bottom.z, 0.0));
    }
    let top = triangle_hit((*p).top[0], (*p).top[1], (*p).top[2]);
    if (top.x >= 0.0) {
        add_crossing(&x, top.x, vec4<f32>(1.0 - top.y - top.z, top.y, top.z, 1.0));
    }
    for (var e = 0u; e < 3u; e++) {
        var i = e;
        var j = (e + 1u) % 3u;
        if ((*p).ids[j] < (*p).ids[i]) {
            i = j;
            j = e;
        }
        patch_crossings(i, j, p, &x);
    }
    return x;
}

// (s, t, w) in voxels of the prism's texel at map value c.
fn voxels(index: u32, c: vec4<f32>) -> vec3<f32> {
    let prism = shell_prisms[index];
    let res = vec3<f32>(shell_objects[prism.vertices.w].resolution.xyz);
    let st = c.x * prism.uv01.xy + c.y * prism.uv01.zw + c.z * prism.uv2.xy;
    return vec3<f32>(st, c.w) * res;
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
        let exact = prism_inverse(ray * mix(ta, tb, f), shape);
        err = max(err, select(FAR, max3(abs(voxels(index, exact) - voxels(index, mix(ca, cb, f)))), exact.w >= 0.0));
    }
    return err;
}

fn sample_t(s: u32, k: u32) -> f32 {
    return iv_t0[s] + (f32(k) + 0.5) * iv_h[s];
}

// Makes piece j the current piece of interval s: its ends mapped exactly (the interval's own
// ends from its crossings), the line between them checked unless it is the whole interval.
fn set_piece(s: u32, j: u32, ca_known: vec4<f32>) {
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
    if (j > 0u) {
        ca = prism_inverse(ray * ta, &shape);
    }
    var cb = iv_c1[s];
    if (j + 1u < m) {
        cb = prism_inverse(ray * tb, &shape);
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
    // Samples: the path through (s, t, w) in voxels over `step`, and at least one per w-voxel.
    let path = max3(abs(v3 - v0)) + max3(abs(v6 - v3)) + max3(abs(v1 - v6));
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
    var j = 0u;
    if (pieces > 1u) {
        j = min(u32((iv_next[s] - t0) / (t1 - t0) * f32(pieces)), pieces - 1u);
    }
    set_piece(s, j, c0);
    // The piece a sample falls in is found by `t >= tb` as the march goes: agree with it.
    while (iv_next[s] >= iv_tb[s] && iv_piece[s] + 1u < pieces) {
        set_piece(s, iv_piece[s] + 1u, c0);
    }
    while (j > 0u && iv_piece[s] == j && iv_next[s] < iv_ta[s]) {
        j -= 1u;
        set_piece(s, j, c0);
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
    let x = crossings(&shape);
    // The ray starts inside only if the near point is in the corners' box.
    let near = ray * t_near;
    var lo = min(min(shape.bottom[0], shape.bottom[1]), min(shape.bottom[2], min(min(shape.top[0], shape.top[1]), shape.top[2])));
    var hi = max(max(shape.bottom[0], shape.bottom[1]), max(shape.bottom[2], max(max(shape.top[0], shape.top[1]), shape.top[2])));
    let may_start_inside = all(near >= lo) && all(near <= hi);
    var t0 = t_near;
    var c0 = vec4<f32>(0.0, 0.0, 0.0, -1.0);
    var at_near = true;
    for (var k = 0u; k < x.count; k++) {
        let t1 = x.t[k];
        if (t1 <= t0) {
            continue;
        }
        // Between consecutive crossings the ray is wholly inside or outside: test a third in.
        var c3 = vec4<f32>(0.0, 0.0, 0.0, -1.0);
        if (!at_near || may_start_inside) {
            c3 = prism_inverse(ray * mix(t0, t1, 1.0 / 3.0), &shape);
        }
        if (c3.w >= 0.0) {
            if (at_near) {
                c0 = prism_inverse(ray * t0, &shape);
            }
            add_interval(index, t0, t1, c0, x.c[k], c3, &shape);
        }
        t0 = t1;
        c0 = x.c[k];
        at_near = false;
    }
}

fn slab(inv: vec3<f32>, node: BvhNode) -> vec2<f32> {
    let a = node.lo * inv;
    let b = node.hi * inv;
    let lo = min(a, b);
    let hi = max(a, b);
    return vec2<f32>(max(max(lo.x, lo.y), lo.z), min(min(hi.x, hi.y), hi.z));
}

// Queues node n if the ray crosses its box where samples may still be taken (a binary heap on
// where the ray enters the box).
fn push_node(n: u32, inv: vec3<f32>) {
    let span = slab(inv, shell_nodes[n]);
    if (!(span.x <= span.y && span.y >= t_resume && span.x < t_opaque)) {
        return;
    }
    if (heap_count >= HEAP_SIZE) {
        dropped += 1u;
        return;
    }
    var i = heap_count;
    heap_count += 1u;
    while (i > 0u && heap_t[(i - 1u) / 2u] > span.x) {
        heap_t[i] = heap_t[(i - 1u) / 2u];
        heap_node[i] = heap_node[(i - 1u) / 2u];
        i = (i - 1u) / 2u;
    }
    heap_t[i] = span.x;
    heap_node[i] = n;
}

// Where the ray enters the first queued box (FAR: none).
fn heap_front() -> f32 {
    return select(FAR, heap_t[0], heap_count > 0u);
}

// Visits the queued node the ray enters first: a leaf's prisms join, an inner node's children queue.
fn visit(inv: vec3<f32>) {
    budget -= NODE_COST;
    let node = shell_nodes[heap_node[0]];
    heap_count -= 1u;
    let t = heap_t[heap_count];
    let n = heap_node[heap_count];
    var i = 0u;
    loop {
        var c = 2u * i + 1u;
        if (c >= heap_count) {
            break;
        }
        if (c + 1u < heap_count && heap_t[c + 1u] < heap_t[c]) {
            c += 1u;
        }
        if (heap_t[c] >= t) {
            break;
        }
        heap_t[i] = heap_t[c];
        heap_node[i] = heap_node[c];
        i = c;
    }
    heap_t[i] = t;
    heap_node[i] = n;
    if (node.count > 0u) {
        for (var p = 0u; p < node.count; p++) {
            expand_prism(node.first + p);
        }
    } else {
        push_node(node.first, inv);
        push_node(node.first + 1u, inv);
    }
}

// How many samples of interval s from map value c on are empty for certain (at most `most`):
// along the line c + k dc, until it leaves the largest brick around c that holds no opacity.
fn empty_run(s: u32, c: vec4<f32>, dc: vec4<f32>, most: u32) -> u32 {
    let prism = shell_prisms[iv_prism[s]];
    let object = shell_objects[prism.vertices.w];
    let res = object.resolution.xyz;
    let resf = vec3<f32>(res);
    let st = c.x * prism.uv01.xy + c.y * prism.uv01.zw + c.z * prism.uv2.xy;
    let x = vec3<f32>(fract(st), c.w) * resf;
    let dx = vec3<f32>(dc.x * prism.uv01.xy + dc.y * prism.uv01.zw + dc.z * prism.uv2.xy, dc.w) * resf;
    var run = 0.0;
    var offset = object.atlas.w;
    for (var level = 0u; level < 3u; level++) {
        let size = 4u << (2u * level);
        let dims = (res + vec3<u32>(size - 1u)) / size;
        let brick = vec3<u32>(clamp(floor(x / f32(size)), vec3<f32>(0.0), vec3<f32>(dims - vec3<u32>(1u))));
        if (shell_occupancy[offset + (brick.z * dims.y + brick.y) * dims.x + brick.x] != 0u) {
            break;
        }
        // The brick and half a voxel around it (the occupancy covers the filter's reach from
        // there); along w the first and last bricks reach on (sampling clamps there).
        var lo = vec3<f32>(brick * size) - 0.5;
        var hi = vec3<f32>(min((brick + 1u) * size, res)) + 0.5;
        lo.z = select(lo.z, -FAR, brick.z == 0u);
        hi.z = select(hi.z, FAR, brick.z + 1u == dims.z);
        let exit = select(select((lo - x) / dx, (hi - x) / dx, dx > vec3<f32>(0.0)), vec3<f32>(FAR), dx == vec3<f32>(0.0));
        run = floor(min(min(exit.x, exit.y), exit.z)) + 1.0;
        offset += dims.x * dims.y * dims.z;
    }
    return u32(clamp(run, 0.0, f32(most)));
}


struct Axis {
    i0: u32,
    i1: u32,
    f: f32,
}

fn axis(c: f32, n: u32, wrap: bool) -> Axis {
    let x = c * f32(n) - 0.5;
    let fl = floor(x);
    let m = i32(n);
    var i0 = i32(fl);
    var i1 = i0 + 1;
    if (wrap) {
        i0 = ((i0 % m) + m) % m;
        i1 = ((i1 % m) + m) % m;
    } else {
        i0 = clamp(i0, 0, m - 1);
        i1 = clamp(i1, 0, m - 1);
    }
    return Axis(u32(i0), u32(i1), x - fl);
}

// Trilinear filtering as the volume sampler does it (the Reference's atlas): repeat in s and t,
// clamp in w, level 0.
fn sample_volume(object: ReferenceObject, uvw: vec3<f32>, normals: bool) -> vec4<f32> {
    let ax = axis(fract(uvw.x), object.resolution.x, true);
    let ay = axis(fract(uvw.y), object.resolution.y, true);
    let az = axis(uvw.z, object.resolution.z, false);
    let offset = select(object.atlas.x, object.atlas.z, normals);
    var out = vec4<f32>(0.0);
    for (var k = 0u; k < 8u; k++) {
        let x = select(ax.i0, ax.i1, (k & 1u) != 0u);
        let y = select(ay.i0, ay.i1, (k & 2u) != 0u);
        let z = select(az.i0, az.i1, (k & 4u) != 0u);
        let weight = select(1.0 - ax.f, ax.f, (k & 1u) != 0u) * select(1.0 - ay.f, ay.f, (k & 2u) != 0u)
            * select(1.0 - az.f, az.f, (k & 4u) != 0u);
        let at = offset + (z * object.resolution.y + y) * object.atlas.y + x;
        if (normals) {
            out += unpack4x8snorm(normal_atlas[at]) * weight;
        } else {
            out += unpack4x8unorm(texel_atlas[at]) * weight;
        }
    }
    return out;
}

// Per-pixel lighting as the Reference does it (shared/shading.wgsl), at map value c.
fn shade(index: u32, object: ReferenceObject, c: vec4<f32>, uvw: vec3<f32>, albedo: vec3<f32>) -> vec3<f32> {
    let shape = load_shape(index);
    let fa = vertex_frames[shape.ids[0]];
    let fb = vertex_frames[shape.ids[1]];
    let fc = vertex_frames[shape.ids[2]];
    let ds = c.x * fa.ds.xyz + c.y * fb.ds.xyz + c.z * fc.ds.xyz;
    let dt = c.x * fa.dt.xyz + c.y * fb.dt.xyz + c.z * fc.dt.xyz;
    let dw = c.x * (shape.top[0] - shape.bottom[0]) + c.y * (shape.top[1] - shape.bottom[1]) + c.z * (shape.top[2] - shape.bottom[2]);
    let sign_j = select(-1.0, 1.0, dot(ds, cross(dt, dw)) >= 0.0);
    let tn = sample_volume(object, uvw, true).xyz;
    var n = cross(dt, dw) * sign_j * tn.x + cross(dw, ds) * sign_j * tn.y + cross(ds, dt) * sign_j * tn.z;
    n = select(-ray, normalize(n), dot(n, n) > 1e-20);
    return shade_phong(albedo, n, frame.light_dir, -ray, PIXEL_SPECULAR, PIXEL_SHININESS);
}

// Composites one sample of interval s at ray distance t and map value c (w < 0: none).
fn composite(s: u32, t: f32, c: vec4<f32>) {
    taken += 1u;
    if (c.w < 0.0) {
        return;
    }
    let prism = shell_prisms[iv_prism[s]];
    let object = shell_objects[prism.vertices.w];
    let uvw = vec3<f32>(c.x * prism.uv01.xy + c.y * prism.uv01.zw + c.z * prism.uv2.xy, c.w);
    let texel = sample_volume(object, uvw, false);
    if (texel.a >= OPAQUE_ALPHA && !opaque_found) {
        opaque_found = true;
        record_opaque_depth(pixel, t * dot(ray, frame.forward.xyz));
    }
    let alpha = clamp(texel.a, 0.0, MAX_ALPHA);
    if (alpha > 1e-6) {
        var colour = texel.rgb / alpha;
        if ((object.resolution.w & 1u) != 0u) {
            colour = shade(iv_prism[s], object, c, uvw, colour);
        }
        // The step-corrected opacity: 1 - (1 - a)^(h / opacity_length).
        let a = 1.0 - exp(log(1.0 - alpha) * iv_h[s] / object.params.x);
        rgb += colour * a * transmittance;
        transmittance *= 1.0 - a;
    }
}

// Samples of interval s before `limit` (its next one in any case: it is the nearest held), in
// order, until the budget or the ray runs out. The interval's state is kept in registers meanwhile
// (dynamically indexed private arrays are slow on lavapipe).
fn run(s: u32, limit: f32) {
    let t0 = iv_t0[s];
    let h = iv_h[s];
    let n = iv_n[s];
    let m = iv_pieces[s];
    var k = iv_k[s];
    var t = iv_next[s];
    var exact = iv_exact[s];
    var ta = iv_ta[s];
    var tb = iv_tb[s];
    var ca = iv_ca[s];
    var cb = iv_cb[s];
    var first = true;
    while ((first || t < limit) && budget > 0 && transmittance >= min_transmittance) {
        first = false;
        if (t >= tb && iv_piece[s] + 1u < m) {
            while (t >= iv_tb[s] && iv_piece[s] + 1u < m) {
                set_piece(s, iv_piece[s] + 1u, vec4<f32>(0.0));
            }
            exact = iv_exact[s];
            ta = iv_ta[s];
            tb = iv_tb[s];
            ca = iv_ca[s];
            cb = iv_cb[s];
        }
        budget -= 1;
        var c: vec4<f32>;
        var dc = vec4<f32>(0.0);
        var most = 1u;
        if (exact) {
            var shape = load_shape(iv_prism[s]);
            c = prism_inverse(ray * t, &shape);
            budget -= EXACT_COST;
        } else {
            c = mix(ca, cb, (t - ta) / (tb - ta));
            dc = (cb - ca) * (h / (tb - ta));
            // Skips stay in this piece and before `limit`: the first sample at or after either.
            let bound = select(min(tb, limit), limit, iv_piece[s] + 1u >= m);
            var e = u32(clamp(ceil((bound - t0) / h - 0.5), f32(k), f32(n)));
            while (e > k && t0 + (f32(e - 1u) + 0.5) * h >= bound) {
                e -= 1u;
            }
            while (e < n && t0 + (f32(e) + 0.5) * h < bound) {
                e += 1u;
            }
            most = e - k;
        }
        var step = 1u;
        let jump = select(0u, empty_run(s, c, dc, most), skip_empty && c.w >= 0.0);
        if (jump > 0u) {
            skipped += jump;
            step = jump;
        } else {
            composite(s, t, c);
        }
        k += step;
        t = select(FAR, t0 + (f32(k) + 0.5) * h, k < n);
    }
    iv_k[s] = k;
    iv_next[s] = t;
}

// Composites every held sample before `end`, nearest first across intervals.
fn march_to(end: f32) {
    loop {
        budget -= 1;
        var best = MAX_ACTIVE;
        var t_best = end;
        var t_second = end;
        var i = 0u;
        while (i < held) {
            let t = iv_next[i];
            if (t >= FAR || t >= t_opaque) {
                // Done: the last held interval takes its slot.
                held -= 1u;
                copy_interval(held, i);
                continue;
            }
            if (t < t_best) {
                t_second = t_best;
                t_best = t;
                best = i;
            } else if (t < t_second) {
                t_second = t;
            }
            i += 1u;
        }
        if (best == MAX_ACTIVE || budget <= 0 || transmittance < min_transmittance) {
            return;
        }
        run(best, t_second);
    }
}

fn copy_interval(src: u32, dst: u32) {
    iv_prism[dst] = iv_prism[src];
    iv_t0[dst] = iv_t0[src];
    iv_t1[dst] = iv_t1[src];
    iv_h[dst] = iv_h[src];
    iv_n[dst] = iv_n[src];
    iv_k[dst] = iv_k[src];
    iv_next[dst] = iv_next[src];
    iv_pieces[dst] = iv_pieces[src];
    iv_piece[dst] = iv_piece[src];
    iv_exact[dst] = iv_exact[src];
    iv_ta[dst] = iv_ta[src];
    iv_tb[dst] = iv_tb[src];
    iv_ca[dst] = iv_ca[src];
    iv_cb[dst] = iv_cb[src];
    iv_c1[dst] = iv_c1[src];
}

fn next_held() -> f32 {
    var t = FAR;
    for (var i = 0u; i < held; i++) {
        t = min(t, iv_next[i]);
    }
    return t;
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<u32>(frame.viewport.xy);
    if (id.x >= size.x || id.y >= size.y) {
        return;
    }
    pixel = id.y * size.x + id.x;
    let state = shell_march_state[pixel];
    // resume: x the first sample not composited, y 1 once started, z 1 once finished.
    if (state.resume.z != 0.0) {
        return;
    }
    let sx = 2.0 * (f32(id.x) + 0.5) * frame.viewport.z - 1.0;
    let sy = 1.0 - 2.0 * (f32(id.y) + 0.5) * frame.viewport.w;
    let forward = frame.forward.xyz;
    ray = normalize(forward + shell_params.right.xyz * sx + shell_params.up.xyz * sy);
    let cos_d = dot(ray, forward);
    let near = shell_params.right.w;
    let far = shell_params.up.w;
    t_near = near / cos_d;
    rgb = state.color.rgb;
    transmittance = state.color.a;
    t_resume = state.resume.x;
    if (state.resume.y == 0.0) {
        rgb = vec3<f32>(0.0);
        transmittance = 1.0;
        t_resume = t_near;
    }
    // Opaque surfaces already drawn (base surfaces) stop the ray.
    let z = textureLoad(depth, vec2<i32>(id.xy), 0);
    t_opaque = FAR;
    if (z < 1.0) {
        t_opaque = far * near / (far - z * (far - near)) / cos_d * (1.0 + DEPTH_SLACK);
    }
    budget = i32(samples_per_dispatch);
    let inv = 1.0 / ray;
    heap_count = 0u;
    held = 0u;
    if (shell_params.counts.x > 0u) {
        push_node(0u, inv);
    }
    var finished = false;
    loop {
        let front = heap_front();
        let next = next_held();
        if (transmittance < min_transmittance || (front >= t_opaque && next >= t_opaque)) {
            finished = true;
            break;
        }
        if (budget <= 0) {
            break;
        }
        // Nothing unvisited starts before `front`: what is held can be marched up to it.
        if (heap_count > 0u && front <= min(next, t_opaque)) {
            visit(inv);
        } else {
            march_to(min(front, t_opaque));
        }
    }
    t_resume = max(t_resume, min(heap_front(), next_held()));
    shell_march_state[pixel] = ReferenceState(vec4<f32>(rgb, transmittance), vec4<f32>(t_resume, 1.0, select(0.0, 1.0, finished), 0.0));
    textureStore(shell_march_rgba, vec2<i32>(id.xy), vec4<f32>(rgb * frame.light_color.rgb, 1.0 - transmittance));
    if (taken > 0u) {
        atomicAdd(&shell_march_counts[0], taken);
    }
    if (skipped > 0u) {
        atomicAdd(&shell_march_counts[1], skipped);
    }
    if (dropped > 0u) {
        atomicAdd(&shell_march_counts[2], dropped);
    }
    if (exact_pieces > 0u) {
        atomicAdd(&shell_march_counts[3], exact_pieces);
    }
}
