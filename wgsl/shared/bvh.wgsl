// The stack of a BVH walk (bake_mesh_grid.wgsl, trace_reference.wgsl): node indices, depth first.
// Reads the kernel's `STACK_SIZE`; a full stack drops the children it cannot hold.

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
