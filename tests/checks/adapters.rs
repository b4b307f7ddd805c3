//! The GPU tests state what they assume of their adapter (`tests/common/adapter.rs`, after wgpu's
//! expectations): every module of `tests/gpu/` that opens the device declares its `ADAPTER` and
//! opens it through `gpu!` or `adapter::device`, never `common::ctx()` or a device of its own.
//! And the matching itself: features, limits, deviations by adapter name and type.

use crate::common::adapter::{Adapter, Deviation, Effect, Expectations, Limit};
use std::path::PathBuf;

#[test]
fn every_gpu_test_module_declares_its_adapter() {
    let all =
        crate::common::files_under(&PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/gpu"), &["rs"]);
    let mut opening = 0;
    let mut wrong = Vec::new();
    for file in &all {
        let text = std::fs::read_to_string(file).unwrap();
        let name = file.display().to_string();
        for (n, line) in text.lines().enumerate() {
            let code = line.trim_start();
            if !code.starts_with("//") && (code.contains("ctx().lock()") || code.contains("GpuContext::new("))
            {
                wrong.push(format!("{name}:{}: opens the device without its expectations: {code}", n + 1));
            }
        }
        if text.contains("gpu!(ADAPTER)")
            || text.contains("adapter::device(&ADAPTER)")
            || text.contains("adapter::open(&ADAPTER)")
        {
            opening += 1;
            if !text.contains("const ADAPTER: Expectations") {
                wrong.push(format!("{name}: opens the device with `ADAPTER` but declares none"));
            }
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
    assert!(opening >= 25, "only {opening} modules open the device");
}

fn adapter(name: &str, device_type: wgpu::DeviceType) -> wgpu::AdapterInfo {
    wgpu::AdapterInfo {
        name: name.into(),
        vendor: 0,
        device: 0,
        device_type,
        device_pci_bus_id: String::new(),
        driver: String::new(),
        driver_info: String::new(),
        backend: wgpu::Backend::Vulkan,
        subgroup_min_size: 4,
        subgroup_max_size: 64,
        transient_saves_memory: Some(false),
        limit_bucket: None,
    }
}

#[test]
fn expectations_match_features_limits_and_adapters() {
    const E: Expectations = Expectations {
        features: wgpu::Features::FLOAT32_BLENDABLE,
        limits: &[Limit {
            name: "max_texture_dimension_3d",
            of: |l| l.max_texture_dimension_3d as u64,
            at_least: 4096,
        }],
        deviations: &[
            Deviation {
                adapter: Adapter { name: "llvmpipe", device_type: Some(wgpu::DeviceType::Cpu) },
                effect: Effect::Tolerance("max", 0.02),
                why: "8-bit filter weights",
            },
            Deviation {
                adapter: Adapter { name: "Broken", device_type: None },
                effect: Effect::Skip,
                why: "a driver bug",
            },
        ],
    };
    let big = wgpu::Limits { max_texture_dimension_3d: 4096, ..Default::default() };
    let llvmpipe = adapter("llvmpipe (LLVM 15.0.6, 256 bits)", wgpu::DeviceType::Cpu);
    let f32_blend = wgpu::Features::FLOAT32_BLENDABLE;
    assert_eq!(E.unmet_on(&llvmpipe, f32_blend, &big), None);
    let lacks = E.unmet_on(&llvmpipe, wgpu::Features::empty(), &big).unwrap();
    assert!(lacks.contains("FLOAT32_BLENDABLE"), "{lacks}");
    let small = E.unmet_on(&llvmpipe, f32_blend, &wgpu::Limits::default()).unwrap();
    assert!(small.contains("max_texture_dimension_3d is 2048, the test needs 4096"), "{small}");
    let broken =
        E.unmet_on(&adapter("BROKEN GPU 9", wgpu::DeviceType::DiscreteGpu), f32_blend, &big).unwrap();
    assert!(broken.contains("a driver bug"), "{broken}");
    // A deviation matches name and type together.
    assert_eq!(E.tolerance_on(&llvmpipe, "max", 0.01), 0.02);
    assert_eq!(E.tolerance_on(&llvmpipe, "mean", 1e-3), 1e-3);
    let gpu_named_llvmpipe = adapter("llvmpipe", wgpu::DeviceType::DiscreteGpu);
    assert_eq!(E.tolerance_on(&gpu_named_llvmpipe, "max", 0.01), 0.01);
    assert_eq!(
        Expectations::DEFAULTS.unmet_on(&llvmpipe, wgpu::Features::empty(), &wgpu::Limits::default()),
        None
    );
}
