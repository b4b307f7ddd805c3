//! Shared helpers for integration tests: `mod common;` in a test file, then `common::golden::…`.
// Each test binary uses only some helpers.
#![allow(dead_code)]

pub mod adapter;
pub mod golden;
pub mod window;

/// The files under `dir` (recursively) whose extension is one of `extensions`, sorted.
pub fn files_under(dir: &std::path::Path, extensions: &[&str]) -> Vec<std::path::PathBuf> {
    let mut out = Vec::new();
    let mut dirs = vec![dir.to_path_buf()];
    while let Some(d) = dirs.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                dirs.push(path);
            } else if path.extension().is_some_and(|e| extensions.iter().any(|x| e == *x)) {
                out.push(path);
            }
        }
    }
    out.sort();
    out
}

/// Copies a folder tree (tests that edit copies of `wgsl/` and `graphs/`).
pub fn copy_dir(from: &std::path::Path, to: &std::path::Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        let target = to.join(e.file_name());
        if e.file_type().unwrap().is_dir() {
            copy_dir(&e.path(), &target);
        } else {
            std::fs::copy(e.path(), target).unwrap();
        }
    }
}

/// This checkout (the compiled-in manifest folder).
pub fn root() -> std::path::PathBuf {
    std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Runs the `voltex` binary with `VOLTEX_ROOT` set to this checkout.
pub fn voltex(args: &[&str]) -> std::process::Output {
    let mut cmd = std::process::Command::new(env!("CARGO_BIN_EXE_voltex"));
    cmd.args(args).env("VOLTEX_ROOT", root());
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
        cmd.env("XDG_RUNTIME_DIR", std::env::temp_dir());
    }
    cmd.output().unwrap()
}

/// The standard output of a run that must succeed (else its standard error in the panic).
pub fn ok(out: std::process::Output) -> String {
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// A path as `&str` for command arguments.
pub fn s(p: &std::path::Path) -> &str {
    p.to_str().unwrap()
}

/// An empty scratch folder `<temp>/<name>-<pid>` (emptied if a previous run left it).
pub fn scratch_dir(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// One device for the whole test binary; renders are serialised (two cores, one lavapipe).
pub fn ctx() -> &'static std::sync::Mutex<voltex::gpu::GpuContext> {
    static CTX: std::sync::OnceLock<std::sync::Mutex<voltex::gpu::GpuContext>> = std::sync::OnceLock::new();
    CTX.get_or_init(|| {
        std::sync::Mutex::new(
            voltex::gpu::GpuContext::new().expect("a GPU adapter (software Vulkan: mesa-vulkan-drivers)"),
        )
    })
}

/// Default render options at this output size.
pub fn sized(w: u32, h: u32) -> voltex::render::RenderOptions {
    voltex::render::RenderOptions { size: Some((w, h)), ..Default::default() }
}

/// A run's standard error as text.
pub fn stderr(out: &std::process::Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// The names in a folder, sorted.
pub fn entries(dir: &std::path::Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// A RayMarch object's layer as its composite draws it: the colour of `ray_march_state` (its
/// bytes) times the frame's light colour, and the coverage.
pub fn lit_march_state(frame: &voltex::types::FrameParams, bytes: &[u8]) -> Vec<[f64; 4]> {
    let light = frame.light_color.map(|c| c as f64);
    bytemuck::pod_collect_to_vec::<u8, voltex::types::MarchState>(bytes)
        .iter()
        .map(|s| std::array::from_fn(|c| s.color[c] as f64 * if c < 3 { light[c] } else { 1.0 }))
        .collect()
}

/// ((camera eye, look-at), node transform) pairs for RayMarch segment strategies compared with
/// the bounds march: a sphere rotated and scaled unevenly, and the eye inside the object.
pub const TRANSFORMED_AND_INSIDE_VIEWS: [((&str, &str), &str); 2] = [
    (("(0.5, -4.0, 1.0)", "(0.0, 0.0, 0.0)"), "(rotate: (30.0, 10.0, 50.0), scale: (1.5, 0.6, 1.0))"),
    (("(0.0, -0.4, 0.2)", "(0.0, -2.0, 0.0)"), "()"),
];

/// The f16 values of an `Rgba16Float` readback.
pub fn f16s(bytes: &[u8]) -> Vec<f32> {
    bytes
        .chunks_exact(2)
        .map(|b| {
            let h = u16::from_le_bytes([b[0], b[1]]);
            let (sign, exp, frac) = ((h >> 15) as i32, ((h >> 10) & 31) as i32, (h & 1023) as f32);
            let v = match exp {
                0 => frac * 2f32.powi(-24),
                31 => f32::INFINITY,
                _ => (1.0 + frac / 1024.0) * 2f32.powi(exp - 15),
            };
            if sign == 1 {
                -v
            } else {
                v
            }
        })
        .collect()
}
