// Exact occlusion of a prism by the opaque base surfaces (CPU twin: `hidden_behind_base` in
// src/methods/axis_slices/twin.rs). Needs `frame: FrameParams` and `base_depth` (R32Float) bound.
//
// Every fragment of a prism's slices lies in the convex hull of its six corners, so its depth is
// at least the nearest corner's, and its pixel centre lies in the prism's projection: inside the
// projected base or top triangle, or the hull of a side's four projected corners. When every such
// pixel already holds a nearer base surface, no fragment of the prism can pass the depth test:
// culling it cannot change the image, at silhouettes included.

// Largest screen rectangle (pixels) tested; larger prisms are drawn.
const MAX_OCCLUSION_PIXELS: i32 = 4096;

// Tolerance of the coverage test (pixels): wider than the rasteriser's sub-pixel snapping.
const COVER_TOLERANCE: f32 = 0.015625;

fn edge_function(a: vec2<f32>, b: vec2<f32>, p: vec2<f32>) -> f32 {
    return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
}

// Whether `p` lies in triangle abc, widened by COVER_TOLERANCE (either orientation; a triangle
// without area covers nothing, as in the rasteriser).
fn in_triangle(a: vec2<f32>, b: vec2<f32>, c: vec2<f32>, p: vec2<f32>) -> bool {
    let area = edge_function(a, b, c);
    if (area == 0.0) {
        return false;
    }
    let s = sign(area);
    return s * edge_function(a, b, p) >= -COVER_TOLERANCE * length(b - a)
        && s * edge_function(b, c, p) >= -COVER_TOLERANCE * length(c - b)
        && s * edge_function(c, a, p) >= -COVER_TOLERANCE * length(a - c);
}

// Whether pixel centre `p` lies in the projection of the prism with projected corners `q`
// (0..3 base, 3..6 top): a side's hull is the union of the four triangles of its corners.
fn in_projection(q: array<vec2<f32>, 6>, p: vec2<f32>) -> bool {
    if (in_triangle(q[0], q[1], q[2], p) || in_triangle(q[3], q[4], q[5], p)) {
        return true;
    }
    for (var i = 0u; i < 3u; i++) {
        let j = (i + 1u) % 3u;
        let a = q[i];
        let b = q[j];
        let c = q[j + 3u];
        let d = q[i + 3u];
        if (in_triangle(a, b, c, p) || in_triangle(a, c, d, p) || in_triangle(a, b, d, p) || in_triangle(b, c, d, p)) {
            return true;
        }
    }
    return false;
}

fn hidden_behind_base(corners: array<vec3<f32>, 6>) -> bool {
    let size = vec2<f32>(frame.viewport.xy);
    var q: array<vec2<f32>, 6>;
    var lo = vec2<f32>(3.4e38);
    var hi = vec2<f32>(-3.4e38);
    var near = 3.4e38;
    for (var i = 0u; i < 6u; i++) {
        let c = frame.view_proj * vec4<f32>(corners[i], 1.0);
        // A corner at or behind the eye: its projection bounds nothing.
        if (c.w <= 0.0) {
            return false;
        }
        let ndc = c.xyz / c.w;
        let px = clamp(vec2<f32>((ndc.x * 0.5 + 0.5) * size.x, (0.5 - ndc.y * 0.5) * size.y), vec2<f32>(-1e7), vec2<f32>(1e7));
        q[i] = px;
        lo = min(lo, px);
        hi = max(hi, px);
        near = min(near, ndc.z);
    }
    // Interpolated fragment depths may round a little below the nearest corner.
    near = near - 1e-6 * (1.0 + abs(near));
    // Pixel centres (x + 0.5) inside [lo, hi], clamped to the target.
    let first = max(vec2<i32>(ceil(lo - 0.5)), vec2<i32>(0));
    let last = min(vec2<i32>(floor(hi - 0.5)), vec2<i32>(size) - vec2<i32>(1));
    if (any(last < first)) {
        // No pixel centre: the prism draws no fragment (or is off screen).
        return true;
    }
    let span = last - first + vec2<i32>(1);
    if (span.x * span.y > MAX_OCCLUSION_PIXELS) {
        return false;
    }
    for (var y = first.y; y <= last.y; y++) {
        for (var x = first.x; x <= last.x; x++) {
            let centre = vec2<f32>(f32(x) + 0.5, f32(y) + 0.5);
            if (in_projection(q, centre) && textureLoad(base_depth, vec2<i32>(x, y), 0).x >= near) {
                return false;
            }
        }
    }
    return true;
}
