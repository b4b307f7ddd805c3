//! GPU allocations estimated from counts alone, and their checks against an adapter's limits
//! and a memory budget, so that `voltex plan` refuses what the driver would refuse late (a wgpu
//! "invalid texture view" naming no file) or what would exhaust the machine.

/// The GPU memory a frame may allocate when `--budget` is not given.
pub(crate) const DEFAULT_BUDGET: u64 = 4 << 30;

/// The limits `voltex plan` checks when no adapter is open: wgpu's defaults (what WebGPU
/// guarantees), raised where every desktop Vulkan, D3D12 and Metal adapter, and lavapipe, offers
/// more and the shipped scenes need it (a 256-voxel texel has 511 slice layers per direction).
pub fn plan_limits() -> wgpu::Limits {
    wgpu::Limits {
        max_texture_dimension_2d: 16384,
        max_texture_array_layers: 2048,
        // wgpu clamps it to `i32::MAX` on several backends; lavapipe reports the same.
        max_buffer_size: i32::MAX as u64,
        ..wgpu::Limits::default()
    }
}

/// What one allocation is, for the limit that applies to it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum AllocationKind {
    /// A buffer; `storage` when a kernel binds it whole (the binding-size limit applies).
    Buffer {
        storage: bool,
    },
    /// A 2D texture or array of `layers` layers.
    Texture2d {
        size: [u32; 2],
        layers: u32,
    },
    Texture3d {
        size: [u32; 3],
    },
}

/// The value in a user file that sizes an allocation, for the error's position and hint.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum Driver {
    /// The output size (the scene's `output`, or `--size`).
    Output,
    /// A texel's `resolution`.
    Texel(String),
    /// A node (its method's knobs).
    Object(String),
    /// A graph resource's declaration.
    Graph(String),
}

/// One texture or buffer a frame allocates.
#[derive(Debug, Clone)]
pub struct Allocation {
    pub(crate) what: String,
    pub(crate) bytes: u64,
    pub(crate) shape: AllocationKind,
    pub(crate) driver: Driver,
}

fn mib(n: u64) -> String {
    format!("{:.1} MiB", n as f64 / (1u64 << 20) as f64)
}

/// Why `a` cannot be allocated under `limits`, if it cannot.
///
/// wgpu's limits bound buffers but not a texture's bytes; drivers refuse a texture larger than
/// their largest allocation, which wgpu reports as `max_buffer_size` (Vulkan's
/// `maxMemoryAllocationSize`), so textures are held to it too.
pub(crate) fn over_limit(a: &Allocation, limits: &wgpu::Limits) -> Option<String> {
    let dims = |size: &[u32], max: u32, name: &str| {
        size.iter().any(|&d| d > max).then(|| {
            let s: Vec<String> = size.iter().map(u32::to_string).collect();
            format!("{} is {}: beyond the {name} of {max} per side", a.what, s.join("x"))
        })
    };
    let bytes = |max: u64, name: &str| {
        (a.bytes > max).then(|| {
            let need = crate::input::bytes(a.bytes);
            format!("{} needs {need} in one allocation: beyond the {name} of {}", a.what, mib(max))
        })
    };
    match a.shape {
        AllocationKind::Texture3d { size } => {
            dims(&size, limits.max_texture_dimension_3d, "max_texture_dimension_3d")
        }
        AllocationKind::Texture2d { size, layers } => {
            dims(&size, limits.max_texture_dimension_2d, "max_texture_dimension_2d").or_else(|| {
                (layers > limits.max_texture_array_layers).then(|| {
                    format!(
                        "{} has {layers} layers: beyond the max_texture_array_layers of {}",
                        a.what, limits.max_texture_array_layers
                    )
                })
            })
        }
        AllocationKind::Buffer { storage: true } => {
            bytes(limits.max_storage_buffer_binding_size, "max_storage_buffer_binding_size")
        }
        AllocationKind::Buffer { storage: false } => None,
    }
    .or_else(|| bytes(limits.max_buffer_size, "max_buffer_size"))
}

/// `--budget`: a byte count, or one with a `K`, `M` or `G` suffix.
pub fn parse_budget(s: &str) -> std::result::Result<u64, String> {
    crate::input::parse_bytes(s.trim())
        .filter(|&b| b > 0)
        .ok_or_else(|| format!("expected a positive byte count such as 512M or 4G, found `{s}`"))
}

/// The total against `budget`, naming the largest items.
pub(crate) fn over_budget(items: &[(String, u64)], budget: u64) -> Option<String> {
    let total: u64 = items.iter().map(|i| i.1).sum();
    if total <= budget {
        return None;
    }
    let mut largest: Vec<&(String, u64)> = items.iter().collect();
    largest.sort_by_key(|i| std::cmp::Reverse(i.1));
    let list: Vec<String> = largest.iter().take(3).map(|(w, b)| format!("{} {w}", mib(*b))).collect();
    let enough = match total.div_ceil(1 << 20) {
        m if m >= 1024 => format!("{}G", total.div_ceil(1 << 30)),
        m => format!("{m}M"),
    };
    Some(format!(
        "the frame needs {} of GPU memory, over the budget of {} (largest: {}): raise it with \
         --budget {enough} or more, or make the scene smaller",
        mib(total),
        mib(budget),
        list.join("; "),
    ))
}

/// Why a frame cannot be allocated: one allocation over a limit, or the total over the budget
/// (with the driver of the largest allocation, the value most worth changing).
pub(crate) enum Failure {
    Limit(Driver, String),
    Budget(Option<Driver>, String),
}

/// Checks every allocation against `limits`, then the total of `memory` against `budget`.
pub(crate) fn check(
    allocations: &[Allocation],
    memory: &[(String, u64)],
    limits: &wgpu::Limits,
    budget: u64,
) -> Option<Failure> {
    for a in allocations {
        if let Some(msg) = over_limit(a, limits) {
            return Some(Failure::Limit(a.driver.clone(), msg));
        }
    }
    let msg = over_budget(memory, budget)?;
    let driver = allocations.iter().max_by_key(|a| a.bytes).map(|a| a.driver.clone());
    Some(Failure::Budget(driver, msg))
}
