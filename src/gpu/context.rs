//! Headless GPU context: Vulkan first (software Vulkan, lavapipe, on machines without a GPU), wgpu's
//! GL backend as fallback. Uncaptured wgpu errors are collected instead of panicking, and a lost
//! device is remembered so that every later wait, readback or error check fails with
//! [`Error::DeviceLost`] instead of touching the dead device.

use std::sync::{Arc, Mutex};

use crate::error::{Error, Result};
use crate::fault::Fault;

/// Features voltex uses when the adapter has them (none is required).
pub(crate) const OPTIONAL_FEATURES: wgpu::Features = wgpu::Features::TIMESTAMP_QUERY
    .union(wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS)
    .union(wgpu::Features::FLOAT32_BLENDABLE);

/// The wgpu device and queue voltex renders with, with its adapter's info, features and limits.
/// A clone shares the device (the preview builds a session on another thread with one; wgpu's
/// error scopes are per thread).
#[derive(Clone)]
pub struct GpuContext {
    /// The wgpu device.
    pub device: wgpu::Device,
    pub(crate) queue: wgpu::Queue,
    pub(crate) info: wgpu::AdapterInfo,
    pub(crate) features: wgpu::Features,
    /// The device's limits (the adapter's, as requested).
    pub limits: wgpu::Limits,
    errors: Arc<Mutex<Vec<String>>>,
    /// Why the device was lost, once it is.
    lost: Arc<Mutex<Option<String>>>,
}

/// How wgpu words an out-of-memory error.
const OOM: &str = "Out of Memory";

const NO_ADAPTER: &str = "no GPU adapter found: install software Vulkan \
    (Debian/Ubuntu: `apt-get install mesa-vulkan-drivers`) or a GPU driver with Vulkan support";

impl GpuContext {
    /// Opens the first adapter: `WGPU_BACKEND` if set, else Vulkan, else GL.
    pub fn new() -> Result<Self> {
        if crate::fault::at_open() {
            return Err(Error::Gpu(format!("{NO_ADAPTER} (VOLTEX_FAULT=no-device)")));
        }
        let tries: Vec<wgpu::Backends> = match wgpu::Backends::from_env() {
            Some(b) => vec![b],
            None => vec![wgpu::Backends::VULKAN, wgpu::Backends::GL],
        };
        for backends in tries {
            let mut desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
            desc.backends = backends;
            let instance = wgpu::Instance::new(desc);
            let options = wgpu::RequestAdapterOptions {
                power_preference: wgpu::PowerPreference::HighPerformance,
                ..Default::default()
            };
            if let Ok(adapter) = pollster::block_on(instance.request_adapter(&options)) {
                if adapter.get_info().backend == wgpu::Backend::Gl {
                    eprintln!(
                        "warning: no Vulkan adapter; using wgpu's GL backend, which lacks features voltex \
                         needs (f32 render targets). Install software Vulkan: apt-get install mesa-vulkan-drivers"
                    );
                }
                return Self::open(adapter);
            }
        }
        Err(Error::Gpu(NO_ADAPTER.into()))
    }

    /// Opens a device on `adapter` (the preview picks one compatible with its window).
    pub(crate) fn open(adapter: wgpu::Adapter) -> Result<Self> {
        let info = adapter.get_info();
        let features = adapter.features() & OPTIONAL_FEATURES;
        let limits = adapter.limits();
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("voltex"),
            required_features: features,
            required_limits: limits.clone(),
            experimental_features: wgpu::ExperimentalFeatures::disabled(),
            memory_hints: wgpu::MemoryHints::Performance,
            trace: wgpu::Trace::Off,
        }))
        .map_err(|e| Error::Gpu(format!("cannot open {} ({:?}): {e}", info.name, info.backend)))?;
        let errors = Arc::new(Mutex::new(Vec::new()));
        let sink = errors.clone();
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
            sink.lock().unwrap().push(e.to_string());
        }));
        let lost = Arc::new(Mutex::new(None));
        let note = lost.clone();
        device.set_device_lost_callback(move |reason, message| {
            let why = match reason {
                wgpu::DeviceLostReason::Destroyed => "destroyed",
                wgpu::DeviceLostReason::Unknown => "lost by the driver",
            };
            note.lock().unwrap().get_or_insert(format!("{why}: {message}"));
        });
        Ok(Self { device, queue, info, features, limits, errors, lost })
    }

    /// `Some(reason)` once the device is lost.
    pub fn lost(&self) -> Option<String> {
        self.lost.lock().unwrap().clone()
    }

    /// The error for a failed GPU operation: [`Error::DeviceLost`] if the device is gone (its lost
    /// callback runs at the next poll, so poll once without waiting), else [`Error::Gpu`].
    fn gpu_error(&self, message: String) -> Error {
        if self.lost().is_none() {
            let _ = self.device.poll(wgpu::PollType::Poll);
        }
        self.check_alive().err().unwrap_or(Error::Gpu(message))
    }

    /// Fails with [`Error::DeviceLost`] once the device is lost.
    pub(crate) fn check_alive(&self) -> Result<()> {
        match self.lost() {
            Some(why) => Err(Error::DeviceLost(format!("{} ({why})", self.info.name))),
            None => Ok(()),
        }
    }

    /// Applies the fault `VOLTEX_FAULT` plans for the next graph pass, if any (see [`fault`]).
    ///
    /// [`fault`]: crate::fault
    pub(crate) fn fault_at_pass(&self) {
        match crate::fault::at_pass() {
            Some(Fault::DeviceLost) => {
                eprintln!("VOLTEX_FAULT: destroying the GPU device");
                self.device.destroy();
                // The callback may run later, at a poll; the device is gone now.
                self.lost.lock().unwrap().get_or_insert("destroyed: VOLTEX_FAULT=device-lost".into());
            }
            Some(Fault::OutOfMemory) => {
                eprintln!("VOLTEX_FAULT: raising an out-of-memory error");
                let e = wgpu::Error::OutOfMemory {
                    source: Box::new(std::io::Error::other("allocation refused by VOLTEX_FAULT=oom")),
                };
                self.errors.lock().unwrap().push(e.to_string());
            }
            Some(Fault::Abort | Fault::NoDevice) | None => {}
        }
    }

    /// One line naming the adapter, for metadata and reports.
    pub fn adapter_line(&self) -> String {
        format!(
            "{} ({:?}, {} {})",
            self.info.name, self.info.backend, self.info.driver, self.info.driver_info
        )
    }

    /// The adapter's name, type, backend and driver.
    pub fn info(&self) -> &wgpu::AdapterInfo {
        &self.info
    }

    /// The optional features the device was opened with (see `OPTIONAL_FEATURES`).
    pub fn features(&self) -> wgpu::Features {
        self.features
    }

    pub(crate) fn has_timestamps(&self) -> bool {
        self.features
            .contains(wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS)
    }

    /// Fails with the first wgpu error raised outside an error scope since the last call.
    pub(crate) fn take_errors(&self) -> Result<()> {
        self.check_alive()?;
        let mut errors = self.errors.lock().unwrap();
        if errors.is_empty() {
            return Ok(());
        }
        let first = errors.remove(0);
        errors.clear();
        drop(errors);
        if first == OOM {
            return Err(Error::Gpu(format!(
                "{first}: the GPU ran out of memory; try a smaller --size, fewer planes or smaller texels"
            )));
        }
        Err(self.gpu_error(first))
    }

    /// Runs `f` inside a validation error scope, turning wgpu validation errors into `Error::Gpu`.
    pub(crate) fn scoped<T>(&self, what: &str, f: impl FnOnce() -> T) -> Result<T> {
        self.check_alive()?;
        let scope = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let value = f();
        match pollster::block_on(scope.pop()) {
            None => self.check_alive().map(|()| value),
            Some(e) => Err(self.gpu_error(format!("{what}: {e}"))),
        }
    }

    /// Blocks until all submitted work is done.
    pub(crate) fn wait(&self) -> Result<()> {
        self.wait_until(None)
    }

    /// Blocks until the work of `submission` (and all before it) is done, not what came after.
    pub(crate) fn wait_for(&self, submission: wgpu::SubmissionIndex) -> Result<()> {
        self.wait_until(Some(submission))
    }

    fn wait_until(&self, submission: Option<wgpu::SubmissionIndex>) -> Result<()> {
        self.check_alive()?;
        let poll = wgpu::PollType::Wait { submission_index: submission, timeout: None };
        self.device.poll(poll).map(|_| ()).map_err(|e| self.gpu_error(format!("waiting for the GPU: {e}")))
    }

    /// Copies a buffer back to the CPU (tests, timestamps, readback of images).
    pub fn read_buffer(&self, buffer: &wgpu::Buffer, offset: u64, size: u64) -> Result<Vec<u8>> {
        let staging = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut enc = self.device.create_command_encoder(&Default::default());
        enc.copy_buffer_to_buffer(buffer, offset, &staging, 0, size);
        self.queue.submit([enc.finish()]);
        self.map_read(&staging)
    }

    /// Maps a MAP_READ buffer after the queue is idle and returns its bytes.
    pub(crate) fn map_read(&self, staging: &wgpu::Buffer) -> Result<Vec<u8>> {
        let slice = staging.slice(..);
        slice.map_async(wgpu::MapMode::Read, |_| {});
        self.wait()?;
        self.check_alive()?;
        let bytes = slice
            .get_mapped_range()
            .map_err(|e| self.gpu_error(format!("mapping a readback buffer: {e}")))?
            .to_vec();
        staging.unmap();
        self.take_errors()?;
        Ok(bytes)
    }

    /// Text of `voltex info`.
    pub fn describe(&self) -> String {
        let l = &self.limits;
        let mut s = String::new();
        s += &format!("adapter:  {}\n", self.info.name);
        s += &format!("type:     {:?}\n", self.info.device_type);
        s += &format!("backend:  {:?}\n", self.info.backend);
        s += &format!("driver:   {} {}\n", self.info.driver, self.info.driver_info);
        s += "features voltex uses:\n";
        for (name, f) in [
            ("TIMESTAMP_QUERY (GPU timings)", wgpu::Features::TIMESTAMP_QUERY),
            ("TIMESTAMP_QUERY_INSIDE_ENCODERS", wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS),
            ("FLOAT32_BLENDABLE (f32 accumulation)", wgpu::Features::FLOAT32_BLENDABLE),
        ] {
            s += &format!("  {:<34} {}\n", name, if self.features.contains(f) { "yes" } else { "no" });
        }
        s += "limits:\n";
        for (name, v) in [
            ("max_texture_dimension_2d", l.max_texture_dimension_2d as u64),
            ("max_texture_dimension_3d", l.max_texture_dimension_3d as u64),
            ("max_buffer_size", l.max_buffer_size),
            ("max_storage_buffer_binding_size", l.max_storage_buffer_binding_size),
            ("max_compute_workgroups_per_dimension", l.max_compute_workgroups_per_dimension as u64),
            ("max_compute_invocations_per_workgroup", l.max_compute_invocations_per_workgroup as u64),
            ("max_bind_groups", l.max_bind_groups as u64),
        ] {
            s += &format!("  {name:<38} {v}\n");
        }
        s
    }
}
