//! GPU timestamps around each pass (when the adapter has TIMESTAMP_QUERY). Durations are read
//! back after the frame; benchmarks take medians after warm-up. Tests never assert on them.

use crate::error::Result;
use crate::gpu::GpuContext;

/// GPU timestamps around labelled passes of one frame (none where the adapter has no timestamp
/// queries).
pub struct Timer {
    set: Option<wgpu::QuerySet>,
    resolve: Option<wgpu::Buffer>,
    labels: Vec<String>,
    capacity: u32,
}

impl Timer {
    /// A timer for up to `passes` passes; inert when the adapter has no timestamps.
    pub fn new(ctx: &GpuContext, passes: u32) -> Self {
        let capacity = passes.max(1) * 2;
        if !ctx.has_timestamps() {
            return Self { set: None, resolve: None, labels: Vec::new(), capacity };
        }
        let set = ctx.device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("pass timestamps"),
            ty: wgpu::QueryType::Timestamp,
            count: capacity,
        });
        let resolve = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("timestamp resolve"),
            size: capacity as u64 * 8,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        Self { set: Some(set), resolve: Some(resolve), labels: Vec::new(), capacity }
    }

    pub(crate) fn reset(&mut self) {
        self.labels.clear();
    }

    /// Reserves the begin/end query pair for a pass; `None` when out of queries or unsupported.
    fn next(&mut self, label: &str) -> Option<(&wgpu::QuerySet, u32)> {
        let index = self.labels.len() as u32 * 2;
        if index + 2 > self.capacity {
            return None;
        }
        let set = self.set.as_ref()?;
        self.labels.push(label.to_string());
        Some((set, index))
    }

    pub(crate) fn compute(&mut self, label: &str) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        self.next(label).map(|(query_set, i)| wgpu::ComputePassTimestampWrites {
            query_set,
            beginning_of_pass_write_index: Some(i),
            end_of_pass_write_index: Some(i + 1),
        })
    }

    pub(crate) fn render(&mut self, label: &str) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        self.next(label).map(|(query_set, i)| wgpu::RenderPassTimestampWrites {
            query_set,
            beginning_of_pass_write_index: Some(i),
            end_of_pass_write_index: Some(i + 1),
        })
    }

    pub(crate) fn resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        if let (Some(set), Some(buf)) = (&self.set, &self.resolve) {
            if !self.labels.is_empty() {
                encoder.resolve_query_set(set, 0..self.labels.len() as u32 * 2, buf, 0);
            }
        }
    }

    /// Per-pass spans on the adapter's timestamp clock, in submission order.
    pub(crate) fn read_spans(&self, ctx: &GpuContext) -> Result<Vec<Span>> {
        let Some(buf) = &self.resolve else {
            return Ok(Vec::new());
        };
        if self.labels.is_empty() {
            return Ok(Vec::new());
        }
        let bytes = ctx.read_buffer(buf, 0, self.labels.len() as u64 * 16)?;
        let ticks: Vec<u64> = bytemuck::pod_collect_to_vec(&bytes);
        let ms = ctx.queue.get_timestamp_period() as f64 * 1e-6;
        Ok(self
            .labels
            .iter()
            .enumerate()
            .map(|(i, l)| Span {
                name: l.clone(),
                begin_ms: ticks[2 * i] as f64 * ms,
                ms: ticks[2 * i + 1].saturating_sub(ticks[2 * i]) as f64 * ms,
            })
            .collect())
    }
}

/// One pass of a frame on the adapter's timestamp clock: its name (the graph pass's), when it
/// began (ms since the clock's origin, which only the adapter knows) and how long it took.
#[derive(Debug, Clone, PartialEq)]
pub struct Span {
    pub(crate) name: String,
    pub(crate) begin_ms: f64,
    pub(crate) ms: f64,
}
