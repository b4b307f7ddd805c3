//! Every struct in wgsl/shared/types.wgsl has the size and field offsets of its Rust twin in
//! src/types.rs (naga computes the WGSL layout).

use std::mem::{offset_of, size_of};

use voltex::types::*;

macro_rules! layout {
    ($t:ty; $($f:ident),*) => {
        (stringify!($t), size_of::<$t>(), vec![$(offset_of!($t, $f)),*])
    };
}

#[test]
fn wgsl_structs_match_rust() {
    let source = std::fs::read_to_string(voltex::project_root().join("wgsl/shared/types.wgsl")).unwrap();
    // A kernel using nothing still gets every struct type when they are used by a dummy global.
    let kernel = voltex::gpu::shader::load_str(std::path::Path::new("types.wgsl"), &source).unwrap();
    let rust = [
        layout!(ShellVertex; bottom, top),
        layout!(Prism; vertices, uv01, uv2),
        layout!(SliceParams; plane_normal, first_plane, spacing, plane_count, prism_count, vertex_capacity),
        layout!(SliceVertex; position, uvw),
        layout!(DrawIndirect; vertex_count, instance_count, first_vertex, first_instance),
        layout!(TileParams; tiles_x, tiles_y, blocks, entry_capacity, width, height, _pad),
        layout!(TileTriangle; e0, e1, e2, tiles, depth, plane, _pad),
        layout!(TileAttributes; at_a, d_x, d_y),
        layout!(FrameParams; view_proj, forward, light_dir, light_color, background, viewport),
        layout!(ObjectParams; base_color, opacity_length, index),
        layout!(BaseVertex; position, normal),
        layout!(VertexFrame; ds, dt),
        layout!(BakeParams; resolution, light),
        layout!(ImplicitShape; kind, first_ball, ball_count, _pad, center, params, color),
        layout!(HeightfieldParams; frequency, octaves, seed, _pad0, amplitude, base, opacity, darkening, color_low, color_high),
        layout!(HeightImageParams; width, height, _pad0, amplitude, base, opacity, darkening, color_low, color_high),
        layout!(ReferenceParams; right, up, counts),
        layout!(ReferenceNode; min, max),
        layout!(ReferencePrism; vertices, uv01, uv2),
        layout!(ReferenceObject; resolution, atlas, params),
        layout!(ReferenceState; color, resume),
        layout!(ShellFilter; mips, levels, bias, occupancy),
        layout!(AxisParams; resolution, criteria, forward, flags),
        layout!(AxisChoice; direction, level, first, count, vertex_count, vertex_offset, reverse, culled),
        layout!(AxisVertex; position, texcoord, normal),
        layout!(AxisBake; resolution, level),
        layout!(ShadowParams; resolution, light, shading),
        layout!(HyperParams; to_local, right, up, bounds_min, bounds_max, object, field, field_center, perturb, kinds, march, budget, grid_min, grid_max, modulation),
        layout!(MeshGridParams; lo, hi, counts),
        layout!(MeshTexelParams; color, extent, mode),
        layout!(HyperNoise; amplitude, frequency, shift, combine, seed, speed, table, rows, scale, tile),
        layout!(TransferFunction; first, count, kind, _pad),
        layout!(TransferPoint; x, y, slope, _pad),
        layout!(MarchState; color, resume),
        layout!(VolumeParams; to_index, right, up, box_lo, box_hi, medium, origin, table, atlas, budget),
        layout!(SegmentParams; from_local, lattice_min, lattice, surface, counts, splatting),
        layout!(Splat; center, normal),
        layout!(LightVolumeParams; origin, u, v, w, to_grid, counts),
        layout!(WorldParams; anchor, voxel, counts, resolution),
    ];
    let mut seen = 0;
    for (_, ty) in kernel.module.types.iter() {
        let naga::TypeInner::Struct { members, span } = &ty.inner else {
            continue;
        };
        let name = ty.name.clone().unwrap_or_default();
        let (_, size, offsets) =
            rust.iter().find(|r| r.0 == name).unwrap_or_else(|| panic!("no Rust twin listed for {name}"));
        assert_eq!(*span as usize, *size, "size of {name}");
        let wgsl: Vec<usize> = members.iter().map(|m| m.offset as usize).take(offsets.len()).collect();
        assert_eq!(&wgsl, offsets, "field offsets of {name}");
        seen += 1;
    }
    assert_eq!(seen, rust.len(), "every listed struct is in types.wgsl");
}

#[test]
fn every_kernel_validates() {
    let root = voltex::project_root().join("wgsl");
    // Kernels live in `wgsl/` and its method folders; `shared/` holds includes.
    let mut paths = Vec::new();
    let mut dirs = vec![root.clone()];
    while let Some(dir) = dirs.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() && !path.ends_with("shared") {
                dirs.push(path);
            } else {
                paths.push(path);
            }
        }
    }
    let mut n = 0;
    for path in paths {
        if path.extension().is_some_and(|e| e == "wgsl") {
            let name = path.strip_prefix(&root).unwrap().to_str().unwrap();
            let k = voltex::gpu::shader::load(&root, name).unwrap_or_else(|e| panic!("{e}"));
            assert!(!k.module.entry_points.is_empty(), "{name} has an entry point");
            let first = std::fs::read_to_string(&path).unwrap();
            assert!(first.starts_with("// "), "{name} starts with a one-line purpose comment");
            n += 1;
        }
    }
    assert!(n >= 30, "found {n} kernels");
}
