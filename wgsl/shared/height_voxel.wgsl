// The voxel of a height-field texel (filled below h(s,t)), shared by bake_heightfield and
// bake_height_image. The including kernel declares `override per_pixel_lighting: bool`.

struct BakedVoxel {
    rgba: vec4<f32>, // premultiplied
    normal: vec3<f32>,
}

// h = (h, dh/ds, dh/dt) at the voxel's column; p the voxel centre in [0,1]^3. `top` is the highest
// possible height: colour runs from color_low at w = 0 to color_high at top, and the albedo darkens
// with depth below the top by `darkening * (top - w) / top`, so grooves read darker (Meyer & Neyret
// 1998, section 3.2: "darkness proportional to the depth").
fn height_voxel(h: vec3<f32>, p: vec3<f32>, voxel_size: f32, opacity: f32, darkening: f32,
                color_low: vec3<f32>, color_high: vec3<f32>, top: f32) -> BakedVoxel {
    // F = w - h(s,t) is negative inside; its gradient (-dh/ds, -dh/dt, 1) is the outward normal and
    // F / |grad F| the distance to the surface to first order.
    let g = vec3<f32>(-h.y, -h.z, 1.0);
    let d = (p.z - h.x) / length(g);
    var out: BakedVoxel;
    out.normal = gradient_normal(g);
    let coverage = clamp(0.5 - d / voxel_size, 0.0, 1.0);
    let alpha = clamp(opacity * coverage, 0.0, 1.0);
    let top_safe = max(top, 1.0e-6);
    let depth = clamp((top_safe - p.z) / top_safe, 0.0, 1.0);
    var rgb = mix(color_low, color_high, clamp(p.z / top_safe, 0.0, 1.0)) * clamp(1.0 - darkening * depth, 0.0, 1.0);
    if (!per_pixel_lighting) {
        rgb = shade_lambert(rgb, out.normal, bake_params.light);
    }
    out.rgba = vec4<f32>(clamp(rgb, vec3<f32>(0.0), vec3<f32>(1.0)) * alpha, alpha);
    return out;
}
