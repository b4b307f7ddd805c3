//! One scene's outcome as a JSON record (`result.json` in the scene's output folder), and the
//! collection of every record under an output folder, so that shards merge into one report.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::io::atomic;
use crate::{Error, Result};

/// File name of a scene's record inside its output folder.
pub(crate) const RECORD_FILE: &str = "result.json";

/// Images a scene's output folder may hold, in the order the report shows them.
pub(crate) const IMAGES: [&str; 4] = ["reference.png", "actual.png", "diff.png", "truth.png"];

/// Artefacts a run writes into a scene's folder besides the record; others are never touched.
pub(crate) const ARTEFACTS: [&str; 5] =
    ["reference.png", "actual.png", "diff.png", "truth.png", "actual.exr"];

/// The outcome of one scene's regression check.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// Failures first (the report sorts by this order).
    BrokenScene,
    /// The reference image is unreadable, or of another size than the render.
    BrokenReference,
    /// The render is beyond the scene's thresholds against its reference.
    Regressed,
    /// The scene has no reference yet.
    New,
    /// Within the thresholds.
    Pass,
}

impl Status {
    pub(crate) fn label(self) -> &'static str {
        match self {
            Status::Pass => "pass",
            Status::Regressed => "regressed",
            Status::New => "new",
            Status::BrokenScene => "broken scene",
            Status::BrokenReference => "broken reference",
        }
    }
}

/// What a run found for one scene. Metrics that could not be computed (or were NaN) are `None`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Record {
    /// Scene file relative to the scanned folder, `/`-separated (`view_slices/torus_egg.ron`).
    pub scene: String,
    /// The scene file and its reference image relative to the suite root (the scanned folder),
    /// `/`-separated, so that records written on other machines merge.
    pub scene_path: String,
    /// The reference image, as `scene_path`.
    pub reference_path: String,
    /// Fingerprint of the suite's sorted scene list: records of different suites do not merge.
    #[serde(default)]
    pub suite: String,
    /// Hash of what the result depends on (scene and asset bytes, reference bytes, render size,
    /// graphs, WGSL, the binary): a rerun skips a scene whose record has the same hash.
    #[serde(default)]
    pub inputs: String,
    /// The outcome.
    pub status: Status,
    /// `--update` wrote the reference in this run (the scene was new, regressed or of another size).
    pub updated: bool,
    /// Why the scene is not `pass` (errors name `file:line:col`), or what `--update` did.
    pub message: Option<String>,
    /// Warnings of the scene's checks (degenerate triangles, ...).
    #[serde(default)]
    pub(crate) warnings: Vec<String>,
    /// Render size (width, height).
    pub size: Option<[u32; 2]>,
    /// Mean FLIP against the reference.
    pub flip: Option<f64>,
    /// Relative RMSE against the reference.
    pub rel_rmse: Option<f64>,
    pub(crate) max_flip: f64,
    pub(crate) max_rel_rmse: f64,
    /// Mean FLIP of the render against the scene's independent truth, and its bound (`None`:
    /// the scene states no `regress.truth`).
    #[serde(default)]
    pub truth_flip: Option<f64>,
    /// The scene's bound on `truth_flip` (`regress.truth.max_flip`).
    #[serde(default)]
    pub max_truth_flip: Option<f64>,
    /// Pixels of the render with a NaN or infinite channel.
    pub(crate) nonfinite_pixels: Option<usize>,
    /// GPU time of the frame from timestamp queries (none without TIMESTAMP_QUERY).
    pub(crate) gpu_ms: Option<f64>,
    /// Wall time of the whole check: load, plan, bake, render, compare, write.
    pub(crate) wall_ms: f64,
    /// The adapter that rendered, as
    /// [`GpuContext::adapter_line`](crate::gpu::GpuContext::adapter_line) names it.
    pub adapter: String,
    /// The adapter that rendered the reference (`voltex_adapter` in its EXR metadata).
    pub(crate) reference_adapter: Option<String>,
    /// Images present in the scene's folder (file names from [`IMAGES`]).
    pub(crate) images: Vec<String>,
    /// `i/n` of the run that wrote this record.
    pub shard: String,
    /// Host that wrote the record (for the report of a farm run).
    #[serde(default)]
    pub(crate) host: String,
    /// Seconds since 1970-01-01 UTC when the record was written.
    pub(crate) finished_unix: u64,
    pub(crate) voltex_version: String,
}

impl Record {
    /// A scene failing (`status` broken or regressed, or new without `--update`)?
    pub(crate) fn failed(&self) -> bool {
        self.status != Status::Pass && !self.updated
    }

    /// Writes `folder/result.json` atomically.
    pub fn write(&self, folder: &Path) -> Result<()> {
        let path = folder.join(RECORD_FILE);
        let text = serde_json::to_string_pretty(self)
            .map_err(|e| Error::file(&path, format!("cannot encode the record: {e}")))?;
        atomic::write_bytes(&path, (text + "\n").as_bytes())
    }

    /// Reads a `result.json`, naming the file in errors.
    pub fn read(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::file(path, e))?;
        serde_json::from_str(&text).map_err(|e| {
            Error::file(path, format!("{}:{}: not a voltex regress record: {e}", e.line(), e.column()))
        })
    }
}

/// A record with the folder it was found in, relative to the output folder.
#[derive(Debug, Clone)]
pub struct Found {
    pub(crate) folder: PathBuf,
    /// The record.
    pub record: Record,
}

/// Every record under `out` (any depth; hidden folders skipped), sorted by failures first, then
/// scene. Records that cannot be read are returned as errors beside them, not fatal.
pub fn collect(out: &Path) -> Result<(Vec<Found>, Vec<Error>)> {
    let mut found = Vec::new();
    let mut bad = Vec::new();
    walk(out, Path::new(""), &mut found, &mut bad)?;
    // Failures first (`!failed()` is false for them), then by status and scene.
    found.sort_by(|a, b| {
        let key = |f: &Found| (!f.record.failed(), f.record.status, f.record.scene.clone());
        key(a).cmp(&key(b))
    });
    Ok((found, bad))
}

fn walk(dir: &Path, rel: &Path, found: &mut Vec<Found>, bad: &mut Vec<Error>) -> Result<()> {
    let entries = std::fs::read_dir(dir).map_err(|e| Error::file(dir, format!("cannot list: {e}")))?;
    let mut entries: Vec<_> = entries.filter_map(|e| e.ok()).collect();
    entries.sort_by_key(|e| e.file_name());
    for e in entries {
        let name = e.file_name();
        if name.to_string_lossy().starts_with('.') {
            continue;
        }
        let path = e.path();
        let is_dir = e.file_type().map(|t| t.is_dir()).unwrap_or(false);
        if is_dir {
            walk(&path, &rel.join(&name), found, bad)?;
        } else if name == RECORD_FILE {
            match Record::read(&path) {
                Ok(record) => found.push(Found { folder: rel.to_path_buf(), record }),
                Err(e) => bad.push(e),
            }
        }
    }
    Ok(())
}
