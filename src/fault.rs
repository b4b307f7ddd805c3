//! Fault injection for tests of the failure paths, from the `VOLTEX_FAULT` environment variable
//! (comma-separated, each fault fires once per process):
//!
//! - `device-lost@pass:N`: destroys the device (`wgpu::Device::destroy`) just before the N-th
//!   graph pass this process records (1-based, counted over all frames and scenes).
//! - `oom@pass:N`: raises wgpu's out-of-memory error at the N-th pass, through the same error
//!   sink a real one takes (a real allocation failure cannot be provoked reliably on software
//!   Vulkan, which overcommits).
//! - `abort@write:N`: aborts the process, as a kill would, in the N-th atomic file write after
//!   the temporary file is complete and before it is renamed over the target.
//! - `no-device@open:N`: the N-th headless device this process opens fails to open (no adapter).
//!
//! Without the variable every hook is one relaxed atomic load.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::OnceLock;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Fault {
    DeviceLost,
    OutOfMemory,
    Abort,
    NoDevice,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Point {
    Pass,
    Write,
    Open,
}

static PASSES: AtomicU64 = AtomicU64::new(0);
static WRITES: AtomicU64 = AtomicU64::new(0);
static OPENS: AtomicU64 = AtomicU64::new(0);

/// Parses `VOLTEX_FAULT`; an unknown entry is reported once and ignored.
fn planned() -> &'static [(Fault, Point, u64)] {
    static PLAN: OnceLock<Vec<(Fault, Point, u64)>> = OnceLock::new();
    PLAN.get_or_init(|| {
        let Ok(text) = std::env::var("VOLTEX_FAULT") else { return Vec::new() };
        text.split(',')
            .filter(|s| !s.trim().is_empty())
            .filter_map(|entry| {
                let parsed = parse(entry.trim());
                if parsed.is_none() {
                    eprintln!(
                        "warning: VOLTEX_FAULT entry `{entry}` ignored: expected device-lost@pass:N, \
                         oom@pass:N, abort@write:N or no-device@open:N"
                    );
                }
                parsed
            })
            .collect()
    })
}

fn parse(entry: &str) -> Option<(Fault, Point, u64)> {
    let (fault, at) = entry.split_once('@')?;
    let (point, n) = at.split_once(':')?;
    let fault = match fault {
        "device-lost" => Fault::DeviceLost,
        "oom" => Fault::OutOfMemory,
        "abort" => Fault::Abort,
        "no-device" => Fault::NoDevice,
        _ => return None,
    };
    let point = match (point, fault) {
        ("pass", Fault::DeviceLost | Fault::OutOfMemory) => Point::Pass,
        ("write", Fault::Abort) => Point::Write,
        ("open", Fault::NoDevice) => Point::Open,
        _ => return None,
    };
    Some((fault, point, n.parse().ok().filter(|&n| n >= 1)?))
}

fn hit(point: Point, counter: &AtomicU64) -> Option<Fault> {
    let plan = planned();
    if plan.is_empty() {
        return None;
    }
    let n = counter.fetch_add(1, Ordering::Relaxed) + 1;
    plan.iter().find(|&&(_, p, at)| p == point && at == n).map(|&(f, _, _)| f)
}

/// Called before each graph pass is recorded: the fault planned for this pass, if any.
pub(crate) fn at_pass() -> Option<Fault> {
    hit(Point::Pass, &PASSES)
}

/// Called when an atomic write's temporary file is complete: aborts if planned.
pub(crate) fn at_write() {
    if hit(Point::Write, &WRITES) == Some(Fault::Abort) {
        eprintln!("VOLTEX_FAULT: aborting in the middle of an atomic write");
        std::process::abort();
    }
}

/// Called when a headless device is about to be opened: whether it must fail.
pub(crate) fn at_open() -> bool {
    hit(Point::Open, &OPENS) == Some(Fault::NoDevice)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_entries() {
        assert_eq!(parse("device-lost@pass:3"), Some((Fault::DeviceLost, Point::Pass, 3)));
        assert_eq!(parse("oom@pass:1"), Some((Fault::OutOfMemory, Point::Pass, 1)));
        assert_eq!(parse("abort@write:2"), Some((Fault::Abort, Point::Write, 2)));
        assert_eq!(parse("no-device@open:2"), Some((Fault::NoDevice, Point::Open, 2)));
        for bad in [
            "oom",
            "oom@pass:0",
            "oom@write:1",
            "abort@pass:1",
            "lost@pass:1",
            "oom@pass:x",
            "no-device@pass:1",
        ] {
            assert_eq!(parse(bad), None, "{bad}");
        }
    }
}
