// Transfer functions as tables of TRANSFER_SIZE samples over [0, 1] (the paper's 1D textures),
// filled by bake_transfer.wgsl and read with linear interpolation. Reads the kernel's
// `transfer_tables`. CPU twin: src/cpu/hypertexture.rs (same names).

const TRANSFER_SIZE: u32 = 256u;

// Table `table` at `x` (clamped to [0, 1]).
fn transfer_lookup(table: u32, x: f32) -> f32 {
    let u = clamp(x, 0.0, 1.0) * f32(TRANSFER_SIZE - 1u);
    let i = min(u32(u), TRANSFER_SIZE - 2u);
    let base = table * TRANSFER_SIZE + i;
    return mix(transfer_tables[base], transfer_tables[base + 1u], u - f32(i));
}
