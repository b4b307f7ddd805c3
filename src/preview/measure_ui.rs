//! `voltex preview SCENE --measure-ui`: how the real window behaves while a slow frame renders.
//! Once the first frame is shown, the window switches to the reference view (what pressing `2`
//! does: every object drawn by the exact Reference, a frame of seconds on a software adapter)
//! and times the frames it presents until the reference's frame is shown: the largest and the
//! 99th-percentile gap between presented frames, and the time to the finished frame. Then it
//! renders the same frame blocking, in one submission, and compares it with the frame rendered in
//! steps bit for bit. Several runs (back to the image view in between), a table, and JSON.

use std::path::PathBuf;
use std::time::Instant;

use serde::Serialize;

use crate::error::{Error, Result};
use crate::render::{Frame, Renderer};

/// One switch to the reference view.
#[derive(Debug, Clone, Serialize)]
pub(crate) struct UiRun {
    /// The largest time between two presented window frames (ms), from the key to the final
    /// frame shown.
    pub(crate) ui_gap_max_ms: f64,
    /// The 99th percentile of those gaps (ms).
    pub(crate) ui_gap_p99_ms: f64,
    /// Window frames presented meanwhile.
    pub(crate) presented: usize,
    /// From the key to the finished frame shown (ms): the reference's build and its steps.
    pub(crate) final_ms: f64,
    /// The same frame rendered blocking, in one submission, waited for (ms); the build not
    /// included.
    pub(crate) blocking_ms: f64,
    /// The reference's build (scene, bakes, pipelines), within `final_ms` (ms).
    pub(crate) build_ms: f64,
    /// Values (pixels' channels and AOVs) of the stepped frame that differ from the blocking one.
    pub(crate) differing_values: usize,
}

/// Where a measurement stands.
enum Phase {
    /// Waiting for the image view's frame to be shown.
    Settle,
    /// Switched to the reference view at this instant; the window's presents since.
    Switched { at: Instant, presents: Vec<Instant> },
}

/// The measurement the window runs (see the module's text).
pub(crate) struct UiMeasure {
    runs: usize,
    json: Option<PathBuf>,
    phase: Phase,
    done: Vec<UiRun>,
    load: [f64; 2],
    /// The reference's build time of the current run (ms).
    pub(crate) build_ms: f64,
}

/// What the window does next for the measurement.
pub(crate) enum Next {
    /// Nothing: keep going.
    Wait,
    /// Switch to the reference view now.
    Switch,
    /// The run ended: back to the image view for the next one.
    Back,
    /// Every run ended: close the window.
    Quit,
}

fn load_average() -> f64 {
    let text = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    text.split_whitespace().next().and_then(|v| v.parse().ok()).unwrap_or(f64::NAN)
}

fn values(frame: &Frame) -> Vec<u32> {
    let mut out: Vec<u32> = frame.image.pixels.iter().flatten().map(|v| v.to_bits()).collect();
    for (_, channel) in &frame.aovs {
        out.extend(channel.iter().map(|v| v.to_bits()));
    }
    out
}

impl UiMeasure {
    pub(crate) fn new(runs: usize, json: Option<PathBuf>) -> Self {
        Self {
            runs: runs.max(1),
            json,
            phase: Phase::Settle,
            done: Vec::new(),
            load: [load_average(), 0.0],
            build_ms: 0.0,
        }
    }

    /// After each window frame presented: `settled` when no frame is in flight, `reference` the
    /// reference's renderer when its frame is finished.
    pub(crate) fn presented(
        &mut self,
        settled: bool,
        reference: Option<&mut Renderer>,
        ctx: &crate::gpu::GpuContext,
    ) -> Result<Next> {
        let now = Instant::now();
        match &mut self.phase {
            Phase::Settle if settled => {
                self.phase = Phase::Switched { at: now, presents: vec![now] };
                Ok(Next::Switch)
            }
            Phase::Settle => Ok(Next::Wait),
            Phase::Switched { presents, .. } if !settled || reference.is_none() => {
                presents.push(now);
                Ok(Next::Wait)
            }
            Phase::Switched { at, presents } => {
                presents.push(now);
                let final_ms = (now - *at).as_secs_f64() * 1e3;
                let mut gaps: Vec<f64> =
                    presents.windows(2).map(|w| (w[1] - w[0]).as_secs_f64() * 1e3).collect();
                gaps.sort_by(f64::total_cmp);
                let p99 = gaps
                    .get(((gaps.len() as f64 * 0.99).ceil() as usize).saturating_sub(1))
                    .copied()
                    .unwrap_or(0.0);
                let presented = presents.len();
                let r = reference.ok_or_else(|| Error::Invalid("no reference renderer".into()))?;
                let stepped = values(&r.read_frame(ctx)?);
                let t = Instant::now();
                r.render_timed(ctx)?;
                let blocking_ms = t.elapsed().as_secs_f64() * 1e3;
                let blocking = values(&r.read_frame(ctx)?);
                let differing_values = stepped.iter().zip(&blocking).filter(|(a, b)| a != b).count()
                    + stepped.len().abs_diff(blocking.len());
                self.done.push(UiRun {
                    ui_gap_max_ms: gaps.last().copied().unwrap_or(0.0),
                    ui_gap_p99_ms: p99,
                    presented,
                    final_ms,
                    blocking_ms,
                    build_ms: self.build_ms,
                    differing_values,
                });
                self.phase = Phase::Settle;
                if self.done.len() < self.runs {
                    return Ok(Next::Back);
                }
                self.load[1] = load_average();
                self.report()?;
                Ok(Next::Quit)
            }
        }
    }

    /// Prints the table and writes the JSON.
    fn report(&self) -> Result<()> {
        println!("run  gap max ms  gap p99 ms  presented  build ms  final ms  blocking ms  final/blocking  differing values");
        for (i, r) in self.done.iter().enumerate() {
            println!(
                "{:>3}  {:>10.1}  {:>10.1}  {:>9}  {:>8.0}  {:>8.0}  {:>11.0}  {:>14.2}  {:>16}",
                i + 1,
                r.ui_gap_max_ms,
                r.ui_gap_p99_ms,
                r.presented,
                r.build_ms,
                r.final_ms,
                r.blocking_ms,
                r.final_ms / r.blocking_ms,
                r.differing_values
            );
        }
        println!("load average (1 min) at start {:.2}, at end {:.2}", self.load[0], self.load[1]);
        let Some(path) = &self.json else { return Ok(()) };
        let worst = |f: fn(&UiRun) -> f64| self.done.iter().map(f).fold(0.0, f64::max);
        let json = serde_json::json!({
            "ui_gap_max_ms": worst(|r| r.ui_gap_max_ms),
            "ui_gap_p99_ms": worst(|r| r.ui_gap_p99_ms),
            "final_ms": worst(|r| r.final_ms),
            "blocking_ms": self.done.iter().map(|r| r.blocking_ms).fold(f64::INFINITY, f64::min),
            "identical": self.done.iter().all(|r| r.differing_values == 0),
            "load_average": self.load,
            "runs": self.done,
        });
        let text = serde_json::to_string_pretty(&json).unwrap_or_default() + "\n";
        crate::io::atomic::write_bytes(path, text.as_bytes())?;
        println!("wrote {}", path.display());
        Ok(())
    }
}
