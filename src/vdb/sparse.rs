//! A grid kept sparse for the GPU: one brick of 9^3 values per 8^3 leaf that the density
//! touches (the leaf's voxels and one more on each positive side, so that the trilinear
//! interpolant of any point whose cell starts in the leaf reads one brick), and a two-level
//! table from index coordinates to bricks: a top grid of 128^3-voxel cells (OpenVDB's internal
//! nodes), each cell naming a node of 16^3 brick numbers. Brick 0 is all zeros, so an absent
//! leaf needs no brick; uniform bricks (a level set's inside, a fog's tiles) are shared.
//! Memory grows with the leaves the density touches, plus one table cell per 128^3 voxels of
//! the bounding box. `density` / `color` here are the CPU twin of `wgsl/shared/volume.wgsl`.

use std::collections::HashMap;

use glam::{DMat4, DVec3, IVec3, UVec3};

use super::tree::{Block, Blocks};

/// Voxels per leaf side.
pub(crate) const LEAF: i32 = 8;
/// Values per brick side: a leaf and one more.
pub(crate) const BRICK: usize = 9;
pub(crate) const BRICK_VALUES: usize = BRICK * BRICK * BRICK;
/// Leaves per table node side (a top cell spans `LEAF * NODE` = 128 voxels).
pub(crate) const NODE: i32 = 16;
pub(crate) const NODE_ENTRIES: usize = (NODE * NODE * NODE) as usize;
/// A top cell without a node.
pub(crate) const NO_NODE: u32 = u32::MAX;
/// Most top cells: the bounding box may span about 16k voxels per side (more along one axis).
pub(crate) const MAX_TOP_CELLS: u64 = 1 << 21;
/// Most bricks of one grid (2^18: 729 MiB of float bricks, 191 million values).
pub(crate) const MAX_BRICKS: u64 = 1 << 18;

/// A grid as bricks and table (see the module's documentation).
#[derive(Debug, Clone, Default)]
pub struct SparseVolume {
    /// Index space to world space (the file's transform).
    pub index_to_world: DMat4,
    /// Index coordinate of the top grid's first voxel (a multiple of 128).
    pub(crate) origin: IVec3,
    /// Top grid cells per axis.
    pub(crate) top: UVec3,
    /// The top grid (node offsets into this table, or `NO_NODE`), then the nodes (brick numbers).
    pub table: Vec<u32>,
    /// Bricks of density, `BRICK_VALUES` each, x fastest; brick 0 is zeros.
    pub density: Vec<f32>,
    /// Bricks of colour alike, when the volume has a colour grid.
    pub(crate) color: Option<Vec<[f32; 3]>>,
    /// Lowest index corner (inclusive) of the voxels with non-zero density.
    pub lo: IVec3,
    /// Highest index corner (inclusive) of the voxels with non-zero density.
    pub hi: IVec3,
    /// Leaves (and leaf tiles) holding density, before dilation.
    pub(crate) leaves: u64,
    pub(crate) max_density: f32,
    /// A digest of the table and bricks (the GPU upload's cache key).
    pub(crate) hash: u64,
}

/// Cell counts of the top grid over leaves `lo..=hi` (leaf coordinates), and its origin.
fn top_grid(lo: IVec3, hi: IVec3) -> (IVec3, [u64; 3]) {
    let origin = (lo * LEAF).div_euclid(IVec3::splat(LEAF * NODE)) * (LEAF * NODE);
    let size = |a: usize| {
        ((hi[a] as i64 + 1) * LEAF as i64 - origin[a] as i64).div_euclid((LEAF * NODE) as i64) as u64 + 1
    };
    (origin, [size(0), size(1), size(2)])
}

/// The brick table's top grid, checked before anything is allocated: `Err` names the limit
/// and the numbers (a grid whose voxels lie far apart).
pub(crate) fn check_extent(blocks: &Blocks<f32>) -> Result<(), String> {
    let mut keys = blocks.keys();
    let Some(first) = keys.next() else { return Ok(()) };
    let (lo, hi) = keys.fold((*first, *first), |(lo, hi), k| (lo.min(*k), hi.max(*k)));
    let (_, top) = top_grid(lo - 1, hi);
    let cells = top[0] * top[1] * top[2];
    if cells > MAX_TOP_CELLS {
        let span = (hi - lo + 1) * LEAF;
        return Err(format!(
            "its voxels span {}x{}x{} index units: the brick table's top grid would need {}x{}x{} = {cells} cells of \
             128^3 voxels (at most {MAX_TOP_CELLS}); voltex keeps grids whose bounding box spans about 16k voxels \
             per side",
            span.x, span.y, span.z, top[0], top[1], top[2]
        ));
    }
    Ok(())
}

/// Leaves whose brick may hold density: every leaf with density and the seven below it along
/// the axes (their bricks' last layer reaches into it). Sorted, so bricks are numbered alike on
/// every run.
fn dilated(blocks: &Blocks<f32>) -> Vec<IVec3> {
    let mut set = std::collections::HashSet::new();
    for k in blocks.keys() {
        for d in 0..8 {
            set.insert(*k - IVec3::new(d & 1, d >> 1 & 1, d >> 2));
        }
    }
    let mut v: Vec<IVec3> = set.into_iter().collect();
    v.sort_by_key(|k| (k.z, k.y, k.x));
    v
}

/// The value of voxel `local` (0..8 per axis) of a block, or `empty` where there is none.
pub(crate) fn value<T: Copy>(b: Option<&Block<T>>, local: IVec3, empty: T) -> T {
    match b {
        None => empty,
        Some(Block::Tile(v)) => *v,
        Some(Block::Voxels(v)) => v[(local.x * 64 + local.y * 8 + local.z) as usize],
    }
}

/// A brick's values: leaf `key` and one voxel more on each positive side, x fastest.
fn brick<T: Copy>(blocks: &Blocks<T>, key: IVec3, empty: T) -> Vec<T> {
    let near: [Option<&Block<T>>; 8] = std::array::from_fn(|d| {
        blocks.get(&(key + IVec3::new(d as i32 & 1, d as i32 >> 1 & 1, d as i32 >> 2)))
    });
    let mut out = Vec::with_capacity(BRICK_VALUES);
    for z in 0..BRICK as i32 {
        for y in 0..BRICK as i32 {
            for x in 0..BRICK as i32 {
                let p = IVec3::new(x, y, z);
                let side = p / LEAF;
                out.push(value(near[(side.x + 2 * side.y + 4 * side.z) as usize], p % LEAF, empty));
            }
        }
    }
    out
}

impl SparseVolume {
    /// Builds the bricks and table of `density` (and `color`, read at the same voxels), after
    /// [`check_extent`] passed. `Ok(None)` when the density is zero everywhere; an error when
    /// it needs more than [`MAX_BRICKS`] bricks.
    pub(crate) fn build(
        density: &Blocks<f32>,
        color: Option<&Blocks<[f32; 3]>>,
        index_to_world: DMat4,
    ) -> Result<Option<SparseVolume>, String> {
        let nonzero = |b: &Block<f32>| match b {
            Block::Tile(v) => *v != 0.0,
            Block::Voxels(v) => v.iter().any(|x| *x != 0.0),
        };
        let density: Blocks<f32> =
            density.iter().filter(|(_, b)| nonzero(b)).map(|(k, b)| (*k, b.clone())).collect();
        let keys = dilated(&density);
        let Some(&first) = keys.first() else { return Ok(None) };
        let (lo_leaf, hi_leaf) = keys.iter().fold((first, first), |(lo, hi), k| (lo.min(*k), hi.max(*k)));
        let (origin, top) = top_grid(lo_leaf, hi_leaf);
        let top = UVec3::new(top[0] as u32, top[1] as u32, top[2] as u32);
        let mut v = SparseVolume {
            index_to_world,
            origin,
            top,
            table: vec![NO_NODE; (top.x * top.y * top.z) as usize],
            density: vec![0.0; BRICK_VALUES],
            color: color.map(|_| vec![[0.0; 3]; BRICK_VALUES]),
            lo: IVec3::MAX,
            hi: IVec3::MIN,
            leaves: density.len() as u64,
            max_density: 0.0,
            hash: 0,
        };
        let mut shared: HashMap<Vec<u32>, u32> = HashMap::new();
        for key in keys {
            let values = brick(&density, key, 0.0);
            if values.iter().all(|x| *x == 0.0) {
                continue;
            }
            let colors = color.map(|c| brick(c, key, [0.0; 3]));
            let uniform = values.iter().all(|x| *x == values[0])
                && colors.as_ref().is_none_or(|c| c.iter().all(|x| *x == c[0]));
            let signature: Vec<u32> = std::iter::once(values[0].to_bits())
                .chain(colors.iter().flat_map(|c| c[0].map(f32::to_bits)))
                .collect();
            let number = match uniform.then(|| shared.get(&signature)).flatten() {
                Some(&n) => n,
                None => {
                    let n = (v.density.len() / BRICK_VALUES) as u32;
                    if n as u64 >= MAX_BRICKS {
                        return Err(format!(
                            "its density touches {} leaves of 8^3 voxels, which need more than {MAX_BRICKS} distinct \
                             bricks of 9^3 values (at most {MAX_BRICKS}: {} MiB of floats)",
                            density.len(),
                            (MAX_BRICKS * BRICK_VALUES as u64 * 4) >> 20
                        ));
                    }
                    v.max_density = values.iter().fold(v.max_density, |m, x| m.max(*x));
                    v.density.extend_from_slice(&values);
                    if let (Some(all), Some(c)) = (v.color.as_mut(), colors) {
                        all.extend_from_slice(&c);
                    }
                    if uniform {
                        shared.insert(signature, n);
                    }
                    n
                }
            };
            v.set(key, number);
        }
        // Voxels with density: the leaves' own (a brick's last layer belongs to its neighbour).
        for (k, b) in &density {
            let (lo, hi) = match b {
                Block::Tile(_) => (*k * LEAF, *k * LEAF + (LEAF - 1)),
                Block::Voxels(vals) => {
                    let mut r = (IVec3::MAX, IVec3::MIN);
                    for (i, x) in vals.iter().enumerate() {
                        if *x != 0.0 {
                            let p = *k * LEAF + IVec3::new(i as i32 >> 6, i as i32 >> 3 & 7, i as i32 & 7);
                            r = (r.0.min(p), r.1.max(p));
                        }
                    }
                    r
                }
            };
            v.lo = v.lo.min(lo);
            v.hi = v.hi.max(hi);
        }
        v.hash = v.digest();
        Ok(Some(v))
    }

    /// Records brick `number` for leaf `key`, making its node if needed.
    fn set(&mut self, key: IVec3, number: u32) {
        let rel = key * LEAF - self.origin;
        let t = rel / (LEAF * NODE);
        let cell = (t.x as u32 + self.top.x * (t.y as u32 + self.top.y * t.z as u32)) as usize;
        if self.table[cell] == NO_NODE {
            self.table[cell] = self.table.len() as u32;
            self.table.resize(self.table.len() + NODE_ENTRIES, 0);
        }
        let l = (rel / LEAF) % NODE;
        let at = self.table[cell] as usize + (l.x + NODE * (l.y + NODE * l.z)) as usize;
        self.table[at] = number;
    }

    fn digest(&self) -> u64 {
        use std::hash::{Hash, Hasher};
        let mut h = std::collections::hash_map::DefaultHasher::new();
        (self.origin.to_array(), self.top.to_array(), &self.table).hash(&mut h);
        bytemuck::cast_slice::<f32, u8>(&self.density).hash(&mut h);
        self.color.as_ref().map(|c| bytemuck::cast_slice::<[f32; 3], u8>(c).to_vec()).hash(&mut h);
        h.finish()
    }

    /// Bricks of density, brick 0 (the zeros) included.
    pub fn bricks(&self) -> u64 {
        (self.density.len() / BRICK_VALUES) as u64
    }

    /// Every leaf with a brick: the index of its first voxel and its brick number (table
    /// order). A brick's values at `(x, y, z)` in `0..BRICK` are those of voxel `first + (x,
    /// y, z)`; its last layer belongs to the next leaf.
    pub(crate) fn leaf_bricks(&self) -> Vec<(IVec3, usize)> {
        let mut out = Vec::new();
        for (cell, &node) in self.table[..(self.top.x * self.top.y * self.top.z) as usize].iter().enumerate()
        {
            if node == NO_NODE {
                continue;
            }
            let cell = cell as u32;
            let t = UVec3::new(
                cell % self.top.x,
                cell / self.top.x % self.top.y,
                cell / (self.top.x * self.top.y),
            );
            for (l, &brick) in self.table[node as usize..node as usize + NODE_ENTRIES].iter().enumerate() {
                if brick != 0 {
                    let l = l as i32;
                    let leaf = IVec3::new(l % NODE, l / NODE % NODE, l / (NODE * NODE));
                    let first = self.origin + t.as_ivec3() * (LEAF * NODE) + leaf * LEAF;
                    out.push((first, brick as usize));
                }
            }
        }
        out
    }

    /// The brick holding the cell whose lower corner is voxel `c`, and `c` within it.
    fn locate(&self, c: IVec3) -> Option<(usize, IVec3)> {
        let rel = c - self.origin;
        let t = rel.div_euclid(IVec3::splat(LEAF * NODE));
        if t.min_element() < 0
            || t.x as u32 >= self.top.x
            || t.y as u32 >= self.top.y
            || t.z as u32 >= self.top.z
        {
            return None;
        }
        let node = self.table[(t.x as u32 + self.top.x * (t.y as u32 + self.top.y * t.z as u32)) as usize];
        if node == NO_NODE {
            return None;
        }
        let l = rel.div_euclid(IVec3::splat(LEAF)) % NODE;
        let brick = self.table[node as usize + (l.x + NODE * (l.y + NODE * l.z)) as usize];
        (brick != 0).then_some((brick as usize, rel.rem_euclid(IVec3::splat(LEAF))))
    }

    /// Trilinear interpolation of brick values at index point `p` (CPU twin of `volume_sample`).
    fn sample<const N: usize>(&self, p: DVec3, values: impl Fn(usize) -> [f64; N]) -> [f64; N] {
        let c = p.floor();
        let Some((brick, v)) = self.locate(c.as_ivec3()) else { return [0.0; N] };
        let f = p - c;
        let mut out = [0.0; N];
        for corner in 0..8 {
            let d = IVec3::new(corner & 1, corner >> 1 & 1, corner >> 2);
            let w = (if d.x == 1 { f.x } else { 1.0 - f.x })
                * (if d.y == 1 { f.y } else { 1.0 - f.y })
                * (if d.z == 1 { f.z } else { 1.0 - f.z });
            let q = v + d;
            let at = brick * BRICK_VALUES + (q.x + BRICK as i32 * (q.y + BRICK as i32 * q.z)) as usize;
            let x = values(at);
            for (o, x) in out.iter_mut().zip(x) {
                *o += w * x;
            }
        }
        out
    }

    /// Density at index point `p`: the trilinear interpolant of the voxels (voxel (i, j, k) at
    /// index point (i, j, k)).
    pub fn density_at(&self, p: DVec3) -> f64 {
        self.sample(p, |i| [self.density[i] as f64])[0]
    }

    /// Colour at index point `p` (white without a colour grid).
    pub fn color_at(&self, p: DVec3) -> [f64; 3] {
        match &self.color {
            None => [1.0; 3],
            Some(c) => self.sample(p, |i| c[i].map(|x| x as f64)),
        }
    }

    /// The index box outside which the density is 0: the voxels' bounds grown by one voxel (the
    /// interpolant's reach).
    pub fn index_bounds(&self) -> (DVec3, DVec3) {
        ((self.lo - 1).as_dvec3(), (self.hi + 1).as_dvec3())
    }

    /// The world-space corners of [`index_bounds`](Self::index_bounds) under `to_world`.
    pub(crate) fn world_corners(&self, to_world: &DMat4) -> [DVec3; 8] {
        let (lo, hi) = self.index_bounds();
        let m = *to_world * self.index_to_world;
        std::array::from_fn(|i| {
            let p = DVec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            );
            m.transform_point3(p)
        })
    }

    /// Brick slots of the atlas per axis for `bricks` bricks under a 3D texture side of `max_side`.
    pub(crate) fn atlas_slots(bricks: u64, max_side: u32) -> [u32; 3] {
        let per = (max_side / BRICK as u32).max(1) as u64;
        let x = bricks.clamp(1, per);
        let y = bricks.div_ceil(x).clamp(1, per);
        let z = bricks.div_ceil(x * y).max(1);
        [x as u32, y as u32, z.min(u32::MAX as u64) as u32]
    }

    /// GPU bytes: the table, and the density (R32Float) and colour (Rgba16Float) atlases.
    pub fn gpu_bytes(&self, max_side: u32) -> u64 {
        let [x, y, z] = Self::atlas_slots(self.bricks(), max_side);
        let texels = (x * y) as u64 * z as u64 * BRICK_VALUES as u64;
        self.table.len() as u64 * 4 + texels * (4 + if self.color.is_some() { 8 } else { 0 })
    }
}
