// A shell prism's corners from the `shell_prisms` and `shell_vertices` the including kernel
// declares (src/mesh/shell.rs makes them): ShellMarch's marcher and the world export.

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
