//! Files that are not what a path promises: FIFOs, devices, folders, sockets, a sparse file of
//! 6 GiB, links to them, missing and empty files; made once per target in a scratch folder.

use std::path::{Path, PathBuf};

/// What a path the scene names turns out to be.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Special {
    Fifo,
    /// A link to `/dev/zero` (reads never end).
    Device,
    Folder,
    /// 6 GiB, sparse: no disk is used, and nothing may read it.
    Sparse,
    Socket,
    LinkToFifo,
    Dangling,
    Missing,
    Empty,
}

pub const ALL: [Special; 9] = [
    Special::Fifo,
    Special::Device,
    Special::Folder,
    Special::Sparse,
    Special::Socket,
    Special::LinkToFifo,
    Special::Dangling,
    Special::Missing,
    Special::Empty,
];

impl Special {
    pub fn name(self) -> String {
        format!("{self:?}").to_lowercase()
    }
}

fn mkfifo(path: &Path) {
    use std::os::unix::ffi::OsStrExt;
    let c = std::ffi::CString::new(path.as_os_str().as_bytes()).unwrap();
    // SAFETY: a valid NUL-terminated path.
    let rc = unsafe { libc::mkfifo(c.as_ptr(), 0o644) };
    assert_eq!(rc, 0, "mkfifo {}", path.display());
}

/// Makes `path` a file of kind `kind`.
pub fn make(kind: Special, path: &Path) {
    use std::os::unix::fs::symlink;
    match kind {
        Special::Fifo => mkfifo(path),
        Special::Device => symlink("/dev/zero", path).unwrap(),
        Special::Folder => std::fs::create_dir_all(path).unwrap(),
        Special::Sparse => std::fs::File::create(path).unwrap().set_len(6 << 30).unwrap(),
        Special::Socket => drop(std::os::unix::net::UnixListener::bind(path).unwrap()),
        Special::LinkToFifo => {
            let mut target = path.as_os_str().to_owned();
            target.push(".target");
            let target = PathBuf::from(target);
            mkfifo(&target);
            symlink(&target, path).unwrap();
        }
        Special::Dangling => symlink(path.with_extension("nowhere"), path).unwrap(),
        Special::Missing => {}
        Special::Empty => drop(std::fs::File::create(path).unwrap()),
    }
}

/// A scratch folder, removed when dropped.
pub struct Scratch(pub PathBuf);

impl std::ops::Deref for Scratch {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// An empty scratch folder `voltex-fuzz-<name>-<pid>` in memory (`/dev/shm`) where there is one:
/// targets rewrite files for every input, and on a disk each truncation may wait for a discard.
pub fn scratch(name: &str) -> Scratch {
    let shm = Path::new("/dev/shm");
    let base = if shm.is_dir() { shm.to_path_buf() } else { std::env::temp_dir() };
    let dir = base.join(format!("voltex-fuzz-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    match std::fs::create_dir_all(&dir) {
        Ok(()) => Scratch(dir),
        Err(_) => {
            let dir = std::env::temp_dir().join(format!("voltex-fuzz-{name}-{}", std::process::id()));
            std::fs::create_dir_all(&dir).unwrap();
            Scratch(dir)
        }
    }
}

/// Under `dir`: `KIND.EXT` for every kind and extension, and `stack_KIND/slice_000.png` (a
/// slice stack whose first slice is of that kind).
pub fn populate(dir: &Path, exts: &[&str]) {
    for kind in ALL {
        for ext in exts {
            make(kind, &dir.join(format!("{}.{ext}", kind.name())));
        }
        let stack = dir.join(format!("stack_{}", kind.name()));
        std::fs::create_dir_all(&stack).unwrap();
        make(kind, &stack.join("slice_000.png"));
    }
}

/// An OBJ of `triangles` triangles (rounded up to even): a grid of quads in the unit square.
pub fn grid_obj(triangles: usize) -> String {
    use std::fmt::Write;
    let quads = triangles.div_ceil(2).max(1);
    let cols = (quads as f64).sqrt().ceil() as usize;
    let rows = quads.div_ceil(cols);
    let mut s = String::with_capacity(quads * 40);
    for j in 0..=rows {
        for i in 0..=cols {
            let _ = writeln!(s, "v {} {} 0", i as f64 / cols as f64, j as f64 / rows as f64);
        }
    }
    let v = |i: usize, j: usize| j * (cols + 1) + i + 1;
    for q in 0..quads {
        let (i, j) = (q % cols, q / cols);
        let _ = writeln!(
            s,
            "f {} {} {}\nf {} {} {}",
            v(i, j),
            v(i + 1, j),
            v(i + 1, j + 1),
            v(i, j),
            v(i + 1, j + 1),
            v(i, j + 1)
        );
    }
    s
}
