//! CPU twin (f64) of `wgsl/bake/bake_transfer.wgsl`: transfer functions sampled into tables of
//! `TRANSFER_SIZE` entries over [0, 1].

use crate::types::{TransferFunction, TransferPoint};

/// Entries per table (mirrors `TRANSFER_SIZE` in wgsl/shared/transfer.wgsl).
pub(crate) const TRANSFER_SIZE: usize = 256;
/// `TransferFunction::kind`: a cubic Hermite curve through points with slopes.
pub(crate) const HERMITE: u32 = 0;
/// `TransferFunction::kind`: straight lines between points.
pub(crate) const LINEAR: u32 = 1;

/// The function at `x`: constant beyond its first and last points, a Hermite or linear segment
/// between them (Hermite clamped to [0, 1]).
pub(crate) fn transfer_curve(f: &TransferFunction, points: &[TransferPoint], x: f64) -> f64 {
    let p = &points[f.first as usize..(f.first + f.count) as usize];
    let (first, last) = (p[0], p[p.len() - 1]);
    if x <= first.x as f64 {
        return first.y as f64;
    }
    if x >= last.x as f64 {
        return last.y as f64;
    }
    let k = (1..p.len() - 1).rev().find(|&j| p[j].x as f64 <= x).unwrap_or(0);
    let (a, b) = (p[k], p[k + 1]);
    let h = b.x as f64 - a.x as f64;
    let t = (x - a.x as f64) / h;
    let (ay, by) = (a.y as f64, b.y as f64);
    if f.kind == LINEAR {
        return ay + (by - ay) * t;
    }
    let (t2, t3) = (t * t, t * t * t);
    let y = (2.0 * t3 - 3.0 * t2 + 1.0) * ay
        + (t3 - 2.0 * t2 + t) * h * a.slope as f64
        + (3.0 * t2 - 2.0 * t3) * by
        + (t3 - t2) * h * b.slope as f64;
    y.clamp(0.0, 1.0)
}

/// Every function's table, one after the other.
pub fn bake_transfer(functions: &[TransferFunction], points: &[TransferPoint]) -> Vec<f64> {
    let mut out = Vec::with_capacity(functions.len() * TRANSFER_SIZE);
    for f in functions {
        for i in 0..TRANSFER_SIZE {
            out.push(transfer_curve(f, points, i as f64 / (TRANSFER_SIZE - 1) as f64));
        }
    }
    out
}
