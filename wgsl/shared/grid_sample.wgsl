// The world position of grid sample `id` (bake_mesh_grid.wgsl, bake_point_grid.wgsl): samples
// at the grid's corners and evenly between them, `size` per axis.
fn grid_sample_point(params: MeshGridParams, id: vec3<u32>) -> vec3<f32> {
    let lo = params.lo.xyz;
    return lo + (params.hi.xyz - lo) * (vec3<f32>(id) / vec3<f32>(params.size.xyz - vec3<u32>(1u)));
}
