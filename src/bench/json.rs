//! Benchmark results as JSON (`bench --json FILE`, `bench-hyper --json FILE`): the adapter, the
//! date, the machine's load and one object per table row, with the knobs that apply to it, its
//! times, its errors against the truth it names, and the work the cost model fits its time
//! against ([`super::cost`]). `voltex bench-report` turns these files into the performance
//! page's tables ([`markdown`]).

use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// One row of a benchmark table.
#[derive(Debug, Clone, Default, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Row {
    /// Which table of the command the row belongs to.
    pub table: String,
    /// `bench`: the scene's file stem.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scene: Option<String>,
    /// `bench-hyper`: the object.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub object: Option<String>,
    /// The method as written in scene files (`ViewSlices`, `RayMarch`, ...).
    pub method: String,
    /// ViewSlices: slicing planes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub planes: Option<u32>,
    /// ViewSlices: whether prisms outside a plane's slab are skipped.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub trivial_reject: Option<bool>,
    /// RayMarch: ray step (world units).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub step: Option<f64>,
    /// RayMarch: quality preset (`HQ`, `IE`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub quality: Option<String>,
    /// RayMarch: shading (`None`, `Phong`, ...).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shading: Option<String>,
    /// RayMarch: how shadows are found (`Rays`, `LightVolume`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shadows: Option<String>,
    /// RayMarch: segment strategy (`Bounds`, `DepthPeeling`, `Splatting`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub segments: Option<String>,
    /// ViewSlices: compositor (`Raster`, `Tiles`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub compositor: Option<String>,
    /// Median wall-clock ms of a whole frame (submit to idle).
    pub frame_ms: f64,
    /// Median GPU ms of a frame from timestamps (the sum over its passes), where the adapter has
    /// them (on lavapipe compute timestamps go wrong once a render pass has run: read frame_ms).
    pub gpu_ms: Option<f64>,
    /// Frames per second from the median frame time.
    pub fps: f64,
    /// Mean FLIP and relative RMSE against `truth`.
    pub flip: Option<f64>,
    /// Relative RMSE against `truth`.
    pub rel_rmse: Option<f64>,
    /// What the error is measured against (a scene or a method setting).
    pub truth: Option<String>,
    /// What the cost model fits the frame time against, and its unit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub work: Option<f64>,
    /// The unit of `work` (e.g. slice triangles, density evaluations).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub work_unit: Option<String>,
    /// The table's other columns (per-pass times, counts, shares).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub extra: BTreeMap<String, f64>,
}

impl Row {
    /// A row of `table` with its frame time (ms) and the fps it implies.
    pub fn new(table: &str, method: &str, frame_ms: f64) -> Self {
        Row {
            table: table.into(),
            method: method.into(),
            frame_ms,
            fps: 1e3 / frame_ms,
            ..Default::default()
        }
    }
}

/// The adapter's own rates, measured in the same run (`bench --limits`).
#[derive(Debug, Clone, Default, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Limits {
    /// Premultiplied-over blended fragments per second into Rgba32Float, each with one trilinear
    /// 3D texture fetch.
    pub blend_fragments_per_s: f64,
    /// Small triangles (32 pixels each) per second beyond their fragments' blending; `None` where
    /// they cost under 5% of their draw. Absent from reports older than it.
    #[serde(default)]
    pub triangles_per_s: Option<f64>,
    /// Trilinear samples per second of an rgba8 3D texture in a compute kernel, marching along z.
    pub texture_samples_per_s: f64,
    /// 3D simplex noise evaluations per second (`bench_simplex.wgsl`).
    pub noise_per_s: f64,
}

/// A whole `--json` file.
#[derive(Debug, Clone, Default, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Report {
    /// `bench` or `bench-hyper`.
    pub command: String,
    /// The adapter, as [`GpuContext::adapter_line`](crate::gpu::GpuContext::adapter_line) names it.
    pub adapter: String,
    /// UTC, `YYYY-MM-DD HH:MM`.
    pub date: String,
    /// The 1-minute load average when the run began (software adapters share the CPU).
    pub(crate) load: Option<f64>,
    /// Frame size in pixels (width, height).
    pub size: [u32; 2],
    /// Timed frames per row, after warm-up.
    pub frames: usize,
    /// One row per measured setting.
    pub rows: Vec<Row>,
    /// The adapter's measured throughput limits (blending, texture sampling, noise), when measured.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub limits: Option<Limits>,
    /// The cost models fitted to the rows.
    #[serde(default)]
    pub cost_models: Vec<super::cost::Fit>,
    /// The timed frames' passes, for `--trace` (not part of the JSON).
    #[serde(skip)]
    pub(crate) traces: Vec<crate::render::trace::Track>,
}

impl Report {
    /// An empty report of `command` on `adapter`, dated now with the current load.
    pub fn new(command: &str, adapter: String, size: (u32, u32), frames: usize) -> Self {
        let now =
            std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_secs());
        Report {
            command: command.into(),
            adapter,
            date: crate::regress::report::utc(now),
            load: std::fs::read_to_string("/proc/loadavg")
                .ok()
                .and_then(|l| l.split_whitespace().next()?.parse().ok()),
            size: [size.0, size.1],
            frames,
            ..Default::default()
        }
    }

    /// Keeps the last frame of `renderer` as a trace track named `name`.
    pub(crate) fn trace(&mut self, name: String, renderer: &crate::render::Renderer) {
        self.traces.push(crate::render::trace::Track { name, frames: vec![renderer.spans().to_vec()] });
    }

    /// Writes `--json` and `--trace` where asked.
    pub(crate) fn finish(&self, json: Option<&Path>, trace: Option<&Path>) -> Result<()> {
        if let Some(path) = json {
            self.write(path)?;
            println!("wrote {}", path.display());
        }
        if let Some(path) = trace {
            crate::render::trace::write(path, &self.traces, &self.adapter)?;
            println!("trace: {}", path.display());
        }
        Ok(())
    }

    /// Writes the report (temporary file, then rename).
    pub fn write(&self, path: &Path) -> Result<()> {
        let text = serde_json::to_string_pretty(self).map_err(|e| Error::Invalid(format!("JSON: {e}")))?;
        crate::io::atomic::write_bytes(path, (text + "\n").as_bytes())
    }

    /// Reads a report written by `--json`, naming the file in errors.
    pub fn read(path: &Path) -> Result<Self> {
        let text = crate::input::read_text(path, "a benchmark JSON file")?;
        serde_json::from_str(&text).map_err(|e| {
            Error::file(
                path,
                format!(
                    "{}:{}: {e}: expected a `bench --json` or `bench-hyper --json` file",
                    e.line(),
                    e.column()
                ),
            )
        })
    }
}

/// The cells of a row for the markdown table, by column name (`None`: the column does not apply).
fn cells(row: &Row) -> BTreeMap<String, String> {
    let mut c = BTreeMap::new();
    let mut put = |k: &str, v: Option<String>| {
        if let Some(v) = v {
            c.insert(k.to_string(), v);
        }
    };
    put("scene", row.scene.clone());
    put("object", row.object.clone());
    put("method", Some(row.method.clone()));
    put("planes", row.planes.map(|v| v.to_string()));
    put("trivial_reject", row.trivial_reject.map(|v| if v { "on".into() } else { "off".into() }));
    put("step", row.step.map(|v| format!("{v}")));
    put("quality", row.quality.clone());
    put("shading", row.shading.clone());
    put("shadows", row.shadows.clone());
    put("segments", row.segments.clone());
    put("compositor", row.compositor.clone());
    put("frame_ms", Some(format!("{:.1}", row.frame_ms)));
    put("gpu_ms", row.gpu_ms.map(|v| format!("{v:.1}")));
    put("fps", Some(format!("{:.2}", row.fps)));
    put("flip", row.flip.map(|v| format!("{v:.4}")));
    put("rel_rmse", row.rel_rmse.map(|v| format!("{v:.4}")));
    put("work", row.work.map(|v| format!("{v:.3e}")));
    for (k, v) in &row.extra {
        put(k, Some(if v.abs() >= 100.0 || *v == v.round() { format!("{v:.0}") } else { format!("{v:.3}") }));
    }
    c
}

/// The order of the columns that come first; the rest follow in name order.
const FIRST: &[&str] = &[
    "scene",
    "object",
    "method",
    "planes",
    "trivial_reject",
    "quality",
    "step",
    "shading",
    "shadows",
    "segments",
    "compositor",
    "frame_ms",
    "gpu_ms",
    "fps",
    "flip",
    "rel_rmse",
];

/// Markdown for the performance page: per report a heading with the command, adapter, date and
/// load, then each of its tables with the columns its rows have, its truths, cost models and
/// limits.
pub fn markdown(reports: &[(String, Report)]) -> String {
    let mut out = String::new();
    for (source, r) in reports {
        out += &format!(
            "### `voltex {}` on {}, {}\n\n{}x{}, median of {} frame(s); load average {} at the start; from `{source}`.\n\n",
            r.command,
            r.adapter,
            r.date,
            r.size[0],
            r.size[1],
            r.frames,
            r.load.map_or("unknown".into(), |l| format!("{l:.1}"))
        );
        if let Some(l) = &r.limits {
            out += &format!(
                "Adapter limits measured in the run: blended fragments {:.0} M/s, small triangles beyond their \
                 fragments {}, trilinear texture samples {:.0} M/s, simplex noise {:.0} M/s.\n\n",
                l.blend_fragments_per_s / 1e6,
                super::limits::triangles(l),
                l.texture_samples_per_s / 1e6,
                l.noise_per_s / 1e6
            );
        }
        let mut tables: Vec<&str> = Vec::new();
        for row in &r.rows {
            if !tables.contains(&row.table.as_str()) {
                tables.push(&row.table);
            }
        }
        for table in tables {
            let rows: Vec<BTreeMap<String, String>> =
                r.rows.iter().filter(|row| row.table == table).map(cells).collect();
            let mut columns: Vec<String> = FIRST
                .iter()
                .filter(|c| rows.iter().any(|r| r.contains_key(**c)))
                .map(|c| c.to_string())
                .collect();
            for row in &rows {
                for k in row.keys() {
                    if !columns.contains(k) {
                        columns.push(k.clone());
                    }
                }
            }
            let mut truths: Vec<String> =
                r.rows.iter().filter(|row| row.table == table).filter_map(|row| row.truth.clone()).collect();
            truths.dedup();
            out += &format!("Table `{table}`");
            if !truths.is_empty() {
                out += &format!("; errors against: {}", truths.join("; "));
            }
            out += ".\n\n";
            out += &format!("| {} |\n|{}\n", columns.join(" | "), "---|".repeat(columns.len()));
            for row in &rows {
                let line: Vec<&str> = columns.iter().map(|c| row.get(c).map_or("", |v| v.as_str())).collect();
                out += &format!("| {} |\n", line.join(" | "));
            }
            out += "\n";
        }
        for f in &r.cost_models {
            out += &format!("- {}\n", f.describe());
        }
        if !r.cost_models.is_empty() {
            out += "\n";
        }
    }
    out
}

/// The markers between which `bench-report --update` replaces a page's generated section.
pub const BEGIN: &str = "<!-- bench-report: begin (generated by `voltex bench-report`; do not edit) -->";
/// The end marker of the generated section (see [`BEGIN`]).
pub const END: &str = "<!-- bench-report: end -->";

/// `page` with the text between [`BEGIN`] and [`END`] replaced by `section`.
pub fn splice(page: &str, section: &str) -> std::result::Result<String, String> {
    let begin = page.find(BEGIN).ok_or_else(|| format!("no line `{BEGIN}`"))?;
    let end = page[begin..]
        .find(END)
        .map(|e| begin + e)
        .ok_or_else(|| format!("no line `{END}` after the begin marker"))?;
    Ok(format!("{}{BEGIN}\n\n{section}{}", &page[..begin], &page[end..]))
}

/// Fails early (before any GPU work) when the folder of an output file is not writable.
pub(crate) fn check_output(path: Option<&Path>) -> Result<()> {
    match path {
        Some(p) => crate::io::atomic::check_writable_dir(
            p.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new(".")),
        ),
        None => Ok(()),
    }
}
