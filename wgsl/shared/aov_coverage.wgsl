// The coverage AOV (graphs/frame.ron's `aovs`): what the raster passes' `fs_coverage` entry points return.

// Per-object coverage, for premultiplied-over blending into two Rgba32Float targets: objects 0
// to 2 in the first target's R, G, B, objects 3 to 5 in the second's. A carries the alpha
// itself, so every slot behind is attenuated by what is drawn in front, as the colour is.
struct Coverage {
    @location(0) first: vec4<f32>,
    @location(1) second: vec4<f32>,
}

fn coverage_slot(slot: u32, a: f32) -> Coverage {
    let first = vec3<f32>(select(0.0, a, slot == 0u), select(0.0, a, slot == 1u), select(0.0, a, slot == 2u));
    let second = vec3<f32>(select(0.0, a, slot == 3u), select(0.0, a, slot == 4u), select(0.0, a, slot == 5u));
    return Coverage(vec4<f32>(first, a), vec4<f32>(second, a));
}
