//! A vdb-rs tree as voltex keeps it: its leaves and tiles by leaf coordinate ([`Blocks`]), the
//! inactive values vdb-rs does not restore put back (a fog's background; a level set's signs by
//! OpenVDB's signed flood fill), and a level set turned into density.

use std::collections::HashMap;

use bitvec::prelude::*;
use glam::IVec3;

/// Voxels of one leaf, in OpenVDB's order (`x * 64 + y * 8 + z`), or a tile of one value.
#[derive(Debug, Clone)]
pub(crate) enum Block<T> {
    Voxels(Box<[T]>),
    Tile(T),
}

/// Leaves and leaf-sized tiles by leaf coordinate (voxel index >> 3); absent is background.
pub(crate) type Blocks<T> = HashMap<IVec3, Block<T>>;

fn local(offset: usize, log2: u32) -> IVec3 {
    let m = (1 << log2) - 1;
    IVec3::new((offset >> (2 * log2)) as i32, ((offset >> log2) & m) as i32, (offset & m) as i32)
}

/// How values enter the blocks: a fog keeps active values (inactive ones are the background,
/// 0); a level set keeps every voxel and the inside tiles (signs filled first).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Keep {
    Active,
    LevelSet,
}

/// Most blocks (leaves and leaf-sized tiles, 2^21: 2^30 voxels) a grid may hold once read.
pub(crate) const MAX_BLOCKS: usize = 1 << 21;

fn too_many(blocks: usize) -> String {
    format!(
        "its leaves and tiles cover more than {blocks} blocks of 8^3 voxels (at most {MAX_BLOCKS}, {} voxels)",
        (MAX_BLOCKS as u64) << 9
    )
}

/// The grid's leaves and tiles as blocks, at most [`MAX_BLOCKS`]. Root tiles are the caller's
/// (the walk reads them).
pub(crate) fn blocks<T: Copy + Default>(
    tree: &vdb_rs::Tree<T>,
    keep: Keep,
    inside: impl Fn(&T) -> bool,
) -> Result<Blocks<T>, String> {
    let mut out = Blocks::new();
    for n5 in &tree.root_nodes {
        let o5 = IVec3::new(n5.origin.x, n5.origin.y, n5.origin.z);
        for i5 in 0..32768 {
            let at5 = o5 + (local(i5, 5) << 7);
            if n5.child_mask[i5] {
                let Some(n4) = n5.nodes.get(&(i5 as u32)) else { continue };
                for i4 in 0..4096 {
                    let key = (at5 >> 3) + local(i4, 4);
                    if n4.child_mask[i4] {
                        let Some(leaf) = n4.nodes.get(&(i4 as u32)) else { continue };
                        let voxels: Box<[T]> = (0..512)
                            .map(|i| match (keep, leaf.value_mask[i]) {
                                (Keep::Active, false) => T::default(),
                                _ => leaf.buffer.get(i).copied().unwrap_or_default(),
                            })
                            .collect();
                        out.insert(key, Block::Voxels(voxels));
                    } else if tile(keep, n4.value_mask[i4], n4.data.get(i4), &inside) {
                        out.insert(key, Block::Tile(n4.data[i4]));
                    }
                }
            } else if tile(keep, n5.value_mask[i5], n5.data.get(i5), &inside) {
                if out.len() + 4096 > MAX_BLOCKS {
                    return Err(too_many(out.len() + 4096));
                }
                for i4 in 0..4096 {
                    out.insert((at5 >> 3) + local(i4, 4), Block::Tile(n5.data[i5]));
                }
            }
            if out.len() > MAX_BLOCKS {
                return Err(too_many(out.len()));
            }
        }
    }
    Ok(out)
}

fn tile<T>(keep: Keep, active: bool, value: Option<&T>, inside: &impl Fn(&T) -> bool) -> bool {
    match value {
        None => false,
        Some(v) => active || (keep == Keep::LevelSet && inside(v)),
    }
}

/// OpenVDB's signed flood fill (`tools::signedFloodFill`), on the values vdb-rs left: every
/// inactive voxel and tile of a level set becomes `-background` inside and `background`
/// outside, its side taken from the active values and children before it in scan order.
pub(crate) fn signed_flood_fill(tree: &mut vdb_rs::Tree<f32>, background: f32) {
    let (inside, outside) = (-background.abs(), background.abs());
    for n5 in &mut tree.root_nodes {
        for n4 in n5.nodes.values_mut() {
            for leaf in n4.nodes.values_mut() {
                fill_leaf(&mut leaf.buffer, &leaf.value_mask, inside, outside);
            }
            let ends: HashMap<u32, (f32, f32)> =
                n4.nodes.iter().map(|(i, l)| (*i, (l.buffer[0], l.buffer[511]))).collect();
            fill_node(&mut n4.data, &n4.child_mask, &n4.value_mask, 4, &ends, inside, outside);
        }
        let ends: HashMap<u32, (f32, f32)> = n5
            .nodes
            .iter()
            .map(|(i, n4)| {
                let end = |k: usize, leaf_end: usize| match n4.nodes.get(&(k as u32)) {
                    Some(l) if n4.child_mask[k] => l.buffer[leaf_end],
                    _ => n4.data[k],
                };
                (*i, (end(0, 0), end(4095, 511)))
            })
            .collect();
        fill_node(&mut n5.data, &n5.child_mask, &n5.value_mask, 5, &ends, inside, outside);
    }
}

fn fill_leaf(buf: &mut [f32], mask: &BitSlice<u64, Lsb0>, inside: f32, outside: f32) {
    if buf.len() < 512 {
        return;
    }
    let Some(first) = mask.first_one() else {
        let v = if buf[0] < 0.0 { inside } else { outside };
        buf.fill(v);
        return;
    };
    let mut x_in = buf[first] < 0.0;
    for x in 0..8 {
        let x00 = x << 6;
        if mask[x00] {
            x_in = buf[x00] < 0.0;
        }
        let mut y_in = x_in;
        for y in 0..8 {
            let xy0 = x00 + (y << 3);
            if mask[xy0] {
                y_in = buf[xy0] < 0.0;
            }
            let mut z_in = y_in;
            for i in xy0..xy0 + 8 {
                if mask[i] {
                    z_in = buf[i] < 0.0;
                } else {
                    buf[i] = if z_in { inside } else { outside };
                }
            }
        }
    }
}

/// An internal node's inactive tiles; `ends`: each child's first and last value.
fn fill_node(
    data: &mut [f32],
    children: &BitSlice<u64, Lsb0>,
    active: &BitSlice<u64, Lsb0>,
    log2: u32,
    ends: &HashMap<u32, (f32, f32)>,
    inside: f32,
    outside: f32,
) {
    let n = 1usize << log2;
    if data.len() < n * n * n {
        return;
    }
    let last = |i: usize| ends.get(&(i as u32)).map(|e| e.1 < 0.0);
    let Some(first) = children.first_one() else {
        let v = if data[0] < 0.0 { inside } else { outside };
        for i in (0..data.len()).filter(|&i| !active[i]) {
            data[i] = v;
        }
        return;
    };
    let mut x_in = ends.get(&(first as u32)).is_some_and(|e| e.0 < 0.0);
    for x in 0..n {
        let x00 = x << (2 * log2);
        if children[x00] {
            x_in = last(x00).unwrap_or(x_in);
        }
        let mut y_in = x_in;
        for y in 0..n {
            let xy0 = x00 + (y << log2);
            if children[xy0] {
                y_in = last(xy0).unwrap_or(y_in);
            }
            let mut z_in = y_in;
            for i in xy0..xy0 + n {
                if children[i] {
                    z_in = last(i).unwrap_or(z_in);
                } else if !active[i] {
                    data[i] = if z_in { inside } else { outside };
                }
            }
        }
    }
}

/// A level set's signed distances (world units) as density: 1 inside, 0 outside, linear over a
/// band of width `band` (world units) centred on the surface.
pub(crate) fn level_set_density(phi: f32, band: f32) -> f32 {
    (0.5 - phi / band).clamp(0.0, 1.0)
}

/// Applies `f` to every value of `blocks`.
pub(crate) fn map<T: Copy, U>(blocks: Blocks<T>, f: impl Fn(T) -> U) -> Blocks<U> {
    blocks
        .into_iter()
        .map(|(k, b)| {
            let b = match b {
                Block::Voxels(v) => Block::Voxels(v.iter().map(|&x| f(x)).collect()),
                Block::Tile(v) => Block::Tile(f(v)),
            };
            (k, b)
        })
        .collect()
}

/// The first value of `blocks` failing `ok`, with its index coordinate.
pub fn find<T: Copy>(blocks: &Blocks<T>, ok: impl Fn(&T) -> bool) -> Option<(IVec3, T)> {
    let mut keys: Vec<&IVec3> = blocks.keys().collect();
    keys.sort_by_key(|k| (k.x, k.y, k.z));
    keys.into_iter().find_map(|k| match &blocks[k] {
        Block::Tile(v) => (!ok(v)).then_some((*k << 3, *v)),
        Block::Voxels(v) => v.iter().position(|x| !ok(x)).map(|i| ((*k << 3) + local(i, 3), v[i])),
    })
}
