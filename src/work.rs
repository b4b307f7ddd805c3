//! Work a step did that the preview's latency report accounts for: files opened and the time
//! spent reading them, and shaders parsed and validated (process-wide counters; a step reads
//! them before and after).

use std::sync::atomic::{AtomicU64, Ordering::Relaxed};
use std::time::Instant;

static FILES: AtomicU64 = AtomicU64::new(0);
static FILE_NANOS: AtomicU64 = AtomicU64::new(0);
static SHADERS: AtomicU64 = AtomicU64::new(0);
static SHADER_NANOS: AtomicU64 = AtomicU64::new(0);

/// The counters at one moment; the difference of two is what happened between them.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct Work {
    /// User, graph and shader files opened.
    pub(crate) files: u64,
    /// Time spent opening and reading them (ms).
    pub(crate) io_ms: f64,
    /// Shaders parsed and validated.
    pub(crate) shaders: u64,
    /// Time spent parsing and validating them (ms).
    pub(crate) validate_ms: f64,
}

impl Work {
    /// The counters now.
    pub(crate) fn now() -> Work {
        Work {
            files: FILES.load(Relaxed),
            io_ms: FILE_NANOS.load(Relaxed) as f64 * 1e-6,
            shaders: SHADERS.load(Relaxed),
            validate_ms: SHADER_NANOS.load(Relaxed) as f64 * 1e-6,
        }
    }

    /// What happened since `earlier`.
    pub(crate) fn since(earlier: Work) -> Work {
        let now = Work::now();
        Work {
            files: now.files - earlier.files,
            io_ms: now.io_ms - earlier.io_ms,
            shaders: now.shaders - earlier.shaders,
            validate_ms: now.validate_ms - earlier.validate_ms,
        }
    }
}

/// Counts a file opened, and the time since `start` as opening it.
pub(crate) fn file_opened(start: Instant) {
    FILES.fetch_add(1, Relaxed);
    FILE_NANOS.fetch_add(start.elapsed().as_nanos() as u64, Relaxed);
}

/// Counts the time since `start` as reading an open file.
pub(crate) fn file_read(start: Instant) {
    FILE_NANOS.fetch_add(start.elapsed().as_nanos() as u64, Relaxed);
}

/// Counts a shader validated, and the time since `start` as validating it.
pub(crate) fn shader_validated(start: Instant) {
    SHADERS.fetch_add(1, Relaxed);
    SHADER_NANOS.fetch_add(start.elapsed().as_nanos() as u64, Relaxed);
}
