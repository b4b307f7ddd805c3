// Plane/prism intersection of view-aligned slicing (2002 paper, Sec. 3-4, Fig. 4); CPU twin in
// src/methods/view_slices/slice_prisms.rs, which mirrors these functions one to one.
// The including kernel declares `slice_params`, `shell_vertices`, `prisms`, `prism_spheres`,
// `trivial_reject` and `planes_per_thread`. Corners and polygons go by pointer: by-value copies
// of their arrays made these kernels 4x slower on lavapipe.

const EDGE_ABOVE: u32 = 0u; // a: the plane cuts the prolonged normal edge above its top
const EDGE_WITHIN: u32 = 1u; // b: bottom and top lie on different sides of the plane
const EDGE_BELOW: u32 = 2u; // c: the plane cuts it below its bottom

// Below this |s_a - s_b| an edge is treated as lying in the plane (t = 0.5); a normal float, so
// flush-to-zero hardware cannot turn the division into inf or NaN.
const MIN_DENOM: f32 = 1e-30;

// The six corners of one prism with their texel coordinates and the welded ids of its vertices.
struct PrismCorners {
    bottom: array<vec3<f32>, 3>,
    top: array<vec3<f32>, 3>,
    uv: array<vec2<f32>, 3>,
    ids: array<u32, 3>,
    sphere: vec4<f32>,
}

// Up to five vertices in order around the prism, in the sense of its base triangle 0-1-2.
struct SlicePolygon {
    count: u32,
    pos: array<vec3<f32>, 5>,
    uvw: array<vec3<f32>, 5>,
}

struct EdgePoint {
    pos: vec3<f32>,
    uvw: vec3<f32>,
}

fn load_prism(index: u32) -> PrismCorners {
    let p = prisms[index];
    var c: PrismCorners;
    c.ids = array<u32, 3>(p.vertices.x, p.vertices.y, p.vertices.z);
    c.uv = array<vec2<f32>, 3>(p.uv01.xy, p.uv01.zw, p.uv2.xy);
    for (var i = 0u; i < 3u; i++) {
        let v = shell_vertices[c.ids[i]];
        c.bottom[i] = v.bottom.xyz;
        c.top[i] = v.top.xyz;
    }
    c.sphere = prism_spheres[index];
    return c;
}

// Depth of plane k (k = 0 is the back-most).
fn plane_offset(k: u32) -> f32 {
    return slice_params.first_plane - f32(k) * slice_params.spacing;
}

// A zero distance counts as the positive side, everywhere.
fn positive_side(s: f32) -> bool {
    return s >= 0.0;
}

fn crossed(sa: f32, sb: f32) -> bool {
    return positive_side(sa) != positive_side(sb);
}

// The paper's classification of a normal edge, with "above" taken relative to the whole prism's
// rise along its heights (`rising`: the summed s_top - s_bottom is >= 0) instead of the edge's own.
// For every edge whose own rise has the prism's sign this is exactly the paper's rule
// (a iff |s_top| < |s_bottom|); it differs for edges parallel to the plane (the paper calls both
// sides c) and in twisted prisms. Used only to pick the paper's order where the walk is free.
fn classify_oriented(s_bottom: f32, s_top: f32, rising: bool) -> u32 {
    if (crossed(s_bottom, s_top)) {
        return EDGE_WITHIN;
    }
    // Uncrossed: the plane is above the edge if the prism rises towards it from the edge's side.
    if (positive_side(s_bottom) != rising) {
        return EDGE_ABOVE;
    }
    return EDGE_BELOW;
}

// Point where the plane crosses the edge a -> b. Callers pass shared edges in a canonical order
// (smaller welded id first; normal edges bottom -> top), so neighbours get bit-identical points.
// `a * (1 - t) + b * t` returns the endpoints exactly at t = 0 and t = 1.
fn edge_point(pa: vec3<f32>, ua: vec3<f32>, sa: f32, pb: vec3<f32>, ub: vec3<f32>, sb: f32) -> EdgePoint {
    let den = sa - sb;
    var t = 0.5;
    if (abs(den) > MIN_DENOM) {
        t = clamp(sa / den, 0.0, 1.0);
    }
    return EdgePoint(pa * (1.0 - t) + pb * t, ua * (1.0 - t) + ub * t);
}

// Appends a point unless it repeats the previous one (a plane through a vertex yields it from
// up to three edges); at most five are kept (see slice_polygon for why five suffice).
fn poly_push(poly: ptr<function, SlicePolygon>, p: EdgePoint) {
    let n = (*poly).count;
    if (n > 0u && all((*poly).pos[n - 1u] == p.pos)) {
        return;
    }
    if (n < 5u) {
        (*poly).pos[n] = p.pos;
        (*poly).uvw[n] = p.uvw;
        (*poly).count = n + 1u;
    }
}

// Intersection of the upper (top) or lower (bottom) edge between corners i and j.
fn side_edge_point(c: ptr<function, PrismCorners>, s: ptr<function, array<f32, 3>>, upper: bool, i: u32, j: u32) -> EdgePoint {
    var a = i;
    var b = j;
    if ((*c).ids[j] < (*c).ids[i]) {
        a = j;
        b = i;
    }
    let w = select(0.0, 1.0, upper);
    var pa = (*c).bottom[a];
    var pb = (*c).bottom[b];
    if (upper) {
        pa = (*c).top[a];
        pb = (*c).top[b];
    }
    return edge_point(pa, vec3<f32>((*c).uv[a], w), (*s)[a], pb, vec3<f32>((*c).uv[b], w), (*s)[b]);
}

const CAP_NONE: u32 = 0u;
const CAP_TOP: u32 = 1u;
const CAP_BOTTOM: u32 = 2u;

// The slice polygon of a prism and the plane dot(n, x) = d.
//
// The Fig. 4 walk over the side quads [i, j = i+1 mod 3]: normal_i, then the upper and lower
// edges of the quad. Every edge is emitted iff the plane crosses it by sign, which depends only
// on the edge's two endpoints, so neighbours sharing an edge always both emit its point (no
// cracks even where a grazing view makes the heights' slopes disagree and the a/b/c table of
// Fig. 4 no longer matches the crossings). For valid prisms this emits exactly the table's points:
// (a,b): U; (a,c): U,L; (b,a): N,U; (b,b): N; (b,c): N,L; (c,a): L,U; (c,b): L.
//
// Order: a quad with both upper and lower crossed continues on the cap of the previous point
// (after an upper point, U then L), which keeps the cycle closed for any input; the walk starts at
// a crossed normal edge so such a quad always has a previous point, except when no normal edge is
// crossed (a quadrilateral of two such quads) where the paper's order is used: lower first iff
// normal_i is c. Polygons thus run around the prism in the order of its base triangle.
//
// At most 5 points for untwisted prisms: with m normal edges crossed, upper crossings are 0 or 2
// (sign changes around a 3-cycle), lower likewise; m = 3: 3; m = 2: 4; m = 1: 3 or 5; m = 0: 0 or 4.
// Twisted prisms (normal edges crossed in opposite directions) can give 6 or 7: clamped to 5.
//
// Degenerate output: consecutive repeated points are merged (also last vs first; a plane through a
// corner reaches it from up to three edges); fewer than 3 points left give an empty polygon.
// count_slices and emit_slices both use this function.
fn slice_polygon(c: ptr<function, PrismCorners>, n: vec3<f32>, d: f32) -> SlicePolygon {
    var poly: SlicePolygon;
    poly.count = 0u;
    if (trivial_reject && abs(dot(n, (*c).sphere.xyz) - d) > (*c).sphere.w) {
        return poly;
    }
    var sb: array<f32, 3>;
    var st: array<f32, 3>;
    for (var i = 0u; i < 3u; i++) {
        sb[i] = dot(n, (*c).bottom[i]) - d;
        st[i] = dot(n, (*c).top[i]) - d;
    }
    let rising = ((st[0] - sb[0]) + (st[1] - sb[1])) + (st[2] - sb[2]) >= 0.0;
    var start = 0u;
    if (!crossed(sb[0], st[0])) {
        if (crossed(sb[1], st[1])) {
            start = 1u;
        } else if (crossed(sb[2], st[2])) {
            start = 2u;
        }
    }
    var last_cap = CAP_NONE;
    for (var f = 0u; f < 3u; f++) {
        let i = (start + f) % 3u;
        let j = (i + 1u) % 3u;
        if (crossed(sb[i], st[i])) {
            let ub = vec3<f32>((*c).uv[i], 0.0);
            let ut = vec3<f32>((*c).uv[i], 1.0);
            poly_push(&poly, edge_point((*c).bottom[i], ub, sb[i], (*c).top[i], ut, st[i]));
            last_cap = CAP_NONE;
        }
        let upper = crossed(st[i], st[j]);
        let lower = crossed(sb[i], sb[j]);
        var lower_first = last_cap == CAP_BOTTOM;
        if (last_cap == CAP_NONE) {
            lower_first = classify_oriented(sb[i], st[i], rising) == EDGE_BELOW;
        }
        if (lower_first) {
            if (lower) {
                poly_push(&poly, side_edge_point(c, &sb, false, i, j));
                last_cap = CAP_BOTTOM;
            }
            if (upper) {
                poly_push(&poly, side_edge_point(c, &st, true, i, j));
                last_cap = CAP_TOP;
            }
        } else {
            if (upper) {
                poly_push(&poly, side_edge_point(c, &st, true, i, j));
                last_cap = CAP_TOP;
            }
            if (lower) {
                poly_push(&poly, side_edge_point(c, &sb, false, i, j));
                last_cap = CAP_BOTTOM;
            }
        }
    }
    if (poly.count > 1u && all(poly.pos[poly.count - 1u] == poly.pos[0])) {
        poly.count -= 1u;
    }
    if (poly.count < 3u) {
        poly.count = 0u;
    }
    return poly;
}

// The slice polygon of prism corners `c` with plane `k`.
fn slice_prism(c: ptr<function, PrismCorners>, k: u32) -> SlicePolygon {
    return slice_polygon(c, slice_params.plane_normal.xyz, plane_offset(k));
}

// Planes [x, y) a thread visits: its block of `planes_per_thread` planes, narrowed with the
// trivial reject to those near the prism's bounding sphere (widened by one plane: the exact
// per-plane sphere test in `slice_polygon` decides). Looping over planes in a thread, rather than
// a thread per (plane, prism) pair, keeps the work proportional to the planes a prism meets.
fn plane_range(c: ptr<function, PrismCorners>, block: u32) -> vec2<u32> {
    let first = block * planes_per_thread;
    var range = vec2<u32>(first, min(first + planes_per_thread, slice_params.plane_count));
    if (trivial_reject) {
        let centre = dot(slice_params.plane_normal.xyz, (*c).sphere.xyz);
        let lo = (slice_params.first_plane - (centre + (*c).sphere.w)) / slice_params.spacing - 1.0;
        let hi = (slice_params.first_plane - (centre - (*c).sphere.w)) / slice_params.spacing + 2.0;
        let k0 = u32(clamp(floor(lo), 0.0, f32(slice_params.plane_count)));
        let k1 = u32(clamp(ceil(hi), 0.0, f32(slice_params.plane_count)));
        range = vec2<u32>(max(range.x, k0), min(range.y, k1));
    }
    return range;
}

// Triangle-list vertices of a fan over a polygon of `count` points.
fn fan_vertex_count(count: u32) -> u32 {
    return select(0u, 3u * (count - 2u), count >= 3u);
}
