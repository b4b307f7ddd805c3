//! RayMarch as a plug-in (see `methods::plugin`).

use super::knobs::{Adaptive, RayMarch, Shadows};
use crate::error::Result;
use crate::methods::plan::ObjectPlan;
use crate::methods::plugin::{KnobEdit, MethodPlugin};
use crate::methods::{options::RenderOptions, PlanCx};
use super::knobs::Segments;
use super::knobs::{parse_shadows, shadows_name};
use crate::scene::{Lighting, Method, Shading};
use crate::methods::sweep::{unique, SweepPoint, SweepScene, SweepValues};


impl MethodPlugin for RayMarch {
    fn plan(&self, cx: &mut PlanCx, object: &mut ObjectPlan) -> Result<()> {
        super::plan_object(cx, object, self)
    }

    /// `--step` (times `step_scale`), `--segments`, the adaptive stride's `max_step` and
    /// `--shadows`.
    fn with_options(&self, o: &RenderOptions, _lighting: Lighting) -> Method {
        let adaptive = match o.max_step {
            Some(m) => m.map(|max_step| Adaptive { max_step }),
            None => self.adaptive,
        };
        let step = o.step.or(self.step);
        let step = o.step_scale.map_or(step, |k| Some(k * step.unwrap_or(self.step())));
        let (shading, shadows) = match o.shadows {
            None => (self.shading, self.shadows),
            Some(None) => (Shading::Phong, Shadows::Rays),
            Some(Some(s)) => (Shading::PhongShadows, s),
        };
        Method::RayMarch(RayMarch {
            step,
            segments: o.segments.unwrap_or(self.segments),
            adaptive,
            shading,
            shadows,
            ..*self
        })
    }

    /// A ray step, shadow step and adaptive stride `d` times longer.
    fn coarser(&self, d: f64) -> Method {
        let mut h = *self;
        h.step = Some(h.step() * d);
        h.shadow_step = h.shadow_step.map(|s| s * d);
        if let Some(a) = &mut h.adaptive {
            a.max_step *= d;
        }
        Method::RayMarch(h)
    }

    /// Half or twice the step, and an adaptive stride's longest step with it (so the stride
    /// stays on).
    fn quality_step(&self, finer: bool) -> Vec<KnobEdit> {
        let scale = if finer { 0.5 } else { 2.0 };
        let mut out = vec![KnobEdit { path: &["step"], value: self.step() * scale, integer: false }];
        if let Some(a) = self.adaptive {
            out.push(KnobEdit { path: &["adaptive", "max_step"], value: a.max_step * scale, integer: false });
        }
        out
    }

    /// The next shading: None, Phong, PhongShadows, HenyeyGreenstein.
    fn next_mode(&self) -> Option<(&'static [&'static str], String)> {
        let shading = match self.shading {
            Shading::None => "Phong",
            Shading::Phong => "PhongShadows",
            Shading::PhongShadows => "HenyeyGreenstein(g: 0.5, shadows: true)",
            Shading::HenyeyGreenstein { .. } => "None",
        };
        Some((&["shading"], shading.into()))
    }

    fn describe(&self) -> String {
        let adaptive = self.adaptive.map_or(String::new(), |a| format!(", max_step: {:.5}", a.max_step));
        format!(
            "RayMarch(step: {:.5}{adaptive}, shading: {:?}, segments: {:?})",
            self.step(),
            self.shading,
            self.segments
        )
    }

    /// Every hypertexture object marched with each segment strategy and each shadow option, at
    /// each fixed step and then with each adaptive stride (textured objects keep their methods).
    fn sweep(&self, v: &SweepValues, scene: &SweepScene) -> std::result::Result<Vec<SweepPoint>, String> {
        if !scene.has_hypertextures {
            return Err("no hypertexture and no volume".into());
        }
        let mut steps = unique(v.ray_steps.iter().copied());
        steps.sort_by(f64::total_cmp);
        let mut pairs = v.ray_adaptive.clone();
        pairs.dedup();
        // No shadow options: each object's own shading.
        let shadows: Vec<Option<Option<Shadows>>> = if v.ray_shadows.is_empty() {
            vec![None]
        } else {
            unique(v.ray_shadows.iter().copied()).into_iter().map(Some).collect()
        };
        let mut out = Vec::new();
        for (segments, shadows) in unique(v.ray_segments.iter().copied())
            .into_iter()
            .flat_map(|g| shadows.iter().map(move |s| (g, *s)))
        {
            let (name, short) = match segments {
                Segments::Bounds => ("Bounds".to_string(), ""),
                Segments::DepthPeeling { passes, .. } => (format!("DepthPeeling({passes})"), " peel"),
                Segments::Splatting { slabs, .. } => (format!("Splatting({slabs})"), " splat"),
            };
            let fixed = steps.iter().map(|&step| (step, None));
            let adaptive = pairs.iter().map(|&(step, max_step)| (step, Some(max_step)));
            for (step, max_step) in fixed.chain(adaptive) {
                let (knob, tag) = match max_step {
                    None => (String::new(), String::new()),
                    Some(m) => (format!(" max_step={m}"), format!("<{m}")),
                };
                let (shadow_knob, shadow_tag) = match shadows {
                    None => (String::new(), String::new()),
                    Some(s) => (format!(" shadows={}", shadows_name(s)), format!(" {}", shadows_name(s))),
                };
                out.push(SweepPoint {
                    knobs: format!("step={step}{knob} segments={name}{shadow_knob}"),
                    tag: format!("{step}{tag}{short}{shadow_tag}"),
                    options: RenderOptions {
                        size: Some(v.size),
                        step: Some(step),
                        max_step: Some(max_step),
                        segments: Some(segments),
                        shadows,
                        ..Default::default()
                    },
                });
            }
        }
        Ok(out)
    }

    /// `ray-march:STEP[:SHADOWS]`: every hypertexture marched with this step (and these
    /// shadows), every textured object drawn by the truth (a converged march).
    fn truth(&self, arg: Option<&str>, size: (u32, u32)) -> std::result::Result<(RenderOptions, String), String> {
        let rest = arg.ok_or("expected a step: ray-march:STEP[:SHADOWS]")?;
        let (step, shadows) = match rest.split_once(':') {
            Some((step, shadows)) => (step, Some(parse_shadows(shadows)?)),
            None => (rest, None),
        };
        let step = match step.parse::<f64>() {
            Ok(v) if v.is_finite() && v > 0.0 => v,
            _ => return Err(format!("`{step}`: expected a positive step in world units")),
        };
        let label = match shadows {
            None => format!("RayMarch, step {step}"),
            Some(s) => format!("RayMarch, step {step}, shadows {}", shadows_name(s)),
        };
        let method = Some(crate::methods::plugin::MethodKind::truth());
        Ok((RenderOptions { size: Some(size), method, step: Some(step), shadows, ..Default::default() }, label))
    }

    fn truth_form(&self) -> Option<&'static str> {
        Some("ray-march:STEP[:SHADOWS]")
    }

    /// The quality preset's step, twice it for shadow rays, a stride of four steps.
    fn unset_knobs(&self) -> Vec<(&'static str, String)> {
        let step = self.step();
        vec![
            ("step", format!("{step:?}")),
            ("shadow_step", format!("{:?}", 2.0 * step)),
            ("adaptive", format!("(max_step: {:?})", 4.0 * step)),
        ]
    }

    fn kpixel_ms(&self) -> f64 {
        75.0
    }
}
