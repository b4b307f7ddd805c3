//! Analytic tests of the CPU bake twins and naga checks of the bake kernels.

use super::*;

const RED: V3 = [0.8, 0.2, 0.1];

fn close(a: f32, b: f32, tol: f32) -> bool {
    (a - b).abs() <= tol
}

/// A 16^3 volume with one sphere centred on voxel (8,8,8).
fn sphere_scene(radius: f32, light: V3, ambient: f32) -> (BakeParams, PackedShapes) {
    let c = 8.5 / 16.0;
    let packed = pack_shapes(&[(Primitive::Sphere { center: [c, c, c], radius }, RED, 0.9)]);
    (bake_params([16; 3], packed.shape_count, light, ambient), packed)
}

#[test]
fn sphere_centre_is_opaque_and_shaded() {
    let light = [0.3, -0.4, 0.8];
    let (params, packed) = sphere_scene(0.2, light, 0.25);
    let (rgba, n) = bake_implicit_voxel(&params, &packed.shapes, &packed.balls, [8, 8, 8], false);
    // The gradient vanishes at the centre: N = (0,0,1).
    assert_eq!(n, [0.0, 0.0, 1.0]);
    let shaded = shade_lambert(RED, n, params.light);
    assert!(close(rgba[3], 0.9, 1e-6), "{rgba:?}");
    for i in 0..3 {
        assert!(close(rgba[i], shaded[i] * 0.9, 1e-6), "{rgba:?} {shaded:?}");
    }
    // Unshaded when lighting is per pixel.
    let (rgba, _) = bake_implicit_voxel(&params, &packed.shapes, &packed.balls, [8, 8, 8], true);
    for i in 0..3 {
        assert!(close(rgba[i], RED[i] * 0.9, 1e-6));
    }
}

#[test]
fn sphere_far_outside_is_empty_and_surface_half_covered() {
    let (params, packed) = sphere_scene(3.0 / 16.0, [0.0, 0.0, 1.0], 0.2);
    let (far, _) = bake_implicit_voxel(&params, &packed.shapes, &packed.balls, [0, 0, 0], false);
    assert_eq!(far, [0.0; 4]);
    // Voxel (11,8,8) lies exactly on the surface: coverage 0.5, outward normal +s.
    let (rgba, n) = bake_implicit_voxel(&params, &packed.shapes, &packed.balls, [11, 8, 8], false);
    assert!(close(rgba[3], 0.9 * 0.5, 1e-4), "{rgba:?}");
    assert!(close(n[0], 1.0, 1e-3), "{n:?}");
    // One voxel further in is fully covered, one further out empty.
    let (inner, _) = bake_implicit_voxel(&params, &packed.shapes, &packed.balls, [10, 8, 8], false);
    let (outer, _) = bake_implicit_voxel(&params, &packed.shapes, &packed.balls, [12, 8, 8], false);
    assert!(close(inner[3], 0.9, 1e-6) && outer[3] == 0.0);
}

#[test]
fn sphere_wraps_across_the_s_seam() {
    // Sphere at s = 0.99, radius 0.05: voxel s = 0.01 (i = 0 of 50) is 0.02 away through the seam,
    // mirroring voxel s = 0.97 (i = 48) on the near side.
    let packed = pack_shapes(&[(Primitive::Sphere { center: [0.99, 0.51, 0.51], radius: 0.05 }, RED, 1.0)]);
    let params = bake_params([50; 3], 1, [0.0, 0.0, 1.0], 1.0);
    let (a, na) = bake_implicit_voxel(&params, &packed.shapes, &packed.balls, [0, 25, 25], false);
    let (b, nb) = bake_implicit_voxel(&params, &packed.shapes, &packed.balls, [48, 25, 25], false);
    assert!(a[3] > 0.99, "{a:?}");
    for i in 0..4 {
        assert!(close(a[i], b[i], 1e-5), "{a:?} {b:?}");
    }
    // Normals mirror in s: +s beyond the seam, -s before it.
    assert!(na[0] > 0.9 && nb[0] < -0.9, "{na:?} {nb:?}");
}

#[test]
fn torus_ellipsoid_metaballs_distances() {
    let packed = pack_shapes(&[
        (Primitive::Torus { center: [0.5, 0.5, 0.5], major: 0.3, minor: 0.1 }, RED, 1.0),
        (Primitive::Ellipsoid { center: [0.5, 0.5, 0.5], radii: [0.2, 0.1, 0.05] }, RED, 1.0),
        (Primitive::Metaballs { balls: vec![([0.5, 0.5, 0.5], 0.2)], threshold: 0.5 }, RED, 1.0),
    ]);
    let [torus, ellipsoid, meta] = [0, 1, 2].map(|i| packed.shapes[i]);
    let balls = &packed.balls;
    // Torus: tube centre at distance -minor, ring centre at major - minor.
    assert!(close(shape_distance(&torus, balls, [0.8, 0.5, 0.5]), -0.1, 1e-6));
    assert!(close(shape_distance(&torus, balls, [0.5, 0.5, 0.5]), 0.2, 1e-6));
    // Ellipsoid: exact along the axes.
    assert!(close(shape_distance(&ellipsoid, balls, [0.8, 0.5, 0.5]), 0.1, 1e-5));
    assert!(close(shape_distance(&ellipsoid, balls, [0.5, 0.5, 0.6]), 0.05, 1e-5));
    assert!(shape_distance(&ellipsoid, balls, [0.5, 0.5, 0.5]) < 0.0);
    // Metaballs: one ball, surface where (1 - x)^3 = 0.5 with x = (d/r)^2.
    let d_surf = 0.2 * (1.0 - 0.5f32.cbrt()).sqrt();
    let at = |d: f32| shape_distance(&meta, balls, [0.5 + d, 0.5, 0.5]);
    assert!(close(at(d_surf), 0.0, 1e-5), "{}", at(d_surf));
    assert!(at(d_surf - 0.01) < 0.0 && at(d_surf + 0.01) > 0.0);
    assert!(close(at(d_surf + 0.005), 0.005, 1e-3), "{}", at(d_surf + 0.005));
    assert!(at(0.3) > 1.0); // outside the support: no field, far
}

#[test]
fn union_takes_the_nearest_shape() {
    let blue = [0.1, 0.2, 0.9];
    let packed = pack_shapes(&[
        (Primitive::Sphere { center: [0.25, 0.5, 0.5], radius: 0.2 }, RED, 1.0),
        (Primitive::Sphere { center: [0.75, 0.5, 0.5], radius: 0.2 }, blue, 0.5),
    ]);
    let params = bake_params([16; 3], 2, [0.0, 0.0, 1.0], 1.0);
    let (a, _) = bake_implicit_voxel(&params, &packed.shapes, &packed.balls, [4, 8, 8], false);
    let (b, _) = bake_implicit_voxel(&params, &packed.shapes, &packed.balls, [12, 8, 8], false);
    assert!(close(a[0], RED[0], 1e-6) && close(a[3], 1.0, 1e-6), "{a:?}");
    assert!(close(b[2], blue[2] * 0.5, 1e-6) && close(b[3], 0.5, 1e-6), "{b:?}");
    // shape_count limits the union even when the buffer holds more.
    let params = bake_params([16; 3], 1, [0.0, 0.0, 1.0], 1.0);
    let (b, _) = bake_implicit_voxel(&params, &packed.shapes, &packed.balls, [12, 8, 8], false);
    assert_eq!(b, [0.0; 4]);
}

#[test]
fn constant_fills_uniformly() {
    let packed = pack_shapes(&[(Primitive::Constant, [0.5, 0.6, 0.7], 0.4)]);
    let params = bake_params([5, 4, 3], 1, [0.0, 0.0, 1.0], 0.3);
    let (rgba, normals) = bake_implicit(&params, &packed, false);
    assert_eq!(rgba.texels.len(), 60);
    for (c, n) in rgba.texels.iter().zip(&normals.texels) {
        // N = (0,0,1) and the light along it: the albedo itself.
        assert_eq!(*n, [0.0, 0.0, 1.0, 0.0]);
        for i in 0..3 {
            assert!(close(c[i], [0.5, 0.6, 0.7][i] * 0.4, 1e-6), "{c:?}");
        }
        assert!(close(c[3], 0.4, 1e-7));
    }
}

#[test]
fn empty_pack_has_bindable_buffers() {
    let packed = pack_shapes(&[]);
    assert_eq!(packed.shape_count, 0);
    assert_eq!((packed.shapes.len(), packed.balls.len()), (1, 1));
    let params = bake_params([4; 3], 0, [0.0, 0.0, 1.0], 0.5);
    let (c, n) = bake_implicit_voxel(&params, &packed.shapes, &packed.balls, [1, 2, 3], false);
    assert_eq!((c, n), ([0.0; 4], [0.0, 0.0, 1.0]));
}

#[test]
fn perlin_gradient_matches_finite_differences() {
    for (period, seed) in [(1u32, 0u32), (4, 7), (13, 12345)] {
        for k in 0..40 {
            let p = [(k as f32 * 0.1371 + 0.013) % 1.0, (k as f32 * 0.2917 + 0.071) % 1.0];
            let (_, g) = perlin_periodic(p, period, seed);
            // Step of 1/500 lattice cell: truncation (~h^2 u'''/6) and f32 rounding both ~1e-5.
            let h = 0.002 / period as f32;
            let fd = [0, 1].map(|i| {
                let (mut a, mut b) = (p, p);
                a[i] += h;
                b[i] -= h;
                (perlin_periodic(a, period, seed).0 - perlin_periodic(b, period, seed).0) / (2.0 * h)
            });
            let err = ((fd[0] - g[0]).powi(2) + (fd[1] - g[1]).powi(2)).sqrt();
            let norm = (g[0] * g[0] + g[1] * g[1]).sqrt().max(period as f32 * 0.05);
            assert!(err / norm < 1e-3, "p {p:?} period {period}: {g:?} vs {fd:?}");
        }
    }
}

#[test]
fn perlin_is_periodic_and_bounded() {
    for k in 0..50 {
        let p = [k as f32 * 0.0371, k as f32 * 0.0529 - 0.6];
        for (period, seed) in [(3u32, 1u32), (8, 99)] {
            let (v, g) = perlin_periodic(p, period, seed);
            assert!(v.abs() <= 1.0);
            for shift in [[1.0, 0.0], [0.0, 1.0], [-1.0, 2.0]] {
                let (w, h) = perlin_periodic([p[0] + shift[0], p[1] + shift[1]], period, seed);
                assert!(close(v, w, 1e-4), "{v} {w}");
                assert!(close(g[0], h[0], 1e-2 * period as f32) && close(g[1], h[1], 1e-2 * period as f32));
            }
        }
        let (v, _) = perlin_fbm_periodic(p, 2, 5, 3);
        let (w, _) = perlin_fbm_periodic([p[0] + 1.0, p[1] - 1.0], 2, 5, 3);
        assert!(v.abs() <= 1.0 && close(v, w, 1e-4));
    }
    // Vanishes on lattice points, differs between seeds.
    assert_eq!(perlin_periodic([0.25, 0.5], 4, 0).0, 0.0);
    let a = perlin_periodic([0.3, 0.6], 4, 0).0;
    let b = perlin_periodic([0.3, 0.6], 4, 1).0;
    assert!(a != b);
}

#[test]
fn fbm_gradient_matches_finite_differences() {
    let p = [0.3717, 0.8123];
    let (_, g) = perlin_fbm_periodic(p, 3, 4, 11);
    let h = 1e-4;
    let fd = [0, 1].map(|i| {
        let (mut a, mut b) = (p, p);
        a[i] += h;
        b[i] -= h;
        (perlin_fbm_periodic(a, 3, 4, 11).0 - perlin_fbm_periodic(b, 3, 4, 11).0) / (2.0 * h)
    });
    let err = ((fd[0] - g[0]).powi(2) + (fd[1] - g[1]).powi(2)).sqrt();
    assert!(err / (g[0].hypot(g[1])).max(1.0) < 2e-3, "{g:?} {fd:?}");
}

fn heightfield() -> HeightfieldParams {
    HeightfieldParams {
        frequency: 4,
        octaves: 3,
        seed: 42,
        amplitude: 0.4,
        base: 0.2,
        opacity: 0.8,
        color_low: [0.2, 0.3, 0.1, 0.0],
        color_high: [0.9, 0.9, 0.9, 0.0],
        ..Default::default()
    }
}

#[test]
fn heightfield_fills_below_the_surface() {
    let hf = heightfield();
    let params = bake_params([32, 32, 64], 0, [0.0, 0.0, 1.0], 1.0);
    for (i, j) in [(0, 0), (5, 17), (31, 9)] {
        let st = [(i as f32 + 0.5) / 32.0, (j as f32 + 0.5) / 32.0];
        let h = heightfield_sample(&hf, st)[0];
        assert!((0.2..=0.6).contains(&h));
        let (below, n) = bake_heightfield_voxel(&params, &hf, [i, j, 0], false);
        let (above, _) = bake_heightfield_voxel(&params, &hf, [i, j, 63], false);
        assert!(close(below[3], 0.8, 1e-6) && above == [0.0; 4], "{below:?} {above:?}");
        assert!(n[2] > 0.0 && close(length(n), 1.0, 1e-5));
        // Colour by height: the bottom voxel is almost color_low (ambient 1 = unshaded).
        assert!(close(below[0], (0.2 + 0.7 * 0.5 / 64.0 / 0.6) * 0.8, 1e-5), "{below:?}");
        // Periodic: voxel i and the same point one tile over agree.
        let h2 = heightfield_sample(&hf, [st[0] + 1.0, st[1] - 1.0])[0];
        assert!(close(h, h2, 1e-5));
    }
    // The surface voxel column: coverage falls from 1 to 0 across h.
    let mut last = 1.0;
    for k in 0..64 {
        let (c, _) = bake_heightfield_voxel(&params, &hf, [7, 3, k], true);
        assert!(c[3] <= last + 1e-6);
        last = c[3];
    }
}

#[test]
fn heightfield_normal_is_the_analytic_one() {
    let hf = heightfield();
    let params = bake_params([16, 16, 16], 0, [0.0, 0.0, 1.0], 0.0);
    let (_, n) = bake_heightfield_voxel(&params, &hf, [3, 5, 2], true);
    let st = [3.5 / 16.0, 5.5 / 16.0];
    let e = 1e-3;
    let hs = (heightfield_sample(&hf, [st[0] + e, st[1]])[0]
        - heightfield_sample(&hf, [st[0] - e, st[1]])[0])
        / (2.0 * e);
    let ht = (heightfield_sample(&hf, [st[0], st[1] + e])[0]
        - heightfield_sample(&hf, [st[0], st[1] - e])[0])
        / (2.0 * e);
    let want = gradient_normal([-hs, -ht, 1.0]);
    for i in 0..3 {
        assert!(close(n[i], want[i], 2e-3), "{n:?} {want:?}");
    }
}

#[test]
fn shading_with_the_light_along_the_normal_gives_the_albedo() {
    let n = gradient_normal([1.0, 2.0, -0.5]);
    for ambient in [0.0, 0.3, 1.0] {
        let c = shade_lambert(RED, n, [n[0] * 3.0, n[1] * 3.0, n[2] * 3.0, ambient]);
        for i in 0..3 {
            assert!(close(c[i], RED[i], 1e-6));
        }
        // Facing away: ambient only.
        let c = shade_lambert(RED, n, [-n[0], -n[1], -n[2], ambient]);
        assert!(close(c[0], RED[0] * ambient, 1e-6));
    }
    // Phong: the highlight peaks with eye and light along the normal.
    let c = shade_phong(RED, n, [n[0], n[1], n[2], 0.1], n, 0.5, 20.0);
    assert!(close(c[0], RED[0] + 0.5, 1e-5));
    assert_eq!(gradient_normal([0.0; 3]), [0.0, 0.0, 1.0]);
}

/// The bake kernels validate with naga, use the agreed global names and workgroup size, and their
/// shared structs have the Rust layouts.
#[test]
fn bake_kernels_validate_and_match_the_contract() {
    use naga::{AddressSpace, TypeInner};
    let root = crate::project_root().join("wgsl");
    let kernels: [(&str, &[&str]); 3] = [
        ("bake/bake_implicit.wgsl", &["bake_params", "shapes", "balls", "volume", "normals"]),
        ("bake/bake_heightfield.wgsl", &["bake_params", "heightfield", "volume", "normals"]),
        ("bake/bake_height_image.wgsl", &["bake_params", "height_image", "heights", "volume", "normals"]),
    ];
    for (file, globals) in kernels {
        let k = crate::gpu::shader::load(&root, file).unwrap_or_else(|e| panic!("{e}"));
        let m = &k.module;
        assert_eq!(m.entry_points.len(), 1, "{file}");
        assert_eq!(m.entry_points[0].workgroup_size, [4, 4, 4], "{file}");
        let names: Vec<_> = m
            .global_variables
            .iter()
            .filter(|(_, g)| !matches!(g.space, AddressSpace::Private | AddressSpace::WorkGroup))
            .map(|(_, g)| g.name.clone().unwrap_or_default())
            .collect();
        let mut want: Vec<_> = globals.iter().map(|s| s.to_string()).collect();
        let mut got = names.clone();
        want.sort();
        got.sort();
        assert_eq!(got, want, "{file}");
        for (_, g) in m.global_variables.iter() {
            let b = g.binding.as_ref().unwrap();
            assert_eq!(b.group, 0, "{file}");
        }
        if file.starts_with("bake_") {
            let o: Vec<_> = m.overrides.iter().map(|(_, o)| o.name.clone()).collect();
            assert_eq!(o, vec![Some("per_pixel_lighting".to_string())], "{file}");
        }
        // Struct layouts against Rust.
        for (_, ty) in m.types.iter() {
            let TypeInner::Struct { members, span } = &ty.inner else {
                continue;
            };
            let (size, offsets): (usize, Vec<usize>) = match ty.name.as_deref() {
                Some("BakeParams") => (
                    std::mem::size_of::<BakeParams>(),
                    vec![
                        std::mem::offset_of!(BakeParams, resolution),
                        std::mem::offset_of!(BakeParams, light),
                    ],
                ),
                Some("ImplicitShape") => {
                    (std::mem::size_of::<ImplicitShape>(), vec![0, 4, 8, 12, 16, 32, 48])
                }
                Some("HeightfieldParams") => (
                    std::mem::size_of::<HeightfieldParams>(),
                    vec![
                        0,
                        4,
                        8,
                        12,
                        std::mem::offset_of!(HeightfieldParams, amplitude),
                        std::mem::offset_of!(HeightfieldParams, base),
                        std::mem::offset_of!(HeightfieldParams, opacity),
                        std::mem::offset_of!(HeightfieldParams, darkening),
                        std::mem::offset_of!(HeightfieldParams, color_low),
                        std::mem::offset_of!(HeightfieldParams, color_high),
                    ],
                ),
                _ => continue,
            };
            assert_eq!(*span as usize, size, "{:?}", ty.name);
            let got: Vec<usize> = members.iter().map(|m| m.offset as usize).collect();
            assert_eq!(got, offsets, "{:?}", ty.name);
        }
    }
    assert_eq!(std::mem::offset_of!(ImplicitShape, color), 48);
    assert_eq!(std::mem::size_of::<ImplicitShape>(), 64);
}

#[test]
fn height_image_heights_and_darkening() {
    // A 4x2 image, rising along s; row 0 is the top row (t = 1).
    let heights = [0.0, 0.25, 0.5, 0.75, 0.0, 0.25, 0.5, 0.75];
    let hi = HeightImageParams {
        width: 4,
        height: 2,
        amplitude: 0.8,
        base: 0.1,
        opacity: 1.0,
        color_low: [0.5, 0.5, 0.5, 0.0],
        color_high: [0.5, 0.5, 0.5, 0.0],
        ..Default::default()
    };
    // At a pixel centre the height is exact, the slope the central difference one pixel apart.
    let h = height_image_sample(&hi, &heights, [(1.0 + 0.5) / 4.0, 0.5]);
    assert!(
        close(h[0], 0.1 + 0.8 * 0.25, 1e-6) && close(h[1], 0.8 * (0.5 - 0.0) / (2.0 / 4.0), 1e-5),
        "{h:?}"
    );
    assert!(close(h[2], 0.0, 1e-6));
    // Darkening scales the albedo by 1 - darkening * (top - w) / top, in the filled voxels only.
    let params = bake_params([4, 2, 8], 0, [0.0, 0.0, 1.0], 1.0);
    let at = |darkening: f32, k: u32| {
        bake_height_image_voxel(&params, &HeightImageParams { darkening, ..hi }, &heights, [3, 0, k], true).0
    };
    let top = 0.9;
    for k in 0..3 {
        let w = (k as f32 + 0.5) / 8.0;
        let (plain, dark) = (at(0.0, k), at(0.6, k));
        assert!(close(plain[3], 1.0, 1e-6), "voxel {k} is filled");
        assert!(close(dark[0], plain[0] * (1.0 - 0.6 * (top - w) / top), 1e-6), "{k}: {plain:?} {dark:?}");
    }
    assert_eq!(at(0.6, 7), [0.0; 4], "above the surface: empty");
}
