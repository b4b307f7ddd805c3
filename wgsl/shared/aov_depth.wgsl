// The depth AOV (graphs/frame.ron's `aovs`): the nearest opaque hit, recorded by the raster passes'
// `fs_depth` entry points and the marching kernels into `aov_opaque_depth`, which the includer declares.

// A sample is opaque when its opacity over the texel's or hypertexture's own `opacity_length`
// (before any step correction) reaches this: the iso-surface an alpha-tested slice draws.
const OPAQUE_ALPHA: f32 = 0.5;

// The pixel's nearest opaque hit so far is kept in `aov_opaque_depth` as the f32 bits of 1 / z
// (z: camera-space depth along the view axis), by atomicMax: 0, the cleared value, is no hit,
// and any order of writers gives the nearest.
fn record_opaque_depth(pixel: u32, z: f32) {
    atomicMax(&aov_opaque_depth[pixel], bitcast<u32>(1.0 / max(z, 1e-30)));
}

// The index of the pixel a fragment at `position` (its @builtin(position)) covers.
fn fragment_pixel(position: vec4<f32>) -> u32 {
    return u32(position.y) * u32(frame.viewport.x) + u32(position.x);
}
