//! Every file voltex reads from a user (scene, graph, WGSL and its `#include`s, OBJ, PNG, EXR,
//! slice stacks, camera files) goes through here: it must be a regular file (a FIFO, device,
//! folder or socket is named as such before anything is opened, so nothing blocks), no larger than
//! a cap, and it is read through a reader that stops one byte past the cap (a file that grows
//! while it is read, or lies about its size, cannot exhaust memory).
//!
//! Caps: `TEXT_CAP` for text voltex parses whole (scene, graph, WGSL, camera), `ASSET_CAP`
//! for assets (OBJ, PNG, EXR). `VOLTEX_MAX_FILE_BYTES` (bytes, or with a `K`, `M` or `G` suffix)
//! replaces both.
//!
//! This is a layer of its own just above `error`, because `gpu`, `io` and `mesh` all read files
//! and may not import each other.

use crate::error::{line_col, Error, FileLoc, Result};
use std::io::Read;
use std::path::Path;

/// Default cap on text files parsed whole: scene, graph, WGSL, camera files.
pub(crate) const TEXT_CAP: u64 = 16 << 20;
/// Default cap on asset files: OBJ meshes, PNG and EXR images.
pub(crate) const ASSET_CAP: u64 = 256 << 20;
/// The environment variable that replaces both caps.
pub(crate) const CAP_VAR: &str = "VOLTEX_MAX_FILE_BYTES";

/// What a file is read as, which picks its default cap.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Kind {
    Text,
    Asset,
}

/// The cap for `kind`: `VOLTEX_MAX_FILE_BYTES` when set, else the default. A malformed value is
/// an error naming the variable (a typo must not silently lift or keep a limit).
pub(crate) fn cap(kind: Kind) -> Result<u64> {
    match std::env::var(CAP_VAR) {
        Ok(v) if !v.trim().is_empty() => parse_bytes(v.trim()).ok_or_else(|| {
            Error::Invalid(format!(
                "{CAP_VAR}: expected a byte count such as 1000000, 64M or 2G, found `{v}`"
            ))
        }),
        _ => Ok(match kind {
            Kind::Text => TEXT_CAP,
            Kind::Asset => ASSET_CAP,
        }),
    }
}

/// A byte count, or one with a `K`, `M` or `G` suffix (binary units).
pub(crate) fn parse_bytes(v: &str) -> Option<u64> {
    let (digits, shift) = match v.as_bytes().last()?.to_ascii_uppercase() {
        b'K' => (&v[..v.len() - 1], 10),
        b'M' => (&v[..v.len() - 1], 20),
        b'G' => (&v[..v.len() - 1], 30),
        _ => (v, 0),
    };
    digits.trim().parse::<u64>().ok()?.checked_mul(1 << shift)
}

/// `n` bytes for messages: `16 MiB (16777216 bytes)`.
pub(crate) fn bytes(n: u64) -> String {
    const MIB: u64 = 1 << 20;
    if n >= MIB {
        format!("{:.1} MiB ({n} bytes)", n as f64 / MIB as f64)
    } else {
        format!("{n} bytes")
    }
}

/// What a path is when it is not a regular file ("a FIFO", "a folder", ...).
fn what(meta: &std::fs::Metadata) -> Option<&'static str> {
    let t = meta.file_type();
    if t.is_file() {
        return None;
    }
    if t.is_dir() {
        return Some("a folder");
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return Some("a FIFO (named pipe)");
        }
        if t.is_char_device() {
            return Some("a character device");
        }
        if t.is_block_device() {
            return Some("a block device");
        }
        if t.is_socket() {
            return Some("a socket");
        }
    }
    Some("not a regular file")
}

/// Checks that `path` is a regular file within the cap for `kind`, without opening it; returns
/// its size. `role` names what voltex expected ("a scene file", "an OBJ file").
pub(crate) fn check(path: &Path, kind: Kind, role: &str) -> Result<u64> {
    let meta = std::fs::metadata(path).map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound => Error::file(path, format!("expected {role}, but it does not exist")),
        _ => Error::file(path, format!("expected {role}, but cannot read it: {e}")),
    })?;
    if let Some(w) = what(&meta) {
        return Err(Error::file(path, format!("expected {role} (a regular file), found {w}")));
    }
    let cap = cap(kind)?;
    if meta.len() > cap {
        return Err(too_large(path, role, meta.len(), cap));
    }
    Ok(meta.len())
}

fn too_large(path: &Path, role: &str, len: u64, cap: u64) -> Error {
    Error::file(
        path,
        format!("expected {role} of at most {} ({CAP_VAR} raises the cap), found {}", bytes(cap), bytes(len)),
    )
}

/// A reader that fails instead of reading more than `cap` bytes.
pub(crate) struct Bounded<R> {
    inner: R,
    left: u64,
    cap: u64,
}

impl<R: Read> Read for Bounded<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        // One byte past the cap tells a file that grew from one that ends exactly at it.
        let want = (buf.len() as u64).min(self.left + 1) as usize;
        let n = self.inner.read(&mut buf[..want])?;
        if n as u64 > self.left {
            return Err(std::io::Error::other(format!(
                "grew past the cap of {} while being read ({CAP_VAR} raises the cap)",
                bytes(self.cap)
            )));
        }
        self.left -= n as u64;
        Ok(n)
    }
}

/// Opens `path` after [`check`]: non-blocking (a file swapped for a FIFO after the check cannot
/// hang the open) and checked again on the open handle.
pub(crate) fn open(path: &Path, kind: Kind, role: &str) -> Result<Bounded<std::fs::File>> {
    let start = std::time::Instant::now();
    let opened = open_checked(path, kind, role);
    crate::work::file_opened(start);
    opened
}

fn open_checked(path: &Path, kind: Kind, role: &str) -> Result<Bounded<std::fs::File>> {
    check(path, kind, role)?;
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK);
    }
    let file = options.open(path).map_err(|e| Error::file(path, format!("cannot open {role}: {e}")))?;
    let meta = file.metadata().map_err(|e| Error::file(path, format!("cannot read {role}: {e}")))?;
    if let Some(w) = what(&meta) {
        return Err(Error::file(path, format!("expected {role} (a regular file), found {w}")));
    }
    let cap = cap(kind)?;
    if meta.len() > cap {
        return Err(too_large(path, role, meta.len(), cap));
    }
    Ok(Bounded { inner: file, left: cap, cap })
}

/// The bytes of `path` (see [`open`]).
pub(crate) fn read(path: &Path, kind: Kind, role: &str) -> Result<Vec<u8>> {
    let mut reader = open(path, kind, role)?;
    let start = std::time::Instant::now();
    let mut out = Vec::new();
    let read = reader.read_to_end(&mut out);
    crate::work::file_read(start);
    read.map_err(|e| Error::file(path, format!("cannot read {role}: {e}")))?;
    Ok(out)
}

/// The text of `path` (see `open`); invalid UTF-8 is an error at its `line:col`.
pub fn read_text(path: &Path, role: &str) -> Result<String> {
    utf8(path, read(path, Kind::Text, role)?)
}

/// Like [`read_text`] under the asset cap (OBJ files are text but may be large).
pub(crate) fn read_asset_text(path: &Path, role: &str) -> Result<String> {
    utf8(path, read(path, Kind::Asset, role)?)
}

/// `bytes` as UTF-8, or an error at the first invalid byte.
pub(crate) fn utf8(path: &Path, bytes: Vec<u8>) -> Result<String> {
    String::from_utf8(bytes).map_err(|e| {
        let valid = e.utf8_error().valid_up_to();
        let bytes = e.into_bytes();
        // The prefix is valid UTF-8 by construction.
        let prefix = std::str::from_utf8(&bytes[..valid]).unwrap_or("");
        let (line, col) = line_col(prefix, valid);
        Error::at(
            FileLoc::new(path, line, col),
            format!("expected UTF-8 text, found the byte 0x{:02x} (byte offset {valid})", bytes[valid]),
        )
    })
}

/// A map read from a user file with each key at most once (`deserialize_with`): serde's maps
/// let the last duplicate win silently. The error comes as the duplicate key is read, so the
/// parser positions it there.
pub(crate) fn unique_keys<'de, D, V>(
    d: D,
) -> std::result::Result<std::collections::BTreeMap<String, V>, D::Error>
where
    D: serde::Deserializer<'de>,
    V: serde::Deserialize<'de>,
{
    struct Unique<V>(std::marker::PhantomData<V>);
    impl<'de, V: serde::Deserialize<'de>> serde::de::Visitor<'de> for Unique<V> {
        type Value = std::collections::BTreeMap<String, V>;
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str("a map of names")
        }
        fn visit_map<A: serde::de::MapAccess<'de>>(
            self,
            mut map: A,
        ) -> std::result::Result<Self::Value, A::Error> {
            let mut out = std::collections::BTreeMap::new();
            while let Some(key) = map.next_key::<String>()? {
                if out.contains_key(&key) {
                    return Err(serde::de::Error::custom(format!(
                        "the name \"{key}\" is declared twice in this map"
                    )));
                }
                let value = map.next_value()?;
                out.insert(key, value);
            }
            Ok(out)
        }
    }
    d.deserialize_map(Unique(std::marker::PhantomData))
}

/// An asset loaded from the user file `path` by `load` (`key`: what else its result depends on),
/// shared while something holds it: a scene parsed again (the preview's edits) finds the meshes,
/// images and volumes the last good scene holds, with no read, while the file keeps its
/// modification time and length. Only weak references are kept, so nothing stays loaded for
/// the cache's sake; errors are not kept.
pub(crate) fn shared<T: Send + Sync + 'static>(
    path: &Path,
    key: &str,
    load: impl FnOnce() -> Result<T>,
) -> Result<std::sync::Arc<T>> {
    use std::any::{Any, TypeId};
    use std::sync::{Arc, Mutex, Weak};
    type Stamp = (std::time::SystemTime, u64);
    type Entries =
        std::collections::HashMap<(std::path::PathBuf, TypeId, String), (Stamp, Weak<dyn Any + Send + Sync>)>;
    static ASSETS: Mutex<Option<Entries>> = Mutex::new(None);
    // Stamped before the read: an edit made meanwhile is seen by the next load.
    let stamp =
        std::fs::metadata(path).ok().map(|m| (m.modified().unwrap_or(std::time::UNIX_EPOCH), m.len()));
    let id = (path.to_path_buf(), TypeId::of::<T>(), key.to_string());
    if let Some(stamp) = stamp {
        let mut assets = ASSETS.lock().unwrap();
        let assets = assets.get_or_insert_with(Default::default);
        assets.retain(|_, (_, held)| held.strong_count() > 0);
        let found = assets.get(&id).filter(|(s, _)| *s == stamp).and_then(|(_, held)| held.upgrade());
        if let Some(asset) = found.and_then(|a| a.downcast::<T>().ok()) {
            return Ok(asset);
        }
    }
    let asset = Arc::new(load()?);
    if let Some(stamp) = stamp {
        let held: Arc<dyn Any + Send + Sync> = asset.clone();
        ASSETS
            .lock()
            .unwrap()
            .get_or_insert_with(Default::default)
            .insert(id, (stamp, Arc::downgrade(&held)));
    }
    Ok(asset)
}

#[cfg(test)]
mod tests {
    /// A shared asset is loaded once while it is held and its file is unchanged; an edit, or
    /// nothing holding it any more, loads it again.
    #[test]
    fn shared_assets_load_once_while_held_and_unchanged() {
        let dir = std::env::temp_dir().join(format!("voltex-shared-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("a.txt");
        std::fs::write(&path, "one").unwrap();
        let loads = std::cell::Cell::new(0);
        let load = || {
            loads.set(loads.get() + 1);
            read_text(&path, "a test file")
        };
        let a = shared(&path, "", load).unwrap();
        let b = shared(&path, "", load).unwrap();
        assert_eq!((a.as_str(), loads.get()), ("one", 1));
        assert!(std::sync::Arc::ptr_eq(&a, &b));
        // Another key is another asset.
        shared(&path, "k", load).unwrap();
        assert_eq!(loads.get(), 2);
        // Edited (another length): loaded again.
        std::fs::write(&path, "three").unwrap();
        assert_eq!(shared(&path, "", load).unwrap().as_str(), "three");
        assert_eq!(loads.get(), 3);
        // Held by nothing: not kept.
        drop((a, b));
        shared(&path, "", load).unwrap();
        assert_eq!(loads.get(), 4);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    use super::*;

    #[test]
    fn byte_counts_parse() {
        assert_eq!(parse_bytes("1000"), Some(1000));
        assert_eq!(parse_bytes("64M"), Some(64 << 20));
        assert_eq!(parse_bytes("2g"), Some(2 << 30));
        assert_eq!(parse_bytes("x"), None);
        assert_eq!(parse_bytes("99999999999G"), None);
    }

    #[test]
    fn invalid_utf8_is_positioned() {
        let e = utf8(Path::new("s.ron"), b"ab\ncd\xffe".to_vec()).unwrap_err().to_string();
        assert!(e.starts_with("s.ron:2:3: expected UTF-8 text, found the byte 0xff"), "{e}");
    }

    #[test]
    fn bounded_reader_stops_past_the_cap() {
        let mut r = Bounded { inner: std::io::repeat(0), left: 10, cap: 10 };
        let mut out = Vec::new();
        let e = r.read_to_end(&mut out).unwrap_err().to_string();
        assert!(e.contains("grew past the cap of 10 bytes"), "{e}");
        assert!(out.len() <= 10);
    }
}
