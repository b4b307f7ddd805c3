// The stack of a BVH walk (bake_mesh_grid.wgsl, bake_point_grid.wgsl, trace_reference.wgsl): node
// indices, depth first. Reads the kernel's `STACK_SIZE`; a full stack drops the children it cannot
// hold.

// The bytes of a `ReferenceNode` (mesh::bvh::flat_bvh) read with integer counts: a count or index
// stored as f32 bits is a denormal, which software rasterisers may flush to zero.
struct BvhNode {
    lo: vec3<f32>,
    // Primitives in the leaf (0: inner node).
    count: u32,
    hi: vec3<f32>,
    // First primitive (leaf) or first child (inner; the second follows it).
    first: u32,
}

struct BvhStack {
    nodes: array<u32, STACK_SIZE>,
    top: u32,
}

// A stack holding `root`, or nothing when the BVH is empty.
fn bvh_stack(root: u32, empty: bool) -> BvhStack {
    var s: BvhStack;
    s.nodes[0] = root;
    s.top = select(1u, 0u, empty);
    return s;
}

// The next node to visit (the stack is not empty).
fn bvh_pop(s: ptr<function, BvhStack>) -> u32 {
    (*s).top -= 1u;
    return (*s).nodes[(*s).top];
}

// Pushes an inner node's children: `next` is visited before `later`.
fn bvh_push(s: ptr<function, BvhStack>, later: u32, next: u32) {
    let top = (*s).top;
    if (top + 2u <= STACK_SIZE) {
        (*s).nodes[top] = later;
        (*s).nodes[top + 1u] = next;
        (*s).top = top + 2u;
    }
}
