// Screen tiles of the Tiles compositor (bin_slices, fill_tiles, composite_tiles). CPU twin:
// src/methods/view_slices/tiles.rs (same names).

// Tiles are TILE_SIZE x TILE_SIZE pixels; a tile's list has one segment per TILE_PLANES planes.
const TILE_SIZE: u32 = 16u;
const TILE_PLANES: u32 = 32u;
// No triangle of this plane covers the pixel (composite_tiles' per-plane slots).
const NO_TRIANGLE: u32 = 0xffffffffu;

// Pixel position (y down, pixel centres at +0.5) of a camera-relative point, and its depth.
fn project_to_pixels(p: vec3<f32>, view_proj: mat4x4<f32>, size: vec2<f32>) -> vec3<f32> {
    let c = view_proj * vec4<f32>(p, 1.0);
    let ndc = c.xyz / c.w;
    return vec3<f32>((ndc.x * 0.5 + 0.5) * size.x, (0.5 - ndc.y * 0.5) * size.y, ndc.z);
}

// Twice the signed area of a projected triangle.
fn tile_triangle_area(t: TileTriangle) -> f32 {
    let a = t.xy01.xy;
    let b = t.xy01.zw;
    let c = t.xy2;
    return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

// Inclusive tile range (x0, y0, x1, y1) whose pixel centres the triangle's bounding box may
// cover; x0 > x1 when it covers none (off screen, degenerate or not finite).
fn tile_range(t: TileTriangle, tiles: vec2<u32>, size: vec2<f32>) -> vec4<u32> {
    let none = vec4<u32>(1u, 1u, 0u, 0u);
    let area = tile_triangle_area(t);
    // Zero area (a degenerate slice or a padding triangle) covers nothing; NaN fails too.
    if (!(abs(area) > 0.0)) {
        return none;
    }
    let lo = min(min(t.xy01.xy, t.xy01.zw), t.xy2) - 0.5;
    let hi = max(max(t.xy01.xy, t.xy01.zw), t.xy2) - 0.5;
    if (!(hi.x >= 0.0 && hi.y >= 0.0 && lo.x <= size.x && lo.y <= size.y)) {
        return none;
    }
    // Pixels whose centres can lie in [lo + 0.5, hi + 0.5], one more on each side for rounding.
    let p0 = vec2<u32>(clamp(floor(lo), vec2<f32>(0.0), size - 1.0));
    let p1 = vec2<u32>(clamp(ceil(hi), vec2<f32>(0.0), size - 1.0));
    return vec4<u32>(p0 / TILE_SIZE, min(p1 / TILE_SIZE, tiles - 1u));
}

// Edge function of a -> b at p ((b - a) x (p - a), positive on its left in y-down pixels),
// computed with the endpoints in a canonical order so that the two triangles sharing an edge get
// exactly opposite values. x: the value; y: +1 when its positive side owns pixel centres on the
// edge by the rasteriser's top-left rule (the side's inward normal points right, or straight
// down for a horizontal edge), else -1.
fn tile_edge(a: vec2<f32>, b: vec2<f32>, p: vec2<f32>) -> vec2<f32> {
    let swap = a.y > b.y || (a.y == b.y && a.x > b.x);
    let lo = select(a, b, swap);
    let hi = select(b, a, swap);
    let e = (hi.x - lo.x) * (p.y - lo.y) - (hi.y - lo.y) * (p.x - lo.x);
    // The value's gradient in p: the positive side's inward normal.
    let g = vec2<f32>(a.y - b.y, b.x - a.x);
    let owns = g.x > 0.0 || (g.x == 0.0 && g.y > 0.0);
    return vec2<f32>(select(e, -e, swap), select(-1.0, 1.0, owns));
}

// Whether an edge (value and tie owner from tile_edge) lets p in, for a triangle of orientation
// `orient` (+1 or -1, the side its inside lies on): strictly inside, or on the edge when the
// inside owns it, so a pixel centre on an edge shared by two triangles is covered by exactly one,
// and the same one as the rasteriser's.
fn tile_edge_inside(e: vec2<f32>, orient: f32) -> bool {
    return e.x * orient > 0.0 || (e.x == 0.0 && orient * e.y > 0.0);
}

// Barycentrics of pixel centre p in the triangle, or a negative x when p is not covered.
// Screen-linear barycentrics are the perspective-correct ones: a slice lies on one view plane.
fn tile_cover(t: TileTriangle, p: vec2<f32>) -> vec3<f32> {
    let a = t.xy01.xy;
    let b = t.xy01.zw;
    let c = t.xy2;
    let area = tile_triangle_area(t);
    let orient = select(-1.0, 1.0, area > 0.0);
    let e0 = tile_edge(b, c, p);
    let e1 = tile_edge(c, a, p);
    let e2 = tile_edge(a, b, p);
    if (!(abs(area) > 0.0) || !tile_edge_inside(e0, orient) || !tile_edge_inside(e1, orient) || !tile_edge_inside(e2, orient)) {
        return vec3<f32>(-1.0);
    }
    let sum = e0.x + e1.x + e2.x;
    return vec3<f32>(e0.x, e1.x, e2.x) / sum;
}
