//! The file as vdb-rs reads one grid of it: the bytes with the walk's splices applied (a vector
//! background narrowed to one float, an unknown map replaced by the identity, ...). The splices
//! are switched on only after vdb-rs has read the descriptors, which it finds by absolute offset.

use std::io::{Read, Seek, SeekFrom};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use super::walk::Splice;

/// A reader over `bytes` that reads the spliced stream once its [`Switch`] is turned on.
pub(crate) struct Spliced {
    bytes: Arc<[u8]>,
    splices: Vec<Splice>,
    on: Arc<AtomicBool>,
    /// Position in the stream as read (spliced or not).
    pos: u64,
}

impl Spliced {
    /// The reader, and the switch that turns `splices` (in file order) on.
    pub(crate) fn new(bytes: Arc<[u8]>, splices: Vec<Splice>) -> (Self, Switch) {
        let on = Arc::new(AtomicBool::new(false));
        let switch = Switch {
            shifts: splices
                .iter()
                .map(|s| (s.end, s.bytes.len() as i64 - (s.end - s.start) as i64))
                .collect(),
            on: on.clone(),
        };
        (Spliced { bytes, splices, on, pos: 0 }, switch)
    }

    /// The piece of the stream from `pos` on: bytes of the file or of a splice.
    fn piece(&self, pos: u64) -> &[u8] {
        let mut shift: i64 = 0;
        if self.on.load(Ordering::Relaxed) {
            for s in &self.splices {
                let start = (s.start as i64 + shift) as u64;
                if pos < start {
                    return slice(&self.bytes, (pos as i64 - shift) as usize, s.start as usize);
                }
                if pos < start + s.bytes.len() as u64 {
                    return &s.bytes[(pos - start) as usize..];
                }
                shift += s.bytes.len() as i64 - (s.end - s.start) as i64;
            }
        }
        slice(&self.bytes, (pos as i64 - shift).max(0) as usize, self.bytes.len())
    }
}

fn slice(bytes: &[u8], from: usize, to: usize) -> &[u8] {
    bytes.get(from.min(to)..to).unwrap_or(&[])
}

/// Turns the splices on, and maps file offsets to positions in the spliced stream.
pub(crate) struct Switch {
    /// Each splice's end in the file and how much longer it makes the stream.
    shifts: Vec<(u64, i64)>,
    on: Arc<AtomicBool>,
}

impl Switch {
    /// Where file offset `real` (outside any splice) lies in the spliced stream.
    pub(crate) fn position(&self, real: u64) -> u64 {
        let shift: i64 = self.shifts.iter().filter(|(end, _)| *end <= real).map(|(_, d)| d).sum();
        (real as i64 + shift) as u64
    }

    pub(crate) fn on(self) {
        self.on.store(true, Ordering::Relaxed);
    }
}

impl Read for Spliced {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let piece = self.piece(self.pos);
        let n = piece.len().min(buf.len());
        buf[..n].copy_from_slice(&piece[..n]);
        self.pos += n as u64;
        Ok(n)
    }
}

impl Seek for Spliced {
    fn seek(&mut self, to: SeekFrom) -> std::io::Result<u64> {
        let pos = match to {
            SeekFrom::Start(p) => Some(p),
            SeekFrom::Current(d) => self.pos.checked_add_signed(d),
            SeekFrom::End(_) => None,
        };
        self.pos = pos.ok_or_else(|| std::io::Error::other("seek out of range"))?;
        Ok(self.pos)
    }
}
