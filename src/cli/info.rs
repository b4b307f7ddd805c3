//! `voltex info`: the adapter and what voltex uses of it.

use voltex::gpu::GpuContext;
use voltex::Result;

pub fn run() -> Result<()> {
    GpuContext::new().map(|ctx| print!("{}", ctx.describe()))
}
