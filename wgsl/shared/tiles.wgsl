// Screen tiles of the Tiles compositor (bin_slices, fill_tiles, composite_tiles). CPU twin:
// src/methods/view_slices/tiles.rs (same names).

// Tiles are TILE_SIZE x TILE_SIZE pixels; a tile's list has one segment per TILE_PLANES planes.
const TILE_SIZE: u32 = 8u;
const TILE_PLANES: u32 = 32u;
// No triangle of this plane covers the pixel (composite_tiles' per-plane slots).
const NO_TRIANGLE: u32 = 0xffffffffu;

// Pixel position (y down, pixel centres at +0.5) of a camera-relative point, and its depth.
fn project_to_pixels(p: vec3<f32>, view_proj: mat4x4<f32>, size: vec2<f32>) -> vec3<f32> {
    let c = view_proj * vec4<f32>(p, 1.0);
    let ndc = c.xyz / c.w;
    return vec3<f32>((ndc.x * 0.5 + 0.5) * size.x, (0.5 - ndc.y * 0.5) * size.y, ndc.z);
}

// Twice the signed area of the triangle a b c.
fn tile_area(a: vec2<f32>, b: vec2<f32>, c: vec2<f32>) -> f32 {
    return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

// The edge function of a -> b as coefficients (x, y, constant): (b - a) x (p - a), computed from
// the endpoints in a canonical order and then negated if they were swapped, so the two triangles
// sharing an edge get exactly opposite coefficients and values.
fn tile_edge(a: vec2<f32>, b: vec2<f32>) -> vec3<f32> {
    let swap = a.y > b.y || (a.y == b.y && a.x > b.x);
    let lo = select(a, b, swap);
    let hi = select(b, a, swap);
    let n = vec2<f32>(lo.y - hi.y, hi.x - lo.x);
    let e = vec3<f32>(n, -(n.x * lo.x + n.y * lo.y));
    return select(e, -e, swap);
}

// An edge oriented so the triangle's inside is positive, with w = 1 when the inside owns pixel
// centres on the edge by the rasteriser's top-left rule (its inward normal points right, or
// straight down for a horizontal edge), else -1: a centre on an edge shared by two triangles is
// covered by exactly one.
fn tile_oriented_edge(e: vec3<f32>, orient: f32) -> vec4<f32> {
    let n = e * orient;
    let owns = n.x > 0.0 || (n.x == 0.0 && n.y > 0.0);
    return vec4<f32>(n, select(-1.0, 1.0, owns));
}

// A slice triangle (corners in pixels, y down, and the depth of its plane) ready for binning and
// coverage: its oriented edges and its inclusive tile range (x0, y0, x1, y1) of the pixel centres
// its bounding box may hold, x0 > x1 when it covers none (off screen, degenerate or not finite).
fn tile_triangle(a: vec3<f32>, b: vec3<f32>, c: vec3<f32>, plane: u32, tiles: vec2<u32>, size: vec2<f32>) -> TileTriangle {
    let area = tile_area(a.xy, b.xy, c.xy);
    let orient = select(-1.0, 1.0, area > 0.0);
    var t = TileTriangle(
        tile_oriented_edge(tile_edge(b.xy, c.xy), orient),
        tile_oriented_edge(tile_edge(c.xy, a.xy), orient),
        tile_oriented_edge(tile_edge(a.xy, b.xy), orient),
        vec4<u32>(1u, 1u, 0u, 0u),
        (a.z + b.z + c.z) / 3.0,
        plane,
        0u,
        0u,
    );
    let lo = min(min(a.xy, b.xy), c.xy) - 0.5;
    let hi = max(max(a.xy, b.xy), c.xy) - 0.5;
    // Zero area (a degenerate slice or a padding triangle) covers nothing; NaN fails too.
    if (abs(area) > 0.0 && hi.x >= 0.0 && hi.y >= 0.0 && lo.x <= size.x && lo.y <= size.y) {
        // Pixels whose centres can lie in [lo + 0.5, hi + 0.5], one more on each side for rounding.
        let p0 = vec2<u32>(clamp(floor(lo), vec2<f32>(0.0), size - 1.0));
        let p1 = vec2<u32>(clamp(ceil(hi), vec2<f32>(0.0), size - 1.0));
        t.tiles = vec4<u32>(p0 / TILE_SIZE, min(p1 / TILE_SIZE, tiles - 1u));
    }
    return t;
}

// Whether an edge may let in a pixel centre of tile (x, y): its largest value over the tile's
// centres (at a corner of their rectangle) is not below zero, with a margin of 1/1024 pixel
// for rounding.
fn tile_edge_touches(e: vec4<f32>, x: u32, y: u32) -> bool {
    let lo = vec2<f32>(f32(x * TILE_SIZE), f32(y * TILE_SIZE)) + 0.5;
    let hi = lo + f32(TILE_SIZE - 1u);
    let corner = select(lo, hi, e.xy > vec2<f32>(0.0));
    return e.x * corner.x + e.y * corner.y + e.z >= -(abs(e.x) + abs(e.y)) / 1024.0;
}

// Whether the triangle may cover a pixel centre of tile (x, y) (within its tile range): the
// lists skip the tiles a sliver's bounding box meets but the sliver misses.
fn tile_touches(t: TileTriangle, x: u32, y: u32) -> bool {
    return tile_edge_touches(t.e0, x, y) && tile_edge_touches(t.e1, x, y) && tile_edge_touches(t.e2, x, y);
}

fn tile_edge_inside(e: vec4<f32>, p: vec2<f32>) -> f32 {
    let v = e.x * p.x + e.y * p.y + e.z;
    return select(-1.0, v, v > 0.0 || (v == 0.0 && e.w > 0.0));
}

// Barycentrics of pixel centre p in the triangle, or a negative x when p is not covered.
// Screen-linear barycentrics are the perspective-correct ones: a slice lies on one view plane.
fn tile_cover(t: TileTriangle, p: vec2<f32>) -> vec3<f32> {
    let e = vec3<f32>(tile_edge_inside(t.e0, p), tile_edge_inside(t.e1, p), tile_edge_inside(t.e2, p));
    if (min(min(e.x, e.y), e.z) < 0.0) {
        return vec3<f32>(-1.0);
    }
    return e / (e.x + e.y + e.z);
}

// Texel coordinates over a triangle as an affine function of the pixel position, exact for a
// slice (it lies on one view plane, where perspective-correct interpolation is linear): the
// value at corner a and its steps per pixel in x and y.
fn tile_attributes_of(a: vec2<f32>, b: vec2<f32>, c: vec2<f32>, fa: vec3<f32>, fb: vec3<f32>, fc: vec3<f32>) -> TileAttributes {
    let d1 = b - a;
    let d2 = c - a;
    let det = d1.x * d2.y - d1.y * d2.x;
    let inv = select(0.0, 1.0 / det, det != 0.0);
    let f1 = fb - fa;
    let f2 = fc - fa;
    let dx = (f1 * d2.y - f2 * d1.y) * inv;
    let dy = (f2 * d1.x - f1 * d2.x) * inv;
    return TileAttributes(vec4<f32>(fa, a.x), vec4<f32>(dx, a.y), vec4<f32>(dy, 0.0));
}

// The texel coordinates at pixel centre p.
fn tile_attribute(t: TileAttributes, p: vec2<f32>) -> vec3<f32> {
    return t.at_a.xyz + t.d_x.xyz * (p.x - t.at_a.w) + t.d_y.xyz * (p.y - t.d_x.w);
}
