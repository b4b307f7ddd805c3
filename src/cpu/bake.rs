//! CPU twins of the bake kernels (`wgsl/bake/bake_implicit.wgsl`, `wgsl/bake/bake_heightfield.wgsl`) and of `wgsl/shared/{noise,shading}.wgsl`: same names, same
//! f32 math, so tests can compare GPU bakes against these voxel by voxel (up to 8-bit storage).
//! Also the constructors that pack shapes into the GPU structs.

use crate::types::{BakeParams, HeightImageParams, HeightfieldParams, ImplicitShape};

/// `ImplicitShape::kind` values; mirrored as `SHAPE_*` consts in `wgsl/bake/bake_implicit.wgsl`.
pub(crate) const SPHERE: u32 = 0;
pub(crate) const TORUS: u32 = 1;
pub(crate) const ELLIPSOID: u32 = 2;
pub(crate) const METABALLS: u32 = 3;
pub(crate) const CONSTANT: u32 = 4;

/// Distance standing for "infinitely far" (outside) or, negated, "infinitely deep" (constant).
pub const FAR: f32 = 1.0e9;

// ---- small f32 vector helpers (WGSL built-ins) ----

type V3 = [f32; 3];

fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn scale(a: V3, s: f32) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}
fn dot(a: V3, b: V3) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn length(a: V3) -> f32 {
    dot(a, a).sqrt()
}
fn xyz(v: [f32; 4]) -> V3 {
    [v[0], v[1], v[2]]
}

// ---- shared/noise.wgsl ----

/// PCG hash (Jarzynski & Olano 2020).
pub fn pcg_hash(v: u32) -> u32 {
    let state = v.wrapping_mul(747796405).wrapping_add(2891336453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277803737);
    (word >> 22) ^ word
}

/// Unit gradient of lattice point `cell`, wrapped by `period` so the noise tiles.
pub fn lattice_gradient(cell: [i32; 2], period: i32, seed: u32) -> [f32; 2] {
    let c = cell.map(|x| (x.rem_euclid(period)) as u32);
    let h = pcg_hash(c[0].wrapping_add(pcg_hash(c[1].wrapping_add(pcg_hash(seed))))) & 7;
    let d = std::f32::consts::FRAC_1_SQRT_2;
    match h {
        1 => [d, d],
        2 => [0.0, 1.0],
        3 => [-d, d],
        4 => [-1.0, 0.0],
        5 => [-d, -d],
        6 => [0.0, -1.0],
        7 => [d, -d],
        _ => [1.0, 0.0],
    }
}

/// Periodic Perlin noise of `p` (tile units: period 1 in both axes) on a lattice of `period` cells
/// per tile: (value in [-1,1], analytic gradient d value / dp).
pub fn perlin_periodic(p: [f32; 2], period: u32, seed: u32) -> (f32, [f32; 2]) {
    let fp = period as f32;
    let q = [p[0] * fp, p[1] * fp];
    let cell_f = q.map(f32::floor);
    let f = [q[0] - cell_f[0], q[1] - cell_f[1]];
    let cell = cell_f.map(|x| x as i32);
    let per = period as i32;
    let g = |dx: i32, dy: i32| lattice_gradient([cell[0] + dx, cell[1] + dy], per, seed);
    let (g00, g10, g01, g11) = (g(0, 0), g(1, 0), g(0, 1), g(1, 1));
    let d2 = |a: [f32; 2], b: [f32; 2]| a[0] * b[0] + a[1] * b[1];
    let n00 = d2(g00, f);
    let n10 = d2(g10, [f[0] - 1.0, f[1]]);
    let n01 = d2(g01, [f[0], f[1] - 1.0]);
    let n11 = d2(g11, [f[0] - 1.0, f[1] - 1.0]);
    let u = f.map(|f| f * f * f * (f * (f * 6.0 - 15.0) + 10.0));
    let du = f.map(|f| 30.0 * f * f * (f * (f - 2.0) + 1.0));
    let k = n00 - n10 - n01 + n11;
    let value = n00 + u[0] * (n10 - n00) + u[1] * (n01 - n00) + u[0] * u[1] * k;
    let grad = |i: usize, dn: f32| {
        let gk = g00[i] - g10[i] - g01[i] + g11[i];
        g00[i] + u[0] * (g10[i] - g00[i]) + u[1] * (g01[i] - g00[i]) + u[0] * u[1] * gk + du[i] * dn
    };
    let gx = grad(0, n10 - n00 + u[1] * k);
    let gy = grad(1, n01 - n00 + u[0] * k);
    let s = std::f32::consts::SQRT_2;
    (value * s, [gx * fp * s, gy * fp * s])
}

/// Fractal sum of periodic Perlin octaves, normalized to [-1,1]: (value, gradient).
pub fn perlin_fbm_periodic(p: [f32; 2], frequency: u32, octaves: u32, seed: u32) -> (f32, [f32; 2]) {
    let (mut value, mut grad) = (0.0, [0.0, 0.0]);
    let (mut amplitude, mut total) = (1.0f32, 0.0f32);
    let mut period = frequency.max(1);
    for o in 0..octaves.clamp(1, 16) {
        let (v, g) = perlin_periodic(p, period, seed ^ o.wrapping_mul(2654435769));
        value += amplitude * v;
        grad = [grad[0] + amplitude * g[0], grad[1] + amplitude * g[1]];
        total += amplitude;
        amplitude *= 0.5;
        period = period.wrapping_mul(2);
    }
    (value / total, [grad[0] / total, grad[1] / total])
}

// ---- shared/shading.wgsl ----

/// Unit outward normal from a gradient; (0,0,1) where the gradient vanishes.
pub(crate) fn gradient_normal(g: V3) -> V3 {
    let len = length(g);
    if len < 1.0e-6 {
        return [0.0, 0.0, 1.0];
    }
    scale(g, 1.0 / len)
}

/// `albedo * (ambient + (1 - ambient) * max(N.L, 0))`, `light` = (direction to the light, ambient).
pub(crate) fn shade_lambert(albedo: V3, normal: V3, light: [f32; 4]) -> V3 {
    let l = gradient_normal(xyz(light));
    scale(albedo, light[3] + (1.0 - light[3]) * dot(normal, l).max(0.0))
}

/// Lambert plus a white Blinn-Phong highlight; `view` points towards the eye.
pub fn shade_phong(albedo: V3, normal: V3, light: [f32; 4], view: V3, specular: f32, shininess: f32) -> V3 {
    let l = gradient_normal(xyz(light));
    let h = gradient_normal(add(l, gradient_normal(view)));
    let lit = if dot(normal, l) > 0.0 { 1.0 } else { 0.0 };
    let spec = specular * lit * dot(normal, h).max(0.0).powf(shininess);
    add(shade_lambert(albedo, normal, light), [spec; 3])
}

// ---- bake_implicit.wgsl ----

/// Ellipsoid distance bound `k0 (k0 - 1) / k1`: exact on the axes, good near the surface.
pub fn ellipsoid_distance(q: V3, radii: V3) -> f32 {
    let k0 = length([q[0] / radii[0], q[1] / radii[1], q[2] / radii[2]]);
    let k1 =
        length([q[0] / (radii[0] * radii[0]), q[1] / (radii[1] * radii[1]), q[2] / (radii[2] * radii[2])]);
    if k1 < 1.0e-12 {
        return -radii[0].min(radii[1].min(radii[2]));
    }
    k0 * (k0 - 1.0) / k1
}

/// Signed distance of one non-periodic copy of a sphere, torus or ellipsoid centred at the origin.
pub fn local_distance(shape: &ImplicitShape, q: V3) -> f32 {
    let r = shape.params;
    match shape.kind {
        SPHERE => length(q) - r[0],
        TORUS => {
            let a = (q[0] * q[0] + q[1] * q[1]).sqrt() - r[0];
            (a * a + q[2] * q[2]).sqrt() - r[1]
        }
        ELLIPSOID => ellipsoid_distance(q, xyz(r)),
        _ => FAR,
    }
}

/// Metaballs: field sum over balls and their 9 periodic copies; `(threshold - field) / |grad|`.
pub fn metaball_distance(shape: &ImplicitShape, balls: &[[f32; 4]], p: V3) -> f32 {
    let (mut field, mut grad) = (0.0f32, [0.0f32; 3]);
    let n = balls.len() as u32;
    let count = shape.ball_count.min(n - shape.first_ball.min(n));
    for b in 0..count {
        let ball = balls[(shape.first_ball + b) as usize];
        let r2 = ball[3] * ball[3];
        for dy in -1..=1 {
            for dx in -1..=1 {
                let d = sub(sub(p, xyz(ball)), [dx as f32, dy as f32, 0.0]);
                let x = dot(d, d) / r2;
                if x < 1.0 {
                    let a = 1.0 - x;
                    field += a * a * a;
                    grad = add(grad, scale(d, -6.0 * a * a / r2));
                }
            }
        }
    }
    (shape.params[0] - field) / length(grad).max(1.0e-6)
}

/// Signed distance with s and t periodic: nearest of the 9 copies (metaballs sum them instead).
pub fn shape_distance(shape: &ImplicitShape, balls: &[[f32; 4]], p: V3) -> f32 {
    match shape.kind {
        CONSTANT => -FAR,
        METABALLS => metaball_distance(shape, balls, p),
        _ => {
            let mut d = FAR;
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let q = sub(sub(p, xyz(shape.center)), [dx as f32, dy as f32, 0.0]);
                    d = d.min(local_distance(shape, q));
                }
            }
            d
        }
    }
}

/// Centre of `voxel` in texel space and the smallest voxel edge.
fn voxel_centre(resolution: [u32; 4], voxel: [u32; 3]) -> (V3, f32) {
    let p = [0, 1, 2].map(|i| (voxel[i] as f32 + 0.5) / resolution[i] as f32);
    let largest = resolution[0].max(resolution[1].max(resolution[2]));
    (p, 1.0 / largest as f32)
}

/// Premultiplied RGBA of a voxel of coverage-antialiased `distance`, plus the shading.
fn finish(
    albedo: V3,
    opacity: f32,
    normal: V3,
    d: f32,
    voxel_size: f32,
    light: [f32; 4],
    per_pixel: bool,
) -> [f32; 4] {
    let coverage = (0.5 - d / voxel_size).clamp(0.0, 1.0);
    let alpha = (opacity * coverage).clamp(0.0, 1.0);
    let rgb = if per_pixel { albedo } else { shade_lambert(albedo, normal, light) };
    let rgb = rgb.map(|c| c.clamp(0.0, 1.0) * alpha);
    [rgb[0], rgb[1], rgb[2], alpha]
}

/// One voxel of `bake_implicit.wgsl`: (premultiplied rgba, outward normal).
pub fn bake_implicit_voxel(
    params: &BakeParams,
    shapes: &[ImplicitShape],
    balls: &[[f32; 4]],
    voxel: [u32; 3],
    per_pixel: bool,
) -> ([f32; 4], [f32; 3]) {
    let (p, voxel_size) = voxel_centre(params.resolution, voxel);
    let count = (params.resolution[3] as usize).min(shapes.len());
    let (mut best, mut best_d) = (0, FAR);
    for (i, shape) in shapes[..count].iter().enumerate() {
        let d = shape_distance(shape, balls, p);
        if d < best_d {
            best_d = d;
            best = i;
        }
    }
    if best_d >= FAR {
        return ([0.0; 4], [0.0, 0.0, 1.0]);
    }
    let shape = &shapes[best];
    let e = 0.5 * voxel_size;
    let axis = |i: usize| {
        let mut o = [0.0; 3];
        o[i] = e;
        shape_distance(shape, balls, add(p, o)) - shape_distance(shape, balls, sub(p, o))
    };
    let normal = gradient_normal([axis(0), axis(1), axis(2)]);
    let rgba = finish(xyz(shape.color), shape.color[3], normal, best_d, voxel_size, params.light, per_pixel);
    (rgba, normal)
}

// ---- bake_heightfield.wgsl ----

/// `(h, dh/ds, dh/dt)` with `h = base + amplitude * (0.5 + 0.5 * fbm)`.
pub fn heightfield_sample(hf: &HeightfieldParams, st: [f32; 2]) -> [f32; 3] {
    let (v, g) = perlin_fbm_periodic(st, hf.frequency, hf.octaves, hf.seed);
    [hf.base + hf.amplitude * (0.5 + 0.5 * v), 0.5 * hf.amplitude * g[0], 0.5 * hf.amplitude * g[1]]
}

/// What `shared/height_voxel.wgsl` takes besides the height sample and the voxel.
pub(crate) struct HeightLook {
    pub(crate) opacity: f32,
    pub(crate) darkening: f32,
    pub(crate) color_low: [f32; 4],
    pub(crate) color_high: [f32; 4],
    /// The highest possible height.
    pub(crate) top: f32,
}

/// `shared/height_voxel.wgsl`: (premultiplied rgba, outward normal) of the voxel at `p` below or
/// above the height sample `h = (h, dh/ds, dh/dt)`.
pub(crate) fn height_voxel(
    params: &BakeParams,
    h: [f32; 3],
    p: V3,
    voxel_size: f32,
    look: &HeightLook,
    per_pixel: bool,
) -> ([f32; 4], [f32; 3]) {
    let g = [-h[1], -h[2], 1.0];
    let d = (p[2] - h[0]) / length(g);
    let normal = gradient_normal(g);
    let top = look.top.max(1.0e-6);
    let f = (p[2] / top).clamp(0.0, 1.0);
    let dark = (1.0 - look.darkening * ((top - p[2]) / top).clamp(0.0, 1.0)).clamp(0.0, 1.0);
    let albedo = [0, 1, 2].map(|i| (look.color_low[i] + (look.color_high[i] - look.color_low[i]) * f) * dark);
    let rgba = finish(albedo, look.opacity, normal, d, voxel_size, params.light, per_pixel);
    (rgba, normal)
}

/// One voxel of `bake_heightfield.wgsl`: (premultiplied rgba, outward normal).
pub fn bake_heightfield_voxel(
    params: &BakeParams,
    hf: &HeightfieldParams,
    voxel: [u32; 3],
    per_pixel: bool,
) -> ([f32; 4], [f32; 3]) {
    let (p, voxel_size) = voxel_centre(params.resolution, voxel);
    let look = HeightLook {
        opacity: hf.opacity,
        darkening: hf.darkening,
        color_low: hf.color_low,
        color_high: hf.color_high,
        top: hf.base + hf.amplitude,
    };
    height_voxel(params, heightfield_sample(hf, [p[0], p[1]]), p, voxel_size, &look, per_pixel)
}

// ---- bake_height_image.wgsl ----

/// Bilinear height of the image with wrapping; pixel centres at (i + 0.5) / size, t = 0 the bottom
/// row (as `HeightImage::sample`, in f32 as the kernel does it).
fn image_height(hi: &HeightImageParams, heights: &[f32], st: [f32; 2]) -> f32 {
    let (w, h) = (hi.width as i32, hi.height as i32);
    let pixel = |x: i32, y: i32| heights[(y.rem_euclid(h) * w + x.rem_euclid(w)) as usize];
    let x = st[0] * w as f32 - 0.5;
    let y = (1.0 - st[1]) * h as f32 - 0.5;
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let (xi, yi) = (x0 as i32, y0 as i32);
    let mix = |a: f32, b: f32, t: f32| a * (1.0 - t) + b * t;
    let top = mix(pixel(xi, yi), pixel(xi + 1, yi), fx);
    let bottom = mix(pixel(xi, yi + 1), pixel(xi + 1, yi + 1), fx);
    mix(top, bottom, fy)
}

/// `(h, dh/ds, dh/dt)` with `h = base + amplitude * image(s, t)`, the slopes by central
/// differences one pixel apart.
pub(crate) fn height_image_sample(hi: &HeightImageParams, heights: &[f32], st: [f32; 2]) -> [f32; 3] {
    let e = [1.0 / hi.width as f32, 1.0 / hi.height as f32];
    let at = |ds: f32, dt: f32| image_height(hi, heights, [st[0] + ds, st[1] + dt]);
    let ds = (at(e[0], 0.0) - at(-e[0], 0.0)) / (2.0 * e[0]);
    let dt = (at(0.0, e[1]) - at(0.0, -e[1])) / (2.0 * e[1]);
    let a = hi.amplitude;
    [hi.base + a * at(0.0, 0.0), a * ds, a * dt]
}

/// One voxel of `bake_height_image.wgsl`: (premultiplied rgba, outward normal).
pub fn bake_height_image_voxel(
    params: &BakeParams,
    hi: &HeightImageParams,
    heights: &[f32],
    voxel: [u32; 3],
    per_pixel: bool,
) -> ([f32; 4], [f32; 3]) {
    let (p, voxel_size) = voxel_centre(params.resolution, voxel);
    let look = HeightLook {
        opacity: hi.opacity,
        darkening: hi.darkening,
        color_low: hi.color_low,
        color_high: hi.color_high,
        top: hi.base + hi.amplitude,
    };
    height_voxel(params, height_image_sample(hi, heights, [p[0], p[1]]), p, voxel_size, &look, per_pixel)
}

// ---- volumes ----

/// A CPU RGBA volume, x fastest: texel (x,y,z) at `x + X * (y + Y * z)`.
#[derive(Clone, Debug, PartialEq)]
pub struct TexelVoxels {
    pub(crate) size: [u32; 3],
    pub(crate) texels: Vec<[f32; 4]>,
}

impl TexelVoxels {
    /// Index of voxel `v` in `texels`.
    pub fn index(&self, v: [u32; 3]) -> usize {
        (v[0] + self.size[0] * (v[1] + self.size[1] * v[2])) as usize
    }
    /// The RGBA of voxel `v`.
    pub fn get(&self, v: [u32; 3]) -> [f32; 4] {
        self.texels[self.index(v)]
    }
    /// Fills a volume of `size` from a per-voxel function.
    pub fn from_fn(size: [u32; 3], mut f: impl FnMut([u32; 3]) -> [f32; 4]) -> TexelVoxels {
        let mut texels = Vec::with_capacity((size[0] * size[1] * size[2]) as usize);
        for z in 0..size[2] {
            for y in 0..size[1] {
                for x in 0..size[0] {
                    texels.push(f([x, y, z]));
                }
            }
        }
        TexelVoxels { size, texels }
    }
}

/// Every voxel of a bake kernel's dispatch (x fastest), from its one-voxel twin:
/// (rgba, normals with w = 0).
pub fn bake_volume(
    params: &BakeParams,
    mut voxel: impl FnMut([u32; 3]) -> ([f32; 4], [f32; 3]),
) -> (TexelVoxels, TexelVoxels) {
    let size = xyz_u(params.resolution);
    let mut normals = Vec::new();
    let rgba = TexelVoxels::from_fn(size, |v| {
        let (c, n) = voxel(v);
        normals.push([n[0], n[1], n[2], 0.0]);
        c
    });
    (rgba, TexelVoxels { size, texels: normals })
}

/// Twin of `bake_implicit.wgsl`: the whole volume (rgba, normals with w = 0).
pub fn bake_implicit(
    params: &BakeParams,
    packed: &PackedShapes,
    per_pixel: bool,
) -> (TexelVoxels, TexelVoxels) {
    bake_volume(params, |v| bake_implicit_voxel(params, &packed.shapes, &packed.balls, v, per_pixel))
}

/// Twin of `bake_heightfield.wgsl`: the whole volume (rgba, normals with w = 0).
pub fn bake_heightfield(
    params: &BakeParams,
    hf: &HeightfieldParams,
    per_pixel: bool,
) -> (TexelVoxels, TexelVoxels) {
    bake_volume(params, |v| bake_heightfield_voxel(params, hf, v, per_pixel))
}

/// Twin of `bake_height_image.wgsl`: the whole volume (rgba, normals with w = 0).
pub fn bake_height_image(
    params: &BakeParams,
    hi: &HeightImageParams,
    heights: &[f32],
    per_pixel: bool,
) -> (TexelVoxels, TexelVoxels) {
    bake_volume(params, |v| bake_height_image_voxel(params, hi, heights, v, per_pixel))
}

fn xyz_u(v: [u32; 4]) -> [u32; 3] {
    [v[0], v[1], v[2]]
}

// ---- packing shapes into the GPU structs ----

/// A texel-space implicit shape, as the scene describes it.
#[derive(Clone, Debug, PartialEq)]
pub enum Primitive {
    /// A solid sphere.
    Sphere {
        /// Centre, texel space.
        center: V3,
        /// Radius, texel units.
        radius: f32,
    },
    /// Axis along w.
    Torus {
        /// Centre, texel space.
        center: V3,
        /// Radius of the ring through the tube's centre.
        major: f32,
        /// Radius of the tube.
        minor: f32,
    },
    /// An axis-aligned ellipsoid.
    Ellipsoid {
        /// Centre, texel space.
        center: V3,
        /// Semi-axes along s, t and w.
        radii: V3,
    },
    /// Balls as (centre, radius); surface where the field equals `threshold` (in (0,1)).
    Metaballs {
        /// The balls `(centre, radius)`, texel space.
        balls: Vec<(V3, f32)>,
        /// Iso-value of the summed field.
        threshold: f32,
    },
    /// Fills the whole volume (analytic tests).
    Constant,
}

/// Shapes and balls ready for upload. Both vectors hold at least one element (zero-sized storage
/// bindings are invalid); `shape_count` is what goes into `BakeParams::resolution[3]`.
#[derive(Clone, Debug, PartialEq)]
pub struct PackedShapes {
    pub(crate) shapes: Vec<ImplicitShape>,
    pub(crate) balls: Vec<[f32; 4]>,
    pub(crate) shape_count: u32,
}

/// Packs a union of (shape, albedo rgb, opacity) into `ImplicitShape`s and the metaball buffer.
pub fn pack_shapes(shapes: &[(Primitive, V3, f32)]) -> PackedShapes {
    let mut packed = PackedShapes {
        shapes: Vec::with_capacity(shapes.len().max(1)),
        balls: Vec::new(),
        shape_count: shapes.len() as u32,
    };
    for (shape, albedo, opacity) in shapes {
        let mut s =
            ImplicitShape { color: [albedo[0], albedo[1], albedo[2], *opacity], ..Default::default() };
        let c = |v: &V3| [v[0], v[1], v[2], 0.0];
        match shape {
            Primitive::Sphere { center, radius } => {
                s.kind = SPHERE;
                s.center = c(center);
                s.params[0] = *radius;
            }
            Primitive::Torus { center, major, minor } => {
                s.kind = TORUS;
                s.center = c(center);
                s.params[0] = *major;
                s.params[1] = *minor;
            }
            Primitive::Ellipsoid { center, radii } => {
                s.kind = ELLIPSOID;
                s.center = c(center);
                s.params = c(radii);
            }
            Primitive::Metaballs { balls, threshold } => {
                s.kind = METABALLS;
                s.first_ball = packed.balls.len() as u32;
                s.ball_count = balls.len() as u32;
                s.params[0] = *threshold;
                packed.balls.extend(balls.iter().map(|(p, r)| [p[0], p[1], p[2], *r]));
            }
            Primitive::Constant => s.kind = CONSTANT,
        }
        packed.shapes.push(s);
    }
    if packed.shapes.is_empty() {
        packed.shapes.push(ImplicitShape::default());
    }
    if packed.balls.is_empty() {
        packed.balls.push([0.0, 0.0, 0.0, 1.0]);
    }
    packed
}

/// `BakeParams` for a volume of `resolution` voxels, `shape_count` shapes, a light direction
/// (towards the light, texel space) and an ambient term.
pub fn bake_params(resolution: [u32; 3], shape_count: u32, light: V3, ambient: f32) -> BakeParams {
    BakeParams {
        resolution: [resolution[0], resolution[1], resolution[2], shape_count],
        light: [light[0], light[1], light[2], ambient],
    }
}

#[cfg(test)]
#[path = "bake_tests.rs"]
mod tests;
