//! What a GPU test assumes of its adapter, after wgpu's `tests/src/expectations.rs`: the features
//! and limits beyond WebGPU's defaults it needs, and the known deviations of particular adapters
//! (a skip with its reason, or a tolerance of their own). Each module of `tests/gpu/` declares
//! its `ADAPTER` and opens the shared device through [`gpu!`]; `tests/checks/adapters.rs` keeps it
//! so. The suite runs on llvmpipe (CI) and on real GPUs: on an adapter that cannot run a test, the
//! test says why and passes, unless `VOLTEX_REQUIRE_GPU_TESTS` is set (CI sets it, so that no
//! test is skipped there unseen).

use std::sync::MutexGuard;
use voltex::gpu::GpuContext;

/// The adapter a test needs, and how known adapters deviate.
pub struct Expectations {
    /// Features beyond WebGPU's defaults.
    pub features: wgpu::Features,
    /// Limits above WebGPU's defaults.
    pub limits: &'static [Limit],
    /// Known deviations, first match wins.
    pub deviations: &'static [Deviation],
}

/// A limit a test needs at least.
pub struct Limit {
    pub name: &'static str,
    pub of: fn(&wgpu::Limits) -> u64,
    pub at_least: u64,
}

/// A known deviation of the adapters `adapter` matches.
pub struct Deviation {
    pub adapter: Adapter,
    pub effect: Effect,
    /// What the adapter does differently (the note a reader of a skip or a tolerance needs).
    pub why: &'static str,
}

/// Which adapters a deviation concerns: each field that is set must match.
pub struct Adapter {
    /// A part of the adapter's name (`llvmpipe`, `NVIDIA`), case-insensitive; "" for any.
    pub name: &'static str,
    /// Its device type, if that is what matters (e.g. `Cpu` for software rasterisers).
    pub device_type: Option<wgpu::DeviceType>,
}

/// What a deviation does to a test.
pub enum Effect {
    /// The test cannot run there.
    Skip,
    /// The named tolerance is this value there (see [`Expectations::tolerance`]).
    Tolerance(&'static str, f64),
}

impl Expectations {
    /// WebGPU's default features and limits, no known deviation.
    pub const DEFAULTS: Expectations =
        Expectations { features: wgpu::Features::empty(), limits: &[], deviations: &[] };

    fn deviation<'a>(&'a self, info: &'a wgpu::AdapterInfo) -> impl Iterator<Item = &'a Deviation> + 'a {
        self.deviations.iter().filter(move |d| {
            let name = d.adapter.name.is_empty()
                || info.name.to_lowercase().contains(&d.adapter.name.to_lowercase());
            name && d.adapter.device_type.is_none_or(|t| t == info.device_type)
        })
    }

    /// Why `ctx`'s adapter cannot run the test; `None` when it can.
    pub fn unmet(&self, ctx: &GpuContext) -> Option<String> {
        self.unmet_on(ctx.info(), ctx.features(), &ctx.limits)
    }

    /// [`Expectations::unmet`] for an adapter described by its info, features and limits.
    pub fn unmet_on(
        &self,
        info: &wgpu::AdapterInfo,
        features: wgpu::Features,
        limits: &wgpu::Limits,
    ) -> Option<String> {
        let missing = self.features - features;
        if !missing.is_empty() {
            return Some(format!("the adapter lacks the features {missing:?}"));
        }
        for l in self.limits {
            let has = (l.of)(limits);
            if has < l.at_least {
                return Some(format!("the adapter's {} is {has}, the test needs {}", l.name, l.at_least));
            }
        }
        self.deviation(info)
            .find(|d| matches!(d.effect, Effect::Skip))
            .map(|d| format!("known deviation: {}", d.why))
    }

    /// The tolerance `name` on `ctx`'s adapter: a deviation's value, else `default`.
    pub fn tolerance(&self, ctx: &GpuContext, name: &str, default: f64) -> f64 {
        self.tolerance_on(ctx.info(), name, default)
    }

    /// [`Expectations::tolerance`] for an adapter described by its info.
    pub fn tolerance_on(&self, info: &wgpu::AdapterInfo, name: &str, default: f64) -> f64 {
        self.deviation(info)
            .find_map(|d| match d.effect {
                Effect::Tolerance(n, v) if n == name => Some(v),
                _ => None,
            })
            .unwrap_or(default)
    }
}

/// The shared device when its adapter meets `expect`; `None` (said on stderr) when it does not,
/// and a panic then where `VOLTEX_REQUIRE_GPU_TESTS` is set.
pub fn open(expect: &Expectations) -> Option<MutexGuard<'static, GpuContext>> {
    let ctx = super::ctx().lock().unwrap_or_else(|e| e.into_inner());
    let Some(why) = expect.unmet(&ctx) else { return Some(ctx) };
    let line = format!("{}: {why}", ctx.adapter_line());
    if std::env::var_os("VOLTEX_REQUIRE_GPU_TESTS").is_some() {
        panic!("{line} (VOLTEX_REQUIRE_GPU_TESTS is set: no GPU test may be skipped)");
    }
    eprintln!("skipped on {line}");
    None
}

/// The shared device for a helper of tests with these expectations: a panic naming what the
/// adapter lacks where it cannot run them (each test opens the device with [`gpu!`] first, so it
/// is skipped before its helpers run).
pub fn device(expect: &Expectations) -> MutexGuard<'static, GpuContext> {
    open(expect).unwrap_or_else(|| panic!("the adapter cannot run these tests (see above)"))
}

/// `gpu!(ADAPTER)`: the shared device for a test with these expectations, or a return from the
/// test (with the value's default) when the adapter cannot run it.
#[allow(unused_macros)] // Only the GPU tests open the device.
macro_rules! gpu {
    ($expect:expr) => {
        match $crate::common::adapter::open(&$expect) {
            Some(ctx) => ctx,
            None => return Default::default(),
        }
    };
}
#[allow(unused_imports)]
pub(crate) use gpu;
