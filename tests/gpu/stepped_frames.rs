//! Frames rendered in steps (`Renderer::step`, what the preview does so that a slow frame never
//! blocks its window) are the frames `Renderer::render` makes, bit for bit: the exact Reference
//! (split between its resumable dispatches and into tiles of the image) and ShellMarch, RayMarch hypertextures and
//! volumes, and the slicing methods, with their AOVs.
use crate::common::adapter::{gpu, Expectations};

/// What these tests assume of the adapter: WebGPU's defaults.
const ADAPTER: Expectations = Expectations::DEFAULTS;

use crate::common;

use voltex::render::{Blueprint, MethodKind, RenderOptions, Renderer};

fn bits(frame: &voltex::render::Frame) -> Vec<u32> {
    let mut out: Vec<u32> = frame.image.pixels.iter().flatten().map(|v| v.to_bits()).collect();
    for (_, channel) in &frame.aovs {
        out.extend(channel.iter().map(|v| v.to_bits()));
    }
    out
}

#[test]
fn a_frame_rendered_in_steps_is_the_blocking_frame_bit_for_bit() {
    let ctx = gpu!(ADAPTER);
    let cases = [
        ("scenes/view_slices/torus_egg.ron", Some("Reference")),
        ("scenes/shell_march/sphere_balls.ron", None),
        ("scenes/hypertextures/fig4_holes.ron", None),
        ("scenes/volumes/smoke.ron", None),
        ("scenes/meyer_neyret/pears_on_sphere.ron", None),
        ("scenes/view_slices/torus_egg.ron", None),
    ];
    for (path, method) in cases {
        let scene = voltex::scene::load(&common::root().join(path)).unwrap();
        let opts = RenderOptions {
            method: method.map(|m| MethodKind::named(m).unwrap()),
            aovs: Some(vec!["depth".into(), "transmittance".into()]),
            ..common::sized(48, 40)
        };
        let mut r = Renderer::new(&ctx, Blueprint::new(&scene, &opts).unwrap()).unwrap();
        let blocking = bits(&r.render(&ctx).unwrap());
        for units in [1, 3] {
            let mut steps = r.begin_steps(&ctx);
            let (mut submissions, mut finished) = (0, false);
            while !finished {
                finished = r.step(&ctx, &mut steps, units).unwrap();
                submissions += 1;
            }
            let (done, total) = steps.progress();
            assert_eq!(done, total, "{path}: every unit done");
            // At most `units` a submission; a tiled pass's tiles (the Reference's) one each.
            assert!(
                (total.div_ceil(units)..=total).contains(&(submissions as u64)),
                "{path}: {submissions} submissions"
            );
            let stepped = bits(&r.read_frame(&ctx).unwrap());
            let differ = blocking.iter().zip(&stepped).filter(|(a, b)| a != b).count();
            println!("{path} {method:?}: {total} units, {units} a step: {differ} values differ");
            assert_eq!(differ, 0, "{path}: a frame in steps of {units} differs from the blocking one");
        }
    }
}
