//! Per-pass GPU times as a Chrome/Perfetto trace (the Trace Event Format's JSON, which
//! chrome://tracing and ui.perfetto.dev open): one complete event (`"ph": "X"`, microseconds) per
//! pass of every frame, from the timestamp queries around each graph pass ([`Span`]). A trace holds
//! tracks (one per renderer: a benchmark setting, the preview), each a thread of its own; a
//! track's frames keep their places on the adapter's clock, shifted so the track begins at 0.

use std::path::Path;

use serde_json::{json, Value};

use crate::error::Result;
use crate::gpu::timing::Span;

/// The frames of one renderer.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Track {
    /// The renderer's name in the trace.
    pub name: String,
    /// Per frame, its passes' timed spans.
    pub frames: Vec<Vec<Span>>,
}

/// The trace's JSON.
pub(crate) fn chrome_trace(tracks: &[Track], adapter: &str) -> Value {
    let mut events = Vec::new();
    for (tid, track) in tracks.iter().enumerate() {
        events.push(
            json!({"name": "thread_name", "ph": "M", "pid": 1, "tid": tid, "args": {"name": track.name}}),
        );
        let origin = track.frames.iter().flatten().map(|s| s.begin_ms).fold(f64::INFINITY, f64::min);
        for (frame, spans) in track.frames.iter().enumerate() {
            for s in spans {
                events.push(json!({
                    "name": s.name,
                    "cat": "gpu",
                    "ph": "X",
                    "pid": 1,
                    "tid": tid,
                    "ts": (s.begin_ms - origin) * 1e3,
                    "dur": s.ms * 1e3,
                    "args": {"frame": frame},
                }));
            }
        }
    }
    events.push(json!({"name": "process_name", "ph": "M", "pid": 1, "args": {"name": format!("voltex on {adapter}")}}));
    json!({"traceEvents": events, "displayTimeUnit": "ms"})
}

/// Writes the trace (temporary file, then rename).
pub fn write(path: &Path, tracks: &[Track], adapter: &str) -> Result<()> {
    let text = serde_json::to_string(&chrome_trace(tracks, adapter)).expect("JSON values serialize");
    crate::io::atomic::write_bytes(path, text.as_bytes())
}
