//! What `voltex pareto` hands back: the measured rows with their fronts, `pareto.csv`, the
//! chart's series and the printed tables.

use super::peers::PeerRow;
use super::{front, measure, svg, unique, Args, Setting};
use crate::error::Result;
use crate::gpu::GpuContext;
use crate::io::Image;

/// A measured setting.
pub(super) struct Row {
    setting: Setting,
    passes: Vec<measure::PassTime>,
    wall_ms: f64,
    /// Wall ms of the compute-only frame (phase 1), to check its timestamps against.
    compute_wall_ms: f64,
    /// Median wall ms of a frame while the camera orbits (`measure::orbit_ms`).
    orbit_ms: f64,
    flip: f64,
    rel_rmse: f64,
    /// Density evaluations of RayMarch objects per frame.
    evaluations: f64,
    method_front: bool,
    overall_front: bool,
}

impl Row {
    pub(super) fn new(
        setting: Setting,
        compute: measure::ComputeOnly,
        frames: measure::Frames,
        orbit_ms: f64,
        truth: &Image,
    ) -> Result<Self> {
        let passes = compute
            .passes
            .into_iter()
            .map(|(name, ms)| measure::PassTime { name, compute: true, ms })
            .chain(frames.raster.into_iter().map(|(name, ms)| measure::PassTime { name, compute: false, ms }))
            .collect();
        Ok(Row {
            passes,
            wall_ms: frames.wall_ms,
            evaluations: frames.evaluations,
            compute_wall_ms: compute.wall_ms,
            orbit_ms,
            flip: crate::metrics::flip(&frames.image, truth)?.mean,
            rel_rmse: crate::metrics::relative_rmse(&frames.image, truth)?,
            setting,
            method_front: false,
            overall_front: false,
        })
    }

    /// `12.3 ms wall, FLIP 0.01234`: a progress line's result.
    pub(super) fn summary(&self) -> String {
        format!("{:.1} ms wall, FLIP {:.5}", self.wall_ms, self.flip)
    }

    /// GPU ms of a frame: the sum of its passes' medians (NaN without timestamps).
    fn gpu_ms(&self) -> f64 {
        if self.passes.is_empty() {
            return f64::NAN;
        }
        self.passes.iter().map(|p| p.ms).sum()
    }
    /// The time plotted: GPU time, or wall time on adapters without timestamps.
    fn time(&self) -> f64 {
        let gpu = self.gpu_ms();
        if gpu.is_finite() {
            gpu
        } else {
            self.wall_ms
        }
    }
}

pub(super) fn mark_fronts(rows: &mut [Row]) {
    let xy: Vec<(f64, f64)> = rows.iter().map(|r| (r.time(), r.flip)).collect();
    for (r, on) in rows.iter_mut().zip(front::front(&xy)) {
        r.overall_front = on;
    }
    let methods: Vec<&'static str> = unique(rows.iter().map(|r| r.setting.method));
    for m in methods {
        let ids: Vec<usize> = (0..rows.len()).filter(|&i| rows[i].setting.method == m).collect();
        let pts: Vec<(f64, f64)> = ids.iter().map(|&i| xy[i]).collect();
        for (&i, on) in ids.iter().zip(front::front(&pts)) {
            rows[i].method_front = on;
        }
    }
}

fn num(v: Option<f64>) -> String {
    v.filter(|v| v.is_finite()).map(|v| format!("{v:.6}")).unwrap_or_default()
}

/// One row per measured setting; `passes` lists `name=ms` of every pass (compute passes first);
/// `compute_wall_ms` is the wall time of a compute-only frame, to check `compute_ms` against.
pub(super) fn csv(rows: &[Row]) -> String {
    let mut s = String::from(
        "method,knobs,planes,trivial_reject,step,gpu_ms,compute_ms,raster_ms,wall_ms,compute_wall_ms,\
         orbit_ms,flip,rel_rmse,evaluations,method_front,overall_front,passes\n",
    );
    for r in rows {
        let o = &r.setting.options;
        let sum = |compute: bool| r.passes.iter().filter(|p| p.compute == compute).map(|p| p.ms).sum::<f64>();
        let passes: Vec<String> = r.passes.iter().map(|p| format!("{}={:.4}", p.name, p.ms)).collect();
        s.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n",
            r.setting.method,
            r.setting.knobs,
            o.planes.map(|p| p.to_string()).unwrap_or_default(),
            o.trivial_reject.map(|t| t.to_string()).unwrap_or_default(),
            num(o.step),
            num(Some(r.gpu_ms())),
            num(Some(sum(true))),
            num(Some(sum(false))),
            num(Some(r.wall_ms)),
            num(Some(r.compute_wall_ms)),
            num(Some(r.orbit_ms)),
            num(Some(r.flip)),
            num(Some(r.rel_rmse)),
            r.evaluations,
            r.method_front,
            r.overall_front,
            passes.join(";"),
        ));
    }
    s
}

pub(super) fn chart(rows: &[Row], peers: &[PeerRow], title: &str, timestamps: bool) -> String {
    let mut series: Vec<svg::Series> = unique(rows.iter().map(|r| r.setting.method))
        .into_iter()
        .map(|m| svg::Series {
            label: m.to_string(),
            points: rows
                .iter()
                .filter(|r| r.setting.method == m)
                .map(|r| svg::Point {
                    x: r.time(),
                    y: r.flip,
                    label: format!("{} {}", m, r.setting.knobs),
                    tag: r.setting.tag.clone(),
                })
                .collect(),
        })
        .collect();
    for name in unique(peers.iter().map(|p| p.renderer.as_str())) {
        let points = peers
            .iter()
            .filter(|p| p.renderer == name)
            .map(|p| svg::Point {
                x: p.seconds * 1e3,
                y: p.flip,
                label: format!(
                    "{name} {} {} spp, {} threads, {}",
                    p.setting, p.samples, p.threads, p.version
                ),
                tag: format!("{} spp", p.samples),
            })
            .collect();
        series.push(svg::Series { label: name.to_string(), points });
    }
    let x_label = match (timestamps, peers.is_empty()) {
        (true, true) => "GPU time per frame (ms, log): sum of pass medians",
        (false, true) => "wall time per frame (ms, log)",
        (true, false) => "time per frame (ms, log): voltex GPU time (pass medians), peers wall time",
        (false, false) => "wall time per frame (ms, log), voltex and peers",
    };
    svg::render(&svg::Chart { title, x_label, y_label: "error: mean FLIP (log)", series: &series })
}

/// Timestamps against wall clock, summed over all settings: compute-only frames (their
/// timestamps should account for nearly all their wall time) and whole frames (compute plus
/// raster time against the frame's wall time). A ratio far below 1 means lost timestamps.
fn timing_check(rows: &[Row]) -> String {
    let sum = |f: &dyn Fn(&Row) -> f64| rows.iter().map(f).filter(|v| v.is_finite()).sum::<f64>();
    let compute = sum(&|r| r.passes.iter().filter(|p| p.compute).map(|p| p.ms).sum());
    let (compute_wall, gpu, wall) = (sum(&|r| r.compute_wall_ms), sum(&|r| r.gpu_ms()), sum(&|r| r.wall_ms));
    let ratio = |a: f64, b: f64| if b > 0.0 { a / b } else { f64::NAN };
    let (c, f) = (ratio(compute, compute_wall), ratio(gpu, wall));
    let mut line = format!(
        "timing check (timestamps / wall clock, all settings): compute-only frames {c:.2}, whole frames {f:.2}"
    );
    if [c, f].iter().any(|r| r.is_finite() && !(0.5..=1.5).contains(r)) {
        line.push_str(
            "\nwarning: timestamps and wall clock disagree by more than 1.5x: GPU times may be wrong",
        );
    }
    line
}

/// The 1-minute load average (Linux), to tell a quiet machine from a busy one: on a software
/// adapter, GPU time is CPU time and other processes stretch it.
pub(super) fn load_average() -> Option<f64> {
    std::fs::read_to_string("/proc/loadavg").ok()?.split_whitespace().next()?.parse().ok()
}

pub(super) fn print_report(
    args: &Args,
    ctx: &GpuContext,
    rows: &[Row],
    peers: &[PeerRow],
    notes: &[String],
    load: Option<f64>,
) {
    println!(
        "pareto: {} at {}x{}, truth: {}",
        args.scene.display(),
        args.sweep.size.0,
        args.sweep.size.1,
        args.truth_label()
    );
    if args.supersample_methods > 1 {
        let n = args.supersample_methods;
        println!("every setting rendered with {n}x{n} samples per pixel, averaged");
    }
    println!("adapter: {}", ctx.adapter_line());
    if ctx.has_timestamps() {
        println!(
            "GPU ms: per frame, the sum of each pass's median over {} frames after warm-up ({} frames, \
             1 when a frame takes over {} ms; compute passes timed alone, see README); wall ms: submit to idle; \
             orbit ms: median wall ms of {} frames whose camera turns {} degrees a frame, planned, uploaded, \
             rendered and waited for",
            args.frames,
            measure::WARM_UP_FRAMES,
            measure::LONG_FRAME_MS,
            args.frames,
            measure::ORBIT_DEGREES
        );
        println!("{}", timing_check(rows));
    } else {
        println!(
            "no GPU timestamps on this adapter: times are wall clock (submit to idle); orbit ms: median wall ms \
             of {} frames whose camera turns {} degrees a frame, planned, uploaded, rendered and waited for",
            args.frames,
            measure::ORBIT_DEGREES
        );
    }
    let cores = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1);
    if let (Some(a), Some(b)) = (load, load_average()) {
        println!("load average (1 min) at start {a:.2}, at end {b:.2}, on {cores} cores");
    }
    for n in notes {
        println!("{n}");
    }
    let table = |title: &str, ids: Vec<usize>| {
        let mut ids = ids;
        ids.sort_by(|&a, &b| rows[a].time().total_cmp(&rows[b].time()));
        println!("\n{title}");
        println!("| method | knobs | GPU ms | wall ms | orbit ms | FLIP | rel RMSE | density evaluations |");
        println!("|---|---|---|---|---|---|---|---|");
        for i in ids {
            let r = &rows[i];
            println!(
                "| {} | {} | {:.2} | {:.2} | {:.2} | {:.4} | {:.4} | {:.3e} |",
                r.setting.method,
                r.setting.knobs,
                r.gpu_ms(),
                r.wall_ms,
                r.orbit_ms,
                r.flip,
                r.rel_rmse,
                r.evaluations
            );
        }
    };
    for m in unique(rows.iter().map(|r| r.setting.method)) {
        let ids = (0..rows.len()).filter(|&i| rows[i].setting.method == m && rows[i].method_front).collect();
        table(&format!("{m} front:"), ids);
    }
    table("overall front:", (0..rows.len()).filter(|&i| rows[i].overall_front).collect());
    if !peers.is_empty() {
        println!("\npeers (--peers; wall time of the whole render on the CPU threads given):");
        println!("| renderer | setting | samples | ms | threads | version | FLIP | rel RMSE | RMSE | from |");
        println!("|---|---|---|---|---|---|---|---|---|---|");
        for p in peers {
            println!(
                "| {} | {} | {} | {:.1} | {} | {} | {:.4} | {:.4} | {:.2e} | {} |",
                p.renderer,
                p.setting,
                p.samples,
                p.seconds * 1e3,
                p.threads,
                p.version,
                p.flip,
                p.rel_rmse,
                p.rmse,
                p.at
            );
        }
    }
}
