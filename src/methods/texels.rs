//! Scene texels as bake requests: only texels some object draws, each (texel, lighting) once.

use crate::bake::hypertexture::HyperTexel;
use crate::bake::shadow::Shadow;
use crate::bake::volume::VolumeTexel;
use crate::bake::{BakeRequest, BakeSource, Heights, MeshTexel, StackTexels};
use crate::cpu::bake::{pack_shapes, Primitive};
use crate::error::{Error, Result};
use crate::methods::plan::BakePlan;
use crate::methods::view::FrameLight;
use crate::scene::{Scene, Shape, TexelSource};
use crate::types::{HeightImageParams, HeightfieldParams};

/// Index of the bake for `texel` with the given lighting, added if new; `time`: the frame's
/// (animated hypertextures are baked at it).
pub(crate) fn bake_index(
    scene: &Scene,
    texel: &str,
    per_pixel: bool,
    light: &FrameLight,
    time: f64,
    bakes: &mut Vec<BakePlan>,
) -> Result<usize> {
    if let Some(i) = bakes.iter().position(|b| b.texel == texel && b.request.per_pixel == per_pixel) {
        return Ok(i);
    }
    let t = scene
        .texels
        .get(texel)
        .ok_or_else(|| Error::Invalid(format!("{}: unknown texel `{texel}`", scene.path.display())))?;
    let source = match &t.source {
        TexelSource::Implicit { shapes } => {
            BakeSource::Implicit(pack_shapes(&shapes.iter().map(bake_shape).collect::<Vec<_>>()))
        }
        TexelSource::PerlinHeight {
            frequency,
            octaves,
            amplitude,
            base,
            seed,
            color_low,
            color_high,
            opacity,
            darkening,
        } => BakeSource::Heightfield(HeightfieldParams {
            frequency: *frequency,
            octaves: *octaves,
            seed: *seed,
            amplitude: *amplitude,
            base: *base,
            opacity: *opacity,
            darkening: *darkening,
            color_low: rgb0(color_low),
            color_high: rgb0(color_high),
            ..Default::default()
        }),
        TexelSource::ImageHeight {
            image,
            channel,
            amplitude,
            base,
            color_low,
            color_high,
            opacity,
            darkening,
        } => {
            let img = scene.image(&image.value).ok_or_else(|| {
                Error::Invalid(format!(
                    "{}: height image {} was not loaded",
                    scene.path.display(),
                    image.value
                ))
            })?;
            let heights: Vec<f32> =
                img.data.iter().skip(*channel as usize).step_by(img.channels).copied().collect();
            BakeSource::HeightImage(
                HeightImageParams {
                    width: img.width as u32,
                    height: img.height as u32,
                    amplitude: *amplitude,
                    base: *base,
                    opacity: *opacity,
                    darkening: *darkening,
                    color_low: rgb0(color_low),
                    color_high: rgb0(color_high),
                    ..Default::default()
                },
                Heights(std::sync::Arc::new(heights)),
            )
        }
        TexelSource::Slices { dir } => {
            if per_pixel {
                return Err(Error::Invalid(format!(
                    "{}: texel \"{texel}\" is a slice stack with its shading baked in: draw it with `lighting: Baked`",
                    scene.path.display()
                )));
            }
            let s = scene.stack(&dir.value).ok_or_else(|| {
                Error::Invalid(format!("{}: slice stack {} was not loaded", scene.path.display(), dir.value))
            })?;
            BakeSource::Stack(StackTexels(std::sync::Arc::new(s.texels.clone())))
        }
        TexelSource::Sequence { .. } => {
            return Err(Error::Invalid(format!(
                "{}: texel \"{texel}\" is a sequence: bake its frames instead",
                scene.path.display()
            )))
        }
        TexelSource::Mesh { path, bounds, color, opacity, fill } => {
            let (shape, filled) = scene.texel_mesh(&path.value, *fill).ok_or_else(|| {
                Error::Invalid(format!("{}: mesh {} was not loaded", scene.path.display(), path.value))
            })?;
            BakeSource::Mesh(MeshTexel::new(
                shape,
                bounds.lo,
                bounds.hi,
                t.resolution,
                *color,
                *opacity,
                filled,
            ))
        }
        TexelSource::Hypertexture { name, bounds } => {
            let h = scene.hypertextures.get(&name.value).ok_or_else(|| {
                Error::Invalid(format!("{}: unknown hypertexture `{}`", scene.path.display(), name.value))
            })?;
            let bounds = bounds.as_ref().map(|b| (b.lo, b.hi));
            BakeSource::Hypertexture(Box::new(HyperTexel::new(h, bounds, t.resolution, time)))
        }
        TexelSource::Volume { name, bounds } => {
            let missing = || {
                Error::Invalid(format!("{}: volume `{}` was not loaded", scene.path.display(), name.value))
            };
            let v = scene.volumes.get(&name.value).ok_or_else(missing)?;
            let grid = scene.volume(&name.value).ok_or_else(missing)?.clone();
            let bounds = bounds.as_ref().map(|b| (b.lo, b.hi));
            let length = t.opacity_length(&scene.hypertextures);
            BakeSource::Volume(Box::new(VolumeTexel::new(grid, bounds, v.albedo, v.density_scale, length)))
        }
        TexelSource::Constant { color, opacity } => {
            BakeSource::Implicit(pack_shapes(&[(Primitive::Constant, *color, *opacity)]))
        }
    };
    bakes.push(BakePlan {
        texel: texel.to_string(),
        request: BakeRequest {
            resolution: t.resolution,
            source,
            per_pixel,
            // Baked shading takes the texel axes (s, t, w) as world (x, y, z): exact for a flat
            // z-up base surface; PerPixel lighting is right everywhere.
            light: light.direction,
            ambient: light.ambient,
            derived: Default::default(),
            layers: false,
            shadow: t.shadow.map(|sh| Shadow {
                // The direction towards the light, like `light.direction`.
                toward_light: sh.direction.map_or(light.direction, |d| (-d).as_vec3().to_array()),
                extinction: sh.extinction,
                ambient: sh.ambient,
                bias: sh.bias,
            }),
        },
        opacity_length: t.opacity_length(&scene.hypertextures),
    });
    Ok(bakes.len() - 1)
}

fn rgb0(v: &[f32; 3]) -> [f32; 4] {
    [v[0], v[1], v[2], 0.0]
}

/// A scene shape as the bake kernels take it: (shape, albedo, opacity).
fn bake_shape(s: &Shape) -> (Primitive, [f32; 3], f32) {
    match s {
        Shape::Sphere { center, radius, color, opacity } => {
            (Primitive::Sphere { center: *center, radius: *radius }, *color, *opacity)
        }
        Shape::Torus { center, major, minor, color, opacity } => {
            (Primitive::Torus { center: *center, major: *major, minor: *minor }, *color, *opacity)
        }
        Shape::Ellipsoid { center, radii, color, opacity } => {
            (Primitive::Ellipsoid { center: *center, radii: *radii }, *color, *opacity)
        }
        Shape::Metaballs { balls, threshold, color, opacity } => (
            Primitive::Metaballs {
                balls: balls.iter().map(|b| (b.center, b.radius)).collect(),
                threshold: *threshold,
            },
            *color,
            *opacity,
        ),
    }
}
