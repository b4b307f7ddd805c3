use super::*;

fn temp(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("voltex-stack-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn manifest(res: [u32; 3], bit_depth: u32, premultiplied: bool) -> Manifest {
    Manifest {
        format: FORMAT.into(),
        resolution: res,
        bounds: [[0.0; 3], [1.0; 3]],
        opacity_length: 0.25,
        premultiplied,
        lighting: StackLighting::Baked,
        bit_depth,
        slices: Vec::new(),
    }
}

/// Premultiplied voxels whose values sit on the 16-bit grid (so they survive 16 bits exactly).
fn volume(res: [u32; 3]) -> Vec<[f32; 4]> {
    let n = (res[0] * res[1] * res[2]) as usize;
    (0..n)
        .map(|i| {
            let a = ((i * 7919) % 65536) as f32 / 65535.0;
            let c = |k: usize| (((i * k) % 65536) as f32 / 65535.0).min(a);
            [c(31), c(131), c(17), a]
        })
        .collect()
}

fn as_u16(v: &[[f32; 4]]) -> Vec<u16> {
    v.iter().flatten().map(|x| (x * 65535.0).round() as u16).collect()
}

#[test]
fn old_8_bit_stacks_without_a_manifest_load_as_before() {
    let dir = temp("old");
    std::fs::create_dir_all(&dir).unwrap();
    let (w, h, d) = (5u32, 3u32, 4u32);
    let bytes: Vec<u8> = (0..w * h * d * 4).map(|i| (i * 7 % 256) as u8).collect();
    for z in 0..d {
        let layer = &bytes[(z * w * h * 4) as usize..][..(w * h * 4) as usize];
        let rows: Vec<[u8; 4]> = (0..h)
            .rev()
            .flat_map(|y| layer[(y * w * 4) as usize..][..(w * 4) as usize].chunks_exact(4))
            .map(|c| [c[0], c[1], c[2], c[3]])
            .collect();
        crate::io::png::write_rgba8(&dir.join(slice_name(z, "png")), w, h, &rows).unwrap();
    }
    let s = read(&dir).unwrap();
    assert_eq!((s.resolution, s.manifest), ([w, h, d], None));
    // 8-bit values come back as v * 257: exactly v again at 8 bits.
    assert_eq!(s.texels, bytes.iter().map(|&b| b as u16 * 257).collect::<Vec<_>>());
    // A slice of another size is an error naming it.
    crate::io::png::write_rgba8(&dir.join("slice_002.png"), 2, 2, &[[0u8; 4]; 4]).unwrap();
    let e = read(&dir).unwrap_err().to_string();
    assert!(e.contains("slice_002.png") && e.contains("expected 5x3"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
    assert!(read(&dir).unwrap_err().to_string().contains("expected a folder"));
}

#[test]
fn stacks_read_back_at_16_bits_and_in_float() {
    let dir = temp("deep");
    let res = [6, 4, 3];
    let v = volume(res);
    write(&dir, &manifest(res, 16, true), &v).unwrap();
    let s = read(&dir).unwrap();
    assert_eq!(s.texels, as_u16(&v), "16-bit slices hold every value");
    let m = s.manifest.unwrap();
    assert_eq!((m.bit_depth, m.slices.len(), m.opacity_length), (16, 3, 0.25));
    assert!(dir.join("slice_002.png").is_file() && dir.join(MANIFEST).is_file());
    // Straight colour in float EXRs: read back premultiplied, to 16-bit rounding.
    write(&dir, &manifest(res, 32, false), &v).unwrap();
    let s = read(&dir).unwrap();
    assert!(!dir.join("slice_000.png").exists(), "the old stack is replaced as a whole");
    let worst = s.texels.iter().zip(as_u16(&v)).map(|(a, b)| (*a as i32 - b as i32).abs()).max().unwrap();
    assert!(worst <= 2, "{worst}");
    // At 8 bits, what 8 bits hold.
    write(&dir, &manifest(res, 8, true), &v).unwrap();
    let s = read(&dir).unwrap();
    let eight: Vec<u16> = v.iter().flatten().map(|x| (x * 255.0).round() as u16 * 257).collect();
    assert_eq!(s.texels, eight);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_manifests_name_the_file_and_what_is_wrong() {
    let dir = temp("bad");
    let res = [2, 2, 2];
    write(&dir, &manifest(res, 16, true), &volume(res)).unwrap();
    let good = std::fs::read_to_string(dir.join(MANIFEST)).unwrap();
    let cases = [
        (good.replace("\"bit_depth\": 16", "\"bit_depth\": 12"), "bit_depth 12"),
        (good.replace("\"bit_depth\": 16", "\"bit_depth\": 8"), "expected a 8-bit slice"),
        (good.replace(FORMAT, "other"), "expected \"voltex slice stack\""),
        (good.replace("\"slice_001.png\"", "\"../slice_001.png\""), "expected a .png file name"),
        (good.replace("\"slice_001.png\"", "\"slice_000.png\", \"slice_001.png\""), "3 slices listed"),
        (good.replace("\"opacity_length\": 0.25", "\"opacity_length\": -1.0"), "opacity_length -1"),
        (good.replace("\"premultiplied\"", "\"colour\": 1, \"premultiplied\""), "unknown field `colour`"),
        (good.replace("\"slice_001.png\"", "\"slice_009.png\""), "slice_009.png"),
    ];
    for (text, expected) in cases {
        std::fs::write(dir.join(MANIFEST), &text).unwrap();
        let e = read(&dir).unwrap_err().to_string();
        assert!(e.contains(expected) && (e.contains(MANIFEST) || e.contains("slice_")), "{expected}: {e}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
