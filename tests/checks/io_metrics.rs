//! EXR/PNG round trips, atomic writes, error metrics and the golden harness.

use crate::common;

use std::fs;
use std::path::{Path, PathBuf};

use common::golden::{check_golden, failure_dir, golden_path, Threshold};
use voltex::io::{self, atomic, Image};
use voltex::{metrics, Error};

/// A fresh, empty temporary folder for one test, removed on drop.
struct TempDir(PathBuf);

impl TempDir {
    fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("voltex-io-{}-{name}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).unwrap();
        TempDir(dir)
    }
    fn path(&self, file: &str) -> PathBuf {
        self.0.join(file)
    }
    /// Every entry name in the folder, sorted (catches stray temporary files).
    fn entries(&self) -> Vec<String> {
        let mut v: Vec<String> = fs::read_dir(&self.0)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = fs::remove_dir_all(&self.0);
    }
}

/// A small HDR test image: gradients, an HDR spike and a varying alpha.
fn test_image(w: u32, h: u32) -> Image {
    Image::from_fn(w, h, |x, y| {
        let u = x as f32 / (w - 1) as f32;
        let v = y as f32 / (h - 1) as f32;
        let spike = if x == w / 2 && y == h / 2 { 50.0 } else { 0.0 };
        [u * 2.0 + spike, v, 0.25 + 0.5 * u * v, 1.0 - 0.5 * u]
    })
}

/// Deterministic pseudo-random perturbation of relative size `amount`.
fn perturbed(img: &Image, amount: f32) -> Image {
    let mut state = 0x2545_f491_u32;
    let mut out = img.clone();
    for p in &mut out.pixels {
        for c in p.iter_mut().take(3) {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            let r = (state as f32 / u32::MAX as f32) * 2.0 - 1.0;
            *c = (*c * (1.0 + amount * r) + 0.1 * amount * r).max(0.0);
        }
    }
    out
}

fn assert_file_error(err: Error, path: &Path) {
    match err {
        Error::File { path: p, .. } => assert_eq!(p, path),
        other => panic!("expected Error::File for {}, got {other:?}", path.display()),
    }
}

#[test]
fn exr_roundtrip_keeps_pixels_and_metadata() {
    let dir = TempDir::new("exr-roundtrip");
    let path = dir.path("render.exr");
    let mut img = test_image(7, 5);
    img.set(0, 0, [1e-6, 65504.0 * 4.0, 0.0, 0.0]);
    let meta = [
        ("method", "prism-slicing".to_string()),
        ("quality: slices per prism", "64".to_string()),
        ("adapter", "llvmpipe (LLVM 17, 256 bits) — Vulkan".to_string()),
        ("GPU time (ms)", "12.5".to_string()),
    ];
    io::exr::write(&path, &img, &meta).unwrap();
    assert_eq!(dir.entries(), vec!["render.exr"], "no temporary file left");

    let (back, back_meta) = io::exr::read(&path).unwrap();
    assert_eq!(back, img, "f32 pixels are stored losslessly");
    for (k, v) in &meta {
        // The em dash is outside Latin-1 and is stored as '?'.
        let want = v.replace('—', "?");
        assert!(
            back_meta.iter().any(|(bk, bv)| bk == k && *bv == want),
            "{k} = {want} missing in {back_meta:?}"
        );
    }

    // Overwriting replaces the content atomically.
    let img2 = Image::filled(3, 2, [0.5, 0.25, 0.125, 1.0]);
    io::exr::write(&path, &img2, &[]).unwrap();
    assert_eq!(io::exr::read(&path).unwrap().0, img2);
    assert_eq!(dir.entries(), vec!["render.exr"]);
}

#[test]
fn exr_rgb_without_alpha_reads_alpha_one() {
    let dir = TempDir::new("exr-rgb");
    let path = dir.path("rgb.exr");
    exr::prelude::write_rgb_file(&path, 3, 2, |x, y| (x as f32, y as f32, 0.5f32)).unwrap();
    let (img, _) = io::exr::read(&path).unwrap();
    assert_eq!((img.width, img.height), (3, 2));
    assert_eq!(img.get(2, 1), [2.0, 1.0, 0.5, 1.0]);
}

#[test]
fn exr_read_errors_are_file_errors() {
    let dir = TempDir::new("exr-errors");
    let missing = dir.path("missing.exr");
    assert_file_error(io::exr::read(&missing).unwrap_err(), &missing);

    let text = dir.path("not.exr");
    fs::write(&text, "this is not an EXR file").unwrap();
    let err = io::exr::read(&text).unwrap_err();
    assert!(err.to_string().contains("EXR"), "{err}");
    assert_file_error(err, &text);

    // A luminance-only EXR has no R, G, B.
    let luma = dir.path("luma.exr");
    let channels = exr::prelude::SpecificChannels::build().with_channel("Y").with_pixel_fn(|_| (0.5f32,));
    exr::prelude::WritableImage::write(&exr::prelude::Image::from_channels((2, 2), channels))
        .to_file(&luma)
        .unwrap();
    let err = io::exr::read(&luma).unwrap_err();
    assert!(err.to_string().contains("R, G, B"), "{err}");
    assert_file_error(err, &luma);
}

#[test]
fn exr_rejects_bad_metadata_keys_before_writing() {
    let dir = TempDir::new("exr-keys");
    let path = dir.path("k.exr");
    let img = Image::new(2, 2);
    for key in ["", "owner", "comments", "ключ"] {
        let err = io::exr::write(&path, &img, &[(key, "x".into())]).unwrap_err();
        assert!(matches!(err, Error::Invalid(_)), "{key:?}: {err:?}");
    }
    assert!(dir.entries().is_empty());
}

#[test]
fn png_tonemapped_and_rgba8_roundtrip() {
    let dir = TempDir::new("png");
    let img = test_image(6, 4);
    let path = dir.path("preview.png");
    io::png::write_tonemapped(&path, &img).unwrap();
    let (w, h, px) = io::png::read_rgba8(&path).unwrap();
    assert_eq!((w, h), (6, 4));
    let want = img.to_srgb8();
    for (got, want) in px.iter().zip(&want) {
        assert_eq!(got[..3], want[..3]);
        assert_eq!(got[3], 255, "previews are opaque");
    }
    // The HDR spike saturates, black stays black.
    assert!(px[2 * 6 + 3][0] >= 250);
    assert_eq!(io::png::read_rgba8(&path).unwrap().2[0][1], 0);

    let heat: Vec<[u8; 4]> = (0..12u8).map(|i| [i * 20, 255 - i, i, i * 10]).collect();
    let hp = dir.path("heat.png");
    io::png::write_rgba8(&hp, 4, 3, &heat).unwrap();
    assert_eq!(io::png::read_rgba8(&hp).unwrap(), (4, 3, heat.clone()));
    assert!(matches!(io::png::write_rgba8(&hp, 5, 3, &heat), Err(Error::Invalid(_))));
    assert_eq!(dir.entries(), vec!["heat.png", "preview.png"]);

    let bad = dir.path("bad.png");
    fs::write(&bad, b"\x89PNG nope").unwrap();
    assert_file_error(io::png::read_rgba8(&bad).unwrap_err(), &bad);
}

#[test]
fn atomic_write_failure_leaves_target_untouched() {
    let dir = TempDir::new("atomic");
    let target = dir.path("out.exr");
    fs::write(&target, "old content").unwrap();
    let err = atomic::write_atomic(&target, |tmp| {
        assert_eq!(tmp.parent(), target.parent(), "temporary file sits beside the target");
        fs::write(tmp, "half-writ").unwrap();
        Err(Error::Gpu("device lost".into()))
    })
    .unwrap_err();
    assert!(matches!(err, Error::Gpu(_)));
    assert_eq!(fs::read_to_string(&target).unwrap(), "old content");
    assert_eq!(dir.entries(), vec!["out.exr"], "temporary file removed");

    // A writer that succeeds replaces the target.
    atomic::write_atomic(&target, |tmp| fs::write(tmp, "new content").map_err(|e| Error::file(tmp, e)))
        .unwrap();
    assert_eq!(fs::read_to_string(&target).unwrap(), "new content");

    // A writer that "succeeds" without writing anything is an error, target kept.
    assert!(atomic::write_atomic(&target, |_| Ok(())).is_err());
    assert_eq!(fs::read_to_string(&target).unwrap(), "new content");
    assert_eq!(dir.entries(), vec!["out.exr"]);
}

#[test]
fn missing_output_folder_fails_before_writing() {
    let dir = TempDir::new("missing-dir");
    let sub = dir.path("no/such");
    let target = sub.join("out.exr");
    let mut called = false;
    let err = atomic::write_atomic(&target, |_| {
        called = true;
        Ok(())
    })
    .unwrap_err();
    assert!(!called, "writer must not run");
    assert_file_error(err, &sub);
    assert_file_error(io::exr::write(&target, &Image::new(2, 2), &[]).unwrap_err(), &sub);
    assert_file_error(io::png::write_tonemapped(&target, &Image::new(2, 2)).unwrap_err(), &sub);
    assert!(dir.entries().is_empty(), "no folder was created");

    assert_file_error(atomic::check_writable_dir(&sub).unwrap_err(), &sub);
    let file = dir.path("plain-file");
    fs::write(&file, "x").unwrap();
    assert_file_error(atomic::check_writable_dir(&file).unwrap_err(), &file);
    atomic::check_writable_dir(&dir.0).unwrap();
    assert_eq!(dir.entries(), vec!["plain-file"], "probe file removed");
}

#[test]
fn metrics_are_zero_for_identical_images_and_grow_with_error() {
    let img = test_image(32, 24);
    assert_eq!(metrics::relative_rmse(&img, &img).unwrap(), 0.0);
    assert_eq!(metrics::max_abs_diff(&img, &img).unwrap(), 0.0);
    let f0 = metrics::flip(&img, &img).unwrap();
    assert_eq!(f0.mean, 0.0);
    assert_eq!(f0.map.len(), 32 * 24);

    let small = perturbed(&img, 0.02);
    let large = perturbed(&img, 0.3);
    let (r1, r2) =
        (metrics::relative_rmse(&small, &img).unwrap(), metrics::relative_rmse(&large, &img).unwrap());
    assert!(0.0 < r1 && r1 < r2, "relative RMSE {r1} then {r2}");
    let (f1, f2) = (metrics::flip(&small, &img).unwrap().mean, metrics::flip(&large, &img).unwrap().mean);
    assert!(0.0 < f1 && f1 < f2, "FLIP {f1} then {f2}");
    assert!(f1 < 0.1, "2% noise is a small FLIP error, got {f1}");
    assert!(metrics::max_abs_diff(&large, &img).unwrap() > 0.0);
    assert_eq!(metrics::count_nonfinite(&img), 0);
}

#[test]
fn flip_of_a_known_pair_is_in_a_sane_range() {
    // Black against white: close to the largest possible error.
    let black = Image::filled(16, 16, [0.0, 0.0, 0.0, 1.0]);
    let white = Image::filled(16, 16, [100.0, 100.0, 100.0, 1.0]);
    let f = metrics::flip(&black, &white).unwrap();
    assert!((0.6..=1.0).contains(&f.mean), "black vs white mean FLIP {}", f.mean);
    assert!(f.map.iter().all(|v| (0.0..=1.0).contains(v)));
    // A red/green swap of a mid-grey-ish image: clearly visible but far from maximal.
    let a = Image::filled(16, 16, [0.4, 0.2, 0.2, 1.0]);
    let b = Image::filled(16, 16, [0.2, 0.4, 0.2, 1.0]);
    let f = metrics::flip(&a, &b).unwrap().mean;
    assert!((0.1..0.9).contains(&f), "red vs green mean FLIP {f}");
}

#[test]
fn size_mismatch_is_an_error() {
    let a = Image::new(4, 4);
    let b = Image::new(4, 3);
    assert!(metrics::relative_rmse(&a, &b).is_err());
    assert!(metrics::flip(&a, &b).is_err());
    assert!(metrics::max_abs_diff(&a, &b).is_err());
    assert!(metrics::relative_error_map(&a, &b).is_err());
}

#[test]
fn golden_harness_passes_fails_and_explains() {
    let updating = std::env::var("VOLTEX_UPDATE_GOLDEN").is_ok_and(|v| v == "1");
    // A committed 8x6 reference.
    let img = test_image(8, 6);
    check_golden("io_metrics_gradient", &img, Threshold::RelRmse(1e-6));
    check_golden("io_metrics_gradient", &img, Threshold::Flip(0.0));
    if updating {
        return;
    }

    let bad = perturbed(&img, 0.5);
    let msg = std::panic::catch_unwind(|| check_golden("io_metrics_gradient", &bad, Threshold::Flip(0.01)))
        .expect_err("a perturbed image must fail");
    let msg = msg.downcast_ref::<String>().unwrap();
    assert!(msg.contains("mean FLIP") && msg.contains("0.01"), "{msg}");
    for suffix in ["actual.png", "actual.exr", "diff.png"] {
        let p = failure_dir().join(format!("io_metrics_gradient.{suffix}"));
        assert!(msg.contains(&p.display().to_string()), "{msg}");
        assert!(p.is_file(), "{} written", p.display());
    }

    let missing = "io_metrics_no_such_reference";
    assert!(!golden_path(missing).exists());
    let msg = std::panic::catch_unwind(|| check_golden(missing, &img, Threshold::Flip(0.1)))
        .expect_err("missing reference must fail");
    let msg = msg.downcast_ref::<String>().unwrap();
    assert!(msg.contains("VOLTEX_UPDATE_GOLDEN=1"), "{msg}");
}
