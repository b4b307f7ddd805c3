// Shows a frame in the preview window: the tonemapped image, the reference, or their difference, with the overlay text.
#include "shared/font.wgsl"
#include "shared/fullscreen.wgsl"

struct PresentParams {
    // 0: image, 1: reference, 2: difference (the image is FLIP's heat map, shown as it is).
    mode: u32,
    // Overlay text: lines of `columns` characters in `text`, drawn `scale` times enlarged.
    lines: u32,
    columns: u32,
    scale: u32,
    image_size: vec2<u32>,
    target_size: vec2<u32>,
    // 1 when the target format encodes sRGB itself.
    srgb_target: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(0) @binding(0) var<uniform> params: PresentParams;
@group(0) @binding(1) var image: texture_2d<f32>;
@group(0) @binding(2) var reference: texture_2d<f32>;
@group(0) @binding(3) var<storage, read> text: array<u32>;
// `FONT`, uploaded: indexed by the character, a const array would be copied into every
// invocation's private memory by llvmpipe (285 words a pixel: ~40 ms a window frame).
@group(0) @binding(4) var<storage, read> font: array<u32>;

@vertex
fn vs_main(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    return fullscreen_position(index);
}

// As src/io/mod.rs `tonemap`: Narkowicz's ACES fit (the sRGB encoding follows).
fn filmic(v: vec3<f32>) -> vec3<f32> {
    let x = max(v, vec3<f32>(0.0));
    return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), vec3<f32>(0.0), vec3<f32>(1.0));
}

fn srgb(v: vec3<f32>) -> vec3<f32> {
    return select(1.055 * pow(v, vec3<f32>(1.0 / 2.4)) - 0.055, 12.92 * v, v <= vec3<f32>(0.0031308));
}

fn overlay(pixel: vec2<u32>) -> vec4<f32> {
    let cell = vec2<u32>(FONT_W, FONT_H) * params.scale;
    let origin = vec2<u32>(8u, 8u);
    if (params.lines == 0u || pixel.x < origin.x || pixel.y < origin.y) {
        return vec4<f32>(0.0);
    }
    let p = pixel - origin;
    let at = p / cell;
    if (at.x >= params.columns || at.y >= params.lines) {
        return vec4<f32>(0.0);
    }
    let code = text[at.y * params.columns + at.x];
    var on = false;
    if (code > 32u && code < 127u) {
        let inner = (p % cell) / params.scale;
        let word = font[(code - 32u) * 3u + inner.y / 4u];
        let row = (word >> (8u * (inner.y % 4u))) & 255u;
        on = ((row >> (7u - inner.x)) & 1u) != 0u;
    }
    return select(vec4<f32>(0.0, 0.0, 0.0, 0.55), vec4<f32>(1.0, 1.0, 1.0, 1.0), on);
}

@fragment
fn fs_main(@builtin(position) position: vec4<f32>) -> @location(0) vec4<f32> {
    let pixel = vec2<u32>(position.xy);
    // The image fits the target, aspect kept, scaled by nearest pixel; grey bars around it.
    let image_size = vec2<f32>(params.image_size);
    let scale = min(f32(params.target_size.x) / image_size.x, f32(params.target_size.y) / image_size.y);
    let origin = 0.5 * (vec2<f32>(params.target_size) - image_size * scale);
    let at = (position.xy - origin) / scale;
    let inside = all(at >= vec2<f32>(0.0)) && all(at < image_size);
    let src = min(vec2<u32>(max(at, vec2<f32>(0.0))), params.image_size - vec2<u32>(1u));
    let a = textureLoad(image, vec2<i32>(src), 0).rgb;
    let b = textureLoad(reference, vec2<i32>(src), 0).rgb;
    var rgb = filmic(a);
    if (params.mode == 1u) {
        rgb = filmic(b);
    } else if (params.mode == 2u) {
        // The difference view: FLIP's heat map (an sRGB texture), shown as it is.
        rgb = a;
    }
    if (!inside) {
        rgb = vec3<f32>(0.02);
    }
    if (params.srgb_target == 0u) {
        rgb = srgb(rgb);
    }
    let o = overlay(pixel);
    var ov = o.rgb;
    // (Only where there is text: a pow per pixel is a cost on software Vulkan.)
    if (params.srgb_target != 0u && o.a > 0.0) {
        ov = pow(ov, vec3<f32>(2.2)); // text and box are given in display values
    }
    return vec4<f32>(mix(rgb, ov, o.a), 1.0);
}
