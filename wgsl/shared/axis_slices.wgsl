// Meyer & Neyret axis-aligned slicing: per-prism frame, direction choice, slice count criteria,
// slice ranges and layers (CPU twin: src/methods/axis_slices/twin.rs). Directions: 0 = s, 1 = t, 2 = w.
// Needs `axis_params: AxisParams`, `shell_vertices`, `prisms` and `axis_occupancy` bound.

// Most slices of one direction crossing one prism (s, t sets of triangles spanning many tiles).
const MAX_PRISM_SLICES: u32 = 4096u;

struct AxisFrame {
    bottom: array<vec3<f32>, 3>,
    top: array<vec3<f32>, 3>,
    uv: array<vec2<f32>, 3>,
    // Per direction: unit slice-plane normal (xyz) and texel thickness along it (w, one tile).
    axes: array<vec4<f32>, 3>,
    centre: vec3<f32>,
    // False when the uv triangle has no area: only the w set can be used.
    has_uv: bool,
}

fn load_axis_frame(index: u32) -> AxisFrame {
    let p = prisms[index];
    var f: AxisFrame;
    for (var i = 0u; i < 3u; i++) {
        let v = shell_vertices[p.vertices[i]];
        f.bottom[i] = v.bottom.xyz;
        f.top[i] = v.top.xyz;
    }
    f.uv[0] = p.uv01.xy;
    f.uv[1] = p.uv01.zw;
    f.uv[2] = p.uv2.xy;
    // Derivatives of the prism map at the middle cross-section.
    let q0 = 0.5 * (f.bottom[0] + f.top[0]);
    let e1 = 0.5 * (f.bottom[1] + f.top[1]) - q0;
    let e2 = 0.5 * (f.bottom[2] + f.top[2]) - q0;
    let d1 = f.uv[1] - f.uv[0];
    let d2 = f.uv[2] - f.uv[0];
    let det = d1.x * d2.y - d2.x * d1.y;
    let dw = ((f.top[0] - f.bottom[0]) + (f.top[1] - f.bottom[1]) + (f.top[2] - f.bottom[2])) / 3.0;
    f.has_uv = abs(det) > 1e-12;
    var ds = vec3<f32>(0.0);
    var dt = vec3<f32>(0.0);
    if (f.has_uv) {
        ds = (e1 * d2.y - e2 * d1.y) / det;
        dt = (e2 * d1.x - e1 * d2.x) / det;
    }
    f.axes[0] = axis_of(cross(dt, dw), ds);
    f.axes[1] = axis_of(cross(dw, ds), dt);
    f.axes[2] = axis_of(cross(ds, dt), dw);
    var c = vec3<f32>(0.0);
    for (var i = 0u; i < 3u; i++) {
        c += f.bottom[i] + f.top[i];
    }
    f.centre = c / 6.0;
    return f;
}

// Unit normal of a slice plane oriented along `along`, and the texel's thickness along it.
fn axis_of(n: vec3<f32>, along: vec3<f32>) -> vec4<f32> {
    let len = length(n);
    if (len < 1e-20) {
        return vec4<f32>(0.0);
    }
    var u = n / len;
    var l = dot(u, along);
    if (l < 0.0) {
        u = -u;
        l = -l;
    }
    return vec4<f32>(u, l);
}

fn level_count(r: u32) -> u32 {
    return 32u - countLeadingZeros(max(r, 1u));
}

fn level_slices(r: u32, level: u32) -> u32 {
    return (r + (1u << level) - 1u) >> level;
}

// First array layer of `level` in a direction's slice array (levels stored finest first).
fn level_layer(r: u32, level: u32) -> u32 {
    var base = 0u;
    for (var l = 0u; l < level; l++) {
        base += level_slices(r, l);
    }
    return base;
}

// First occupancy word of (direction, level): directions s, t, w one after the other.
fn occupancy_base(direction: u32, level: u32) -> u32 {
    var base = 0u;
    for (var d = 0u; d < direction; d++) {
        let r = axis_params.resolution[d];
        base += level_layer(r, level_count(r));
    }
    return base + level_layer(axis_params.resolution[direction], level);
}

// Index of a slice position in its level (s, t positions wrap across tiles).
fn slice_layer(g: i32, n: u32) -> u32 {
    let m = g % i32(n);
    return u32(select(m, m + i32(n), m < 0));
}

// The quality score (1/c^2 - 1) h^2 of a direction (section 4.2); huge when unusable.
fn direction_score(f: ptr<function, AxisFrame>, d: u32, view: vec3<f32>) -> f32 {
    let axis = (*f).axes[d];
    let c = abs(dot(axis.xyz, view));
    if (c < 1e-6 || axis.w <= 0.0 || (d < 2u && !(*f).has_uv)) {
        return 3.0e38;
    }
    let h = axis.w / f32(axis_params.resolution[d]);
    return (1.0 / (c * c) - 1.0) * h * h;
}

// The eye's texture coordinate (s, t or w) in the prism's frame: positions are camera-relative,
// so the eye is the origin, and the coordinate grows by 1 over the axis' thickness from the
// centre (s, t: the mean corner uv; w: 1/2). A huge negative value for an unusable direction.
fn eye_coordinate(f: ptr<function, AxisFrame>, d: u32) -> f32 {
    let axis = (*f).axes[d];
    if (axis.w <= 0.0 || (d < 2u && !(*f).has_uv)) {
        return -3.0e38;
    }
    var mid = 0.5;
    if (d < 2u) {
        mid = ((*f).uv[0][d] + (*f).uv[1][d] + (*f).uv[2][d]) / 3.0;
    }
    return mid - dot((*f).centre, axis.xyz) / axis.w;
}

// The eye inside the shell (the host's test, forward.w) and within this prism's height range:
// rays from the eye run inside the layer and may leave it through its top or bottom before
// reaching a coarse slab's one slice, so the criteria (made for an eye outside) do not apply.
fn eye_in_layer(f: ptr<function, AxisFrame>) -> bool {
    let w = eye_coordinate(f, 2u);
    return axis_params.forward.w != 0.0 && w >= 0.0 && w <= 1.0;
}

// The eye in the prism's box of texture coordinates widened by one finest slice: the direction
// from the eye to the centre says nothing of the rays through it, the camera's forward does.
fn eye_near(f: ptr<function, AxisFrame>) -> bool {
    for (var d = 0u; d < 2u; d++) {
        var lo = (*f).uv[0][d];
        var hi = lo;
        for (var i = 1u; i < 3u; i++) {
            lo = min(lo, (*f).uv[i][d]);
            hi = max(hi, (*f).uv[i][d]);
        }
        let margin = 1.0 / f32(axis_params.resolution[d]);
        let e = eye_coordinate(f, d);
        if (e < lo - margin || e > hi + margin) {
            return false;
        }
    }
    return true;
}

// Direction, level and slice range of a prism (vertex_count and offset filled by the caller).
fn choose_axis(f: ptr<function, AxisFrame>) -> AxisChoice {
    let inside = eye_in_layer(f);
    var view = normalize((*f).centre);
    if (inside && eye_near(f)) {
        view = axis_params.forward.xyz;
    }
    var best = 2u;
    var best_score = 3.4e38;
    // w first so that it wins ties, then s, t.
    for (var k = 0u; k < 3u; k++) {
        let d = (k + 2u) % 3u;
        if ((axis_params.flags.x & (1u << d)) == 0u) {
            continue;
        }
        let s = direction_score(f, d, view);
        if (s < best_score) {
            best = d;
            best_score = s;
        }
    }
    let axis = (*f).axes[best];
    let r = axis_params.resolution[best];
    // Criteria (section 4.3) at the prism's centre, the view angle clamped to the maximum.
    let cos_a = clamp(abs(dot(axis.xyz, view)), 0.0, 1.0);
    let a = min(acos(cos_a), axis_params.criteria.z);
    let needed_depth = f32(r) * tan(a) / axis_params.criteria.x;
    let z = max(dot((*f).centre, axis_params.forward.xyz), 1e-6);
    let needed_pixels = axis.w * sin(a) * axis_params.criteria.w / (z * axis_params.criteria.y);
    let needed = clamp(min(needed_depth, needed_pixels), 1.0, f32(r));
    // The coarsest power-of-two level that still has at least `needed` slices.
    // Inside the layer: the finest level (every voxel slice).
    var level = 0u;
    let levels = level_count(r);
    while (!inside && level + 1u < levels && f32(level_slices(r, level + 1u)) >= needed) {
        level++;
    }
    let n = level_slices(r, level);
    var out: AxisChoice;
    out.direction = best;
    out.level = level;
    out.first = 0;
    out.count = n;
    if (best < 2u) {
        var lo = (*f).uv[0][best];
        var hi = lo;
        for (var i = 1u; i < 3u; i++) {
            lo = min(lo, (*f).uv[i][best]);
            hi = max(hi, (*f).uv[i][best]);
        }
        let g_lo = i32(ceil(lo * f32(n) - 0.5));
        let g_hi = i32(floor(hi * f32(n) - 0.5));
        out.first = g_lo;
        out.count = u32(clamp(g_hi - g_lo + 1, 0, i32(MAX_PRISM_SLICES)));
    }
    // Back to front: the far end of the stack first.
    out.reverse = select(0u, 1u, dot(axis.xyz, view) > 0.0);
    out.culled = 0u;
    return out;
}

// The j-th slice position drawn (back to front) of a choice.
fn slice_position(c: AxisChoice, j: u32) -> i32 {
    let k = select(j, c.count - 1u - j, c.reverse == 1u);
    return c.first + i32(k);
}

fn slice_occupied(c: AxisChoice, g: i32) -> bool {
    if (axis_params.flags.w == 0u) {
        return true;
    }
    let n = level_slices(axis_params.resolution[c.direction], c.level);
    return axis_occupancy[occupancy_base(c.direction, c.level) + slice_layer(g, n)] != 0u;
}

// Triangle-list vertices of one slice at texture coordinate x: 3 for a w slice, 6 for a ruled
// quad (0 if the line misses the uv triangle).
fn slice_vertex_count(f: ptr<function, AxisFrame>, c: AxisChoice, x: f32) -> u32 {
    if (c.direction == 2u) {
        return 3u;
    }
    var crossings = 0u;
    for (var e = 0u; e < 3u; e++) {
        let a = (*f).uv[e][c.direction];
        let b = (*f).uv[(e + 1u) % 3u][c.direction];
        if ((a <= x && x < b) || (b <= x && x < a)) {
            crossings++;
        }
    }
    return select(0u, 6u, crossings == 2u);
}

// The eye's position in units of the chosen level's slices (slice g spans [g, g + 1]) when the
// eye is in the prism's layer, else a huge negative value: slices are then drawn farthest from
// the eye first (on both of its sides) and the slab holding the eye is split at the eye.
fn eye_slice(f: ptr<function, AxisFrame>, c: AxisChoice) -> f32 {
    if (!eye_in_layer(f)) {
        return -3.0e38;
    }
    let e = eye_coordinate(f, c.direction);
    if (e < -1.0e30) {
        return e;
    }
    return e * f32(level_slices(axis_params.resolution[c.direction], c.level));
}

// Slab g split at the eye (xe inside it): a ray from the eye sees only the part on its own side,
// so each part is drawn as its own slice at its middle with its own thickness (in slices).
fn splits_at_eye(g: i32, xe: f32) -> bool {
    return xe > f32(g) && xe < f32(g + 1);
}

// The two parts of slab g split at xe: texture coordinates of their middles (x, y) and their
// thicknesses in slices (z, w), for `n` slices per tile.
fn split_slab(g: i32, xe: f32, n: f32) -> vec4<f32> {
    let below = xe - f32(g);
    let above = f32(g + 1) - xe;
    return vec4<f32>((f32(g) + 0.5 * below) / n, (xe + 0.5 * above) / n, below, above);
}
