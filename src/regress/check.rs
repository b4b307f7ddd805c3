//! One scene of a run: load, plan, render, compare with `<stem>.ref.exr`, write the artefacts
//! and the record, and with `--update` the reference.

use std::path::Path;
use std::time::Instant;

use super::discover::SceneEntry;
use super::record::{Record, Status, ARTEFACTS, IMAGES, RECORD_FILE};
use super::{shards, Args, RunInfo};
use crate::gpu::GpuContext;
use crate::io::{self, Image};
use crate::metrics;
use crate::render::{Blueprint, MethodKind, RenderOptions, Renderer};
use crate::scene::{self, Regress};
use crate::{Error, Result};

/// A rendered scene with what the report needs from its renderer.
struct Rendered {
    image: Image,
    gpu_ms: Option<f64>,
    metadata: Vec<(String, String)>,
}

/// One scene's outcome: its record, and whether that is an earlier run's, still current.
pub(super) struct Checked {
    pub(crate) record: Record,
    pub(crate) skipped: bool,
}

/// Checks one scene, or keeps its record when that is current (see [`current`]; a broken scene
/// is always rechecked, since it may have been a passing GPU fault) unless `--force`. Problems of the scene or its reference become the record's status; only
/// failures to write into the output folder or the reference are errors.
pub(super) fn check(ctx: &GpuContext, run: &RunInfo, entry: &SceneEntry) -> Result<Checked> {
    let opts = run.args;
    let start = Instant::now();
    let folder = opts.out.join(&entry.folder);
    std::fs::create_dir_all(&folder)
        .map_err(|e| Error::file(&folder, format!("cannot create folder: {e}")))?;
    let defaults = Regress::default();
    let reference_rel = match entry.rel.rsplit_once('/') {
        Some((dir, _)) => format!("{dir}/{}", file_name(&entry.reference)),
        None => file_name(&entry.reference),
    };
    let mut rec = Record {
        scene: entry.rel.clone(),
        scene_path: entry.rel.clone(),
        reference_path: reference_rel,
        suite: run.suite.clone(),
        inputs: String::new(),
        status: Status::BrokenScene,
        updated: false,
        message: None,
        warnings: Vec::new(),
        size: None,
        flip: None,
        rel_rmse: None,
        max_flip: defaults.max_flip,
        max_rel_rmse: defaults.max_rel_rmse,
        truth_flip: None,
        max_truth_flip: None,
        nonfinite_pixels: None,
        gpu_ms: None,
        wall_ms: 0.0,
        adapter: ctx.adapter_line(),
        reference_adapter: None,
        images: Vec::new(),
        shard: run.shard.to_string(),
        host: run.host.clone(),
        finished_unix: 0,
        voltex_version: env!("CARGO_PKG_VERSION").to_string(),
    };
    // A panic on some input is a bug, but still only this scene's problem.
    let mut scene_hash = String::new();
    let loaded = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| scene::load(&entry.path)))
        .unwrap_or_else(|p| Err(Error::file(&entry.path, super::panic_text(&p))));
    let rendered = loaded.and_then(|scene| {
        let size = opts
            .size
            .or(scene.regress.size.map(|[w, h]| (w, h)))
            .unwrap_or((scene.output.width, scene.output.height));
        scene_hash = shards::scene_hash(&scene, entry, size, &run.toolchain);
        rec.inputs = shards::inputs_hash(&scene_hash, entry);
        if !opts.force {
            if let Ok(old) = Record::read(&folder.join(RECORD_FILE)) {
                if current(&old, &rec, opts.update) {
                    return Ok(None);
                }
            }
        }
        rec.max_flip = opts.max_flip.unwrap_or(scene.regress.max_flip);
        rec.max_rel_rmse = opts.max_rel_rmse.unwrap_or(scene.regress.max_rel_rmse);
        // A bound holds at the size it was measured at: `--size` renders check no truth.
        let own_size =
            scene.regress.size.map(|[w, h]| (w, h)).unwrap_or((scene.output.width, scene.output.height));
        let checked = !opts.no_truth && size == own_size;
        rec.max_truth_flip = scene.regress.truth.filter(|_| checked).map(|t| t.max_flip);
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            let frame = render(ctx, &scene, size, &mut rec)?;
            let truth = if checked { truth(ctx, &scene, size)? } else { None };
            Ok((frame, truth))
        }))
        .unwrap_or_else(|p| Err(Error::file(&entry.path, super::panic_text(&p))))
        .map(Some)
    });
    let rendered = match rendered {
        Ok(None) => {
            let record = Record::read(&folder.join(RECORD_FILE))?;
            return Ok(Checked { record, skipped: true });
        }
        Ok(Some(frame)) => Ok(frame),
        Err(e) => Err(e),
    };
    match rendered {
        Ok((frame, truth)) => {
            let true_enough = match truth {
                Some(t) => measure_truth(&frame.image, &t, &folder, &mut rec)?,
                None => true,
            };
            compare(opts, entry, &folder, &frame, true_enough, &mut rec)?;
            if rec.updated {
                // The reference is part of the inputs, and this run rewrote it.
                rec.inputs = shards::inputs_hash(&scene_hash, entry);
            }
        }
        Err(e) => rec.message = Some(e.to_string()),
    }
    rec.wall_ms = start.elapsed().as_secs_f64() * 1e3;
    rec.finished_unix =
        std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map(|d| d.as_secs()).unwrap_or(0);
    rec.images.sort_by_key(|i| IMAGES.iter().position(|n| n == i));
    rec.write(&folder)?;
    // Artefacts of an earlier run that this one did not write would mislead a reader of the folder.
    for name in ARTEFACTS {
        let written = match name {
            "actual.exr" => rec.size.is_some(),
            _ => rec.images.iter().any(|i| i == name),
        };
        if !written {
            let _ = std::fs::remove_file(folder.join(name));
        }
    }
    Ok(Checked { record: rec, skipped: false })
}

/// Whether an earlier record of this scene still holds: same inputs and suite, not a broken
/// scene, not one whose reference that run rewrote (a rerun says whether it passes now), and
/// nothing `--update` would rewrite.
fn current(old: &Record, new: &Record, update: bool) -> bool {
    let rewrite = matches!(old.status, Status::New | Status::Regressed | Status::BrokenReference);
    old.inputs == new.inputs
        && old.suite == new.suite
        && old.status != Status::BrokenScene
        && !old.updated
        && !(update && rewrite)
}

fn file_name(path: &Path) -> String {
    path.file_name().unwrap_or_default().to_string_lossy().into_owned()
}

/// Plans and renders the loaded scene; any error here makes it a broken scene.
fn render(ctx: &GpuContext, scene: &scene::Scene, size: (u32, u32), rec: &mut Record) -> Result<Rendered> {
    let opts = RenderOptions {
        size: Some(size),
        supersample: Some(scene.regress.supersample),
        ..Default::default()
    };
    let bp = Blueprint::new(scene, &opts)?;
    rec.warnings.extend(scene.warnings.iter().cloned());
    for o in &bp.objects {
        for w in &o.object.report.warnings {
            rec.warnings.push(format!("object `{}`: {w}", o.object.name));
        }
    }
    let mut renderer = Renderer::new(ctx, bp)?;
    let frame = renderer.render(ctx)?;
    let metadata = renderer.metadata(ctx, &frame);
    Ok(Rendered { gpu_ms: frame.gpu_ms(), image: frame.image, metadata })
}

/// The scene's independent truth at `size` (see `scene::Truth`), if it states a bound.
fn truth(ctx: &GpuContext, scene: &scene::Scene, size: (u32, u32)) -> Result<Option<Image>> {
    let Some(t) = scene.regress.truth else { return Ok(None) };
    let opts = RenderOptions {
        size: Some(size),
        supersample: Some(scene.regress.supersample),
        method: Some(MethodKind::truth()),
        step_scale: Some(t.step_scale),
        segments: Some(scene::Segments::Bounds),
        max_step: Some(None),
        ..Default::default()
    };
    let mut renderer = Renderer::new(ctx, Blueprint::new(scene, &opts)?)?;
    Ok(Some(renderer.render(ctx)?.image))
}

/// FLIP of the render against its truth (written as `truth.png`); a render beyond the bound
/// regresses. Whether it is within.
fn measure_truth(image: &Image, truth: &Image, folder: &Path, rec: &mut Record) -> Result<bool> {
    io::png::write_tonemapped(&folder.join("truth.png"), truth)?;
    rec.images.push("truth.png".into());
    let flip = metrics::flip(image, truth)?.mean;
    rec.truth_flip = flip.is_finite().then_some(flip);
    let bound = rec.max_truth_flip.unwrap_or(1.0);
    Ok(flip <= bound)
}

/// Writes the render, compares it with the reference, and updates the reference if asked and
/// the render is within its truth bound.
fn compare(
    opts: &Args,
    entry: &SceneEntry,
    folder: &Path,
    frame: &Rendered,
    true_enough: bool,
    rec: &mut Record,
) -> Result<()> {
    let image = &frame.image;
    rec.size = Some([image.width, image.height]);
    rec.gpu_ms = frame.gpu_ms;
    let nonfinite = metrics::count_nonfinite(image);
    rec.nonfinite_pixels = Some(nonfinite);
    let meta: Vec<(&str, String)> = frame.metadata.iter().map(|(k, v)| (k.as_str(), v.clone())).collect();
    io::exr::write(&folder.join("actual.exr"), image, &meta)?;
    io::png::write_tonemapped(&folder.join("actual.png"), image)?;
    rec.images.push("actual.png".into());

    let mut size_mismatch = false;
    if !entry.reference.exists() {
        rec.status = Status::New;
        rec.message = Some(format!("no reference image {}", entry.reference.display()));
    } else {
        match io::exr::read(&entry.reference) {
            Err(e) => {
                rec.status = Status::BrokenReference;
                rec.message = Some(format!(
                    "{e} (delete it and run with --update to write a new one from this render)"
                ));
            }
            Ok((reference, ref_meta)) => {
                rec.reference_adapter =
                    ref_meta.iter().find(|(k, _)| k == "voltex_adapter").map(|(_, v)| v.clone());
                io::png::write_tonemapped(&folder.join("reference.png"), &reference)?;
                rec.images.push("reference.png".into());
                if !reference.same_size(image) {
                    size_mismatch = true;
                    rec.status = Status::BrokenReference;
                    rec.message = Some(format!(
                        "{}: reference is {}x{}, the render is {}x{} (regress.size or --size changed? \
                         --update rewrites it)",
                        entry.reference.display(),
                        reference.width,
                        reference.height,
                        image.width,
                        image.height
                    ));
                } else {
                    measure(image, &reference, folder, rec)?;
                }
            }
        }
    }
    if nonfinite > 0 {
        let note = format!("{nonfinite} pixels of the render are NaN or infinite");
        rec.message = Some(match rec.message.take() {
            Some(m) => format!("{m}; {note}"),
            None => note,
        });
    }
    if !true_enough {
        // Unchanged or not, a render this far from the truth is wrong.
        let note = format!(
            "mean FLIP {:.5} against the truth > {} (regress.truth)",
            rec.truth_flip.unwrap_or(f64::NAN),
            rec.max_truth_flip.unwrap_or(1.0)
        );
        if rec.status == Status::Pass {
            rec.status = Status::Regressed;
        }
        rec.message = Some(match rec.message.take() {
            Some(m) => format!("{m}; {note}"),
            None => note,
        });
    }
    let rewrite = matches!(rec.status, Status::New | Status::Regressed) || size_mismatch;
    if opts.update && rewrite && !true_enough {
        let what = format!("--update refused: {} would break its truth bound", entry.reference.display());
        rec.message = rec.message.take().map(|m| format!("{m}; {what}"));
    } else if opts.update && rewrite {
        let mut meta = meta;
        meta.push(("voltex_regress_scene", entry.rel.clone()));
        io::exr::write(&entry.reference, image, &meta)?;
        rec.updated = true;
        let what = format!("--update wrote {}", entry.reference.display());
        rec.message = Some(match rec.message.take() {
            Some(m) if rec.status != Status::New => format!("{m}; {what}"),
            _ => what,
        });
    }
    Ok(())
}

/// FLIP and relative RMSE against a reference of the same size; writes the FLIP heat map.
fn measure(image: &Image, reference: &Image, folder: &Path, rec: &mut Record) -> Result<()> {
    let flip = metrics::flip(image, reference)?;
    let rel = metrics::relative_rmse(image, reference)?;
    let heat = metrics::diff_heatmap(&flip.map, image.width, image.height);
    io::png::write_rgba8(&folder.join("diff.png"), image.width, image.height, &heat)?;
    rec.images.push("diff.png".into());
    rec.flip = flip.mean.is_finite().then_some(flip.mean);
    rec.rel_rmse = rel.is_finite().then_some(rel);
    let flip_ok = flip.mean <= rec.max_flip;
    let rel_ok = rel <= rec.max_rel_rmse;
    if flip_ok && rel_ok {
        rec.status = Status::Pass;
    } else {
        rec.status = Status::Regressed;
        let mut over = Vec::new();
        if !flip_ok {
            over.push(format!("mean FLIP {:.5} > {}", flip.mean, rec.max_flip));
        }
        if !rel_ok {
            over.push(format!("relative RMSE {:.5} > {}", rel, rec.max_rel_rmse));
        }
        rec.message = Some(over.join(", "));
    }
    Ok(())
}
