//! Budgets checked from the counts in the scene file, before any mesh is built or texel baked:
//! work that the limits of single values allow but whose product exhausts memory or time
//! (a `Plane` of 4096x4096 cells, 10,000 nodes, an `Implicit` texel of 10,000 shapes at 256^3).
//! Each rejection gives the numbers and the position of the value that drives them.

use super::types::{Node, Scene, Shape, Surface, TexelSource};
use super::validate::Assets;
use std::path::Path;

/// Most nodes in a scene, children included.
pub const MAX_NODES: usize = 1024;
/// Most base-surface triangles in a scene, all nodes together (each becomes a prism, and every
/// method's per-prism work and memory scale with them).
pub const MAX_TRIANGLES: u64 = 1 << 21;
/// Most shape evaluations of a scene's `Implicit` bakes together: shapes (metaballs counted one
/// by one) x voxels, summed over the texels. The bake evaluates every shape at every voxel: on
/// llvmpipe 2^29 evaluations take about 20 s (1,000 spheres at 64^3 take 9 s; 10,000 took
/// minutes before this budget).
pub const MAX_SHAPE_VOXELS: u64 = 1 << 29;

/// Base triangles of a surface; `None` for an OBJ that did not load (reported elsewhere).
fn triangles(surface: &Surface, assets: &Assets) -> Option<u64> {
    Some(match *surface {
        Surface::Plane { cells, .. } => 2 * cells[0] as u64 * cells[1] as u64,
        Surface::Sphere { segments, .. } | Surface::Torus { segments, .. } => {
            2 * segments[0] as u64 * segments[1] as u64
        }
        Surface::Mesh { ref path } => {
            assets.meshes.get(&assets.dir.join(&path.value))?.triangles.len() as u64
        }
    })
}

fn all_nodes<'a>(nodes: &'a [Node], out: &mut Vec<&'a Node>) {
    for n in nodes {
        out.push(n);
        all_nodes(&n.children, out);
    }
}

/// The budget failures: messages for marks (positioned by the second parse), and errors
/// positioned here (texels have no mark; their key is found in `source`).
pub(super) fn check(
    scene: &Scene,
    assets: &Assets,
    source: &str,
    path: &Path,
) -> (Vec<(usize, String)>, Option<crate::Error>) {
    let mut marks = Vec::new();
    let mut nodes = Vec::new();
    all_nodes(&scene.nodes, &mut nodes);
    if let Some(n) = nodes.get(MAX_NODES) {
        let msg = format!(
            "the scene has {} nodes: at most {MAX_NODES} are allowed (node \"{}\" is number {})",
            nodes.len(),
            n.name,
            MAX_NODES + 1
        );
        match node_mark(n) {
            Some(seq) => marks.push((seq, msg)),
            None => return (marks, Some(crate::Error::Invalid(format!("{}: {msg}", path.display())))),
        }
        return (marks, None);
    }
    let mut total = 0u64;
    for n in &nodes {
        let Some(s) = &n.surface else { continue };
        let Some(t) = triangles(&s.value, assets) else { continue };
        total += t;
        if total > MAX_TRIANGLES {
            let msg = format!(
                "node \"{}\": {t} base triangles bring the scene to {total}: at most {MAX_TRIANGLES} are allowed",
                n.name
            );
            marks.push((s.seq, msg));
            return (marks, None);
        }
    }
    let mut evaluations = 0u64;
    for (name, t) in &scene.texels {
        let TexelSource::Implicit { shapes } = &t.source else { continue };
        let count: u64 = shapes
            .iter()
            .map(|s| match s {
                Shape::Metaballs { balls, .. } => balls.len().max(1) as u64,
                _ => 1,
            })
            .sum();
        let voxels: u64 = t.resolution.iter().map(|&r| r as u64).product();
        evaluations += count * voxels;
        if evaluations > MAX_SHAPE_VOXELS {
            let others = evaluations - count * voxels;
            let before = if others > 0 {
                format!(" (with {others} of the other Implicit texels)")
            } else {
                String::new()
            };
            let msg = format!(
                "texel \"{name}\": {count} shapes x {voxels} voxels = {} shape evaluations{before}: at most \
                 {MAX_SHAPE_VOXELS} are allowed in a scene (fewer shapes or a lower resolution)",
                count * voxels
            );
            let at = key_offset(source, name);
            let (line, col) = crate::error::line_col(source, at);
            return (marks, Some(crate::Error::at(crate::FileLoc::new(path, line, col), msg)));
        }
    }
    (marks, None)
}

/// A mark of node `n` to position an error at: its surface, texel, hypertexture or method.
fn node_mark(n: &Node) -> Option<usize> {
    let seqs = [
        n.surface.as_ref().map(|m| m.seq),
        n.texel.as_ref().map(|m| m.seq),
        n.hypertexture.as_ref().map(|m| m.seq),
        n.method.as_ref().map(|m| m.seq),
    ];
    seqs.into_iter().flatten().find(|&s| s != usize::MAX)
}

/// Byte offset of the map key `"name":` in `source` (the first mention otherwise).
fn key_offset(source: &str, name: &str) -> usize {
    let needle = format!("\"{name}\"");
    let mut from = 0;
    while let Some(i) = source[from..].find(&needle) {
        let at = from + i;
        if source[at + needle.len()..].trim_start().starts_with(':') {
            return at;
        }
        from = at + needle.len();
    }
    source.find(&needle).unwrap_or(0)
}
