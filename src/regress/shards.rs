//! Balanced, resumable shards: each scene's cost (its last record's wall time, else an estimate
//! from render size and method), a longest-processing-time-first plan that every shard computes
//! alike, the plan file shards of one output folder share, and the per-shard manifest the merge
//! reads to find shards that are missing or died.

use std::cmp::Reverse;
use std::collections::{BTreeMap, BinaryHeap};
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::discover::{SceneEntry, Shard};
use super::record::{Record, RECORD_FILE};
use crate::io::atomic;
use crate::{Error, Result};

/// Hidden folder in the output folder holding plans and shard manifests (the record walk skips
/// hidden folders).
pub const STATE_DIR: &str = ".voltex";

/// FNV-1a, 64 bits: stable across builds and platforms (std's hasher is not), which is all that
/// change detection needs.
pub(crate) struct Fnv(u64);

impl Default for Fnv {
    fn default() -> Self {
        Fnv(0xcbf2_9ce4_8422_2325)
    }
}

impl Fnv {
    pub(crate) fn bytes(&mut self, bytes: &[u8]) -> &mut Self {
        // Length first, so that field boundaries count.
        for b in (bytes.len() as u64).to_le_bytes().iter().chain(bytes) {
            self.0 = (self.0 ^ u64::from(*b)).wrapping_mul(0x0100_0000_01b3);
        }
        self
    }
    pub(crate) fn hex(&self) -> String {
        format!("{:016x}", self.0)
    }
}

/// Fingerprint of a suite: its sorted scene list.
pub(crate) fn suite_id(scenes: &[SceneEntry]) -> String {
    let mut h = Fnv::default();
    for s in scenes {
        h.bytes(s.rel.as_bytes());
    }
    h.hex()
}

/// Hash of what every scene's result depends on besides its own files: the binary and the
/// graphs and WGSL as this run resolves them (files on disk win over the built-in copies).
pub(crate) fn toolchain_hash() -> Result<String> {
    let mut h = Fnv::default();
    let exe = std::env::current_exe().map_err(|e| Error::Invalid(format!("cannot find this binary: {e}")))?;
    h.bytes(&std::fs::read(&exe).map_err(|e| Error::file(&exe, e))?);
    let sources = crate::gpu::sources::Sources::project()?;
    for (key, _) in crate::gpu::sources::embedded_files() {
        let found = match key.split_once('/') {
            Some(("wgsl", rel)) => sources.shader(rel)?,
            Some(("graphs", name)) => sources.graph(name)?,
            _ => None,
        };
        h.bytes(key.as_bytes()).bytes(found.map(|s| s.text).unwrap_or_default().as_bytes());
    }
    Ok(h.hex())
}

/// Hash of one scene's inputs but its reference: the scene file, the files it refers to, the
/// render size and the toolchain hash; [`inputs_hash`] adds the reference (which `--update` may
/// rewrite after this is taken).
pub(crate) fn scene_hash(
    scene: &crate::scene::Scene,
    entry: &SceneEntry,
    size: (u32, u32),
    toolchain: &str,
) -> String {
    let mut h = Fnv::default();
    h.bytes(toolchain.as_bytes()).bytes(&size.0.to_le_bytes()).bytes(&size.1.to_le_bytes());
    h.bytes(scene.source().as_bytes());
    // Paths relative to the scene's folder: the same suite elsewhere hashes the same.
    let base = entry.path.parent().unwrap_or(Path::new(""));
    let mut files = scene.asset_paths();
    files.sort();
    for path in files {
        hash_path(&mut h, base, &path);
    }
    h.hex()
}

/// The whole inputs hash: [`scene_hash`] and the reference's bytes.
pub(crate) fn inputs_hash(scene_hash: &str, entry: &SceneEntry) -> String {
    let mut h = Fnv::default();
    h.bytes(scene_hash.as_bytes());
    hash_path(&mut h, entry.path.parent().unwrap_or(Path::new("")), &entry.reference);
    h.hex()
}

/// A file's bytes, or a folder's files' names and bytes (slice stacks); a missing one hashes as
/// absent.
fn hash_path(h: &mut Fnv, base: &Path, path: &Path) {
    h.bytes(path.strip_prefix(base).unwrap_or(path).to_string_lossy().as_bytes());
    if path.is_dir() {
        let mut entries: Vec<PathBuf> =
            std::fs::read_dir(path).into_iter().flatten().filter_map(|e| e.ok().map(|e| e.path())).collect();
        entries.sort();
        for e in entries.iter().filter(|e| e.is_file()) {
            hash_path(h, base, e);
        }
    } else {
        h.bytes(&std::fs::read(path).unwrap_or_default());
    }
}

/// How long a scene is expected to take, in milliseconds.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub(crate) struct Cost {
    pub(crate) ms: f64,
    /// From a record of an earlier run (else estimated).
    pub(crate) measured: bool,
}

/// Fixed milliseconds of a scene (start, bake, read-back) besides its methods' per-pixel cost
/// (each method's plug-in estimates its own rate: `MethodPlugin::kpixel_ms`).
const FIXED_MS: f64 = 150.0;
/// Milliseconds per 1000 pixels of a scene whose methods cost less (or that has none).
const MIN_KPIXEL_MS: f64 = 15.0;

/// A scene's cost: its record's wall time under `out`, else an estimate from its render size
/// and the costliest method its nodes use (a scene that does not load costs [`FIXED_MS`]).
pub(crate) fn cost(out: &Path, entry: &SceneEntry, size: Option<(u32, u32)>) -> Cost {
    if let Ok(r) = Record::read(&out.join(&entry.folder).join(RECORD_FILE)) {
        if r.wall_ms.is_finite() && r.wall_ms > 0.0 {
            return Cost { ms: r.wall_ms, measured: true };
        }
    }
    Cost { ms: estimate(entry, size), measured: false }
}

fn estimate(entry: &SceneEntry, size: Option<(u32, u32)>) -> f64 {
    let Ok(text) = std::fs::read_to_string(&entry.path) else { return FIXED_MS };
    let Ok(scene) = crate::scene::parse(&text, &entry.path) else { return FIXED_MS };
    let (w, h) =
        size.or(scene.regress.size.map(|[w, h]| (w, h))).unwrap_or((scene.output.width, scene.output.height));
    let rate = scene.methods().iter().map(|m| m.plugin().kpixel_ms()).fold(MIN_KPIXEL_MS, f64::max);
    let samples = f64::from(scene.regress.supersample.pow(2));
    FIXED_MS + rate * f64::from(w) * f64::from(h) * samples / 1000.0
}

/// A plan: which shard (0-based) each scene goes to, and each shard's predicted load.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ShardPlan {
    pub(crate) suite: String,
    pub(crate) count: usize,
    pub(crate) scenes: Vec<Planned>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub(crate) struct Planned {
    pub(crate) scene: String,
    /// 1-based, as `--shard i/n`.
    pub(crate) shard: usize,
    pub(crate) cost: Cost,
}

impl ShardPlan {
    /// Longest processing time first: scenes by falling cost (ties by path) each to the shard
    /// with the least load so far (ties to the lowest index). Loads are summed in whole
    /// microseconds so that every machine computes the same plan.
    pub(crate) fn new(scenes: &[SceneEntry], costs: &[Cost], count: usize) -> Self {
        let micros: Vec<u64> = costs.iter().map(|c| (c.ms.max(0.0) * 1e3).round() as u64).collect();
        let mut order: Vec<usize> = (0..scenes.len()).collect();
        order.sort_by(|&a, &b| micros[b].cmp(&micros[a]).then_with(|| scenes[a].rel.cmp(&scenes[b].rel)));
        let mut heap: BinaryHeap<Reverse<(u64, usize)>> = (0..count).map(|k| Reverse((0, k))).collect();
        let mut shard = vec![0; scenes.len()];
        for i in order {
            let Reverse((load, k)) = heap.pop().expect("count >= 1");
            shard[i] = k;
            heap.push(Reverse((load + micros[i], k)));
        }
        ShardPlan {
            suite: suite_id(scenes),
            count,
            scenes: scenes
                .iter()
                .zip(costs)
                .zip(shard)
                .map(|((s, c), k)| Planned { scene: s.rel.clone(), shard: k + 1, cost: *c })
                .collect(),
        }
    }

    /// Predicted milliseconds of each shard (index 0 is shard 1).
    pub(crate) fn loads(&self) -> Vec<f64> {
        let mut loads = vec![0.0; self.count];
        for p in &self.scenes {
            loads[p.shard - 1] += p.cost.ms;
        }
        loads
    }

    /// The predicted wall time of the whole run: its slowest shard.
    pub fn makespan(&self) -> f64 {
        self.loads().into_iter().fold(0.0, f64::max)
    }

    /// The scenes of shard `shard`, in the suite's order.
    pub(crate) fn take(&self, shard: Shard, scenes: Vec<SceneEntry>) -> Vec<SceneEntry> {
        let mine: BTreeMap<&str, usize> = self.scenes.iter().map(|p| (p.scene.as_str(), p.shard)).collect();
        scenes.into_iter().filter(|s| mine.get(s.rel.as_str()) == Some(&shard.index)).collect()
    }

    /// The plan as a table: shard, scenes, predicted seconds, then the makespan and imbalance.
    pub fn table(&self) -> String {
        use std::fmt::Write as _;
        let loads = self.loads();
        let mut s = String::from("shard  scenes  predicted s  measured\n");
        for (k, load) in loads.iter().enumerate() {
            let mine: Vec<&Planned> = self.scenes.iter().filter(|p| p.shard == k + 1).collect();
            let measured = mine.iter().filter(|p| p.cost.measured).count();
            let _ = writeln!(
                s,
                "{:>5}  {:>6}  {:>11.1}  {measured}/{}",
                k + 1,
                mine.len(),
                load / 1e3,
                mine.len()
            );
        }
        let total: f64 = loads.iter().sum();
        let mean = total / self.count as f64;
        let _ = writeln!(
            s,
            "predicted makespan {:.1} s for {} scenes on {} shards (one machine: {:.1} s; imbalance {:.1}% over the mean)",
            self.makespan() / 1e3,
            self.scenes.len(),
            self.count,
            total / 1e3,
            if mean > 0.0 { (self.makespan() / mean - 1.0) * 100.0 } else { 0.0 }
        );
        s
    }

    pub(crate) fn path(out: &Path, count: usize) -> PathBuf {
        out.join(STATE_DIR).join(format!("plan-{count}.json"))
    }

    pub(crate) fn write(&self, out: &Path) -> Result<()> {
        std::fs::create_dir_all(out.join(STATE_DIR))
            .map_err(|e| Error::file(out.join(STATE_DIR), format!("cannot create folder: {e}")))?;
        write_json(&Self::path(out, self.count), self)
    }

    /// The plan for `count` shards stored in `out` if it is for exactly these scenes.
    pub(crate) fn stored(out: &Path, scenes: &[SceneEntry], count: usize) -> Option<ShardPlan> {
        let plan: ShardPlan = read_json(&Self::path(out, count)).ok()?;
        let same = plan.count == count
            && plan.scenes.len() == scenes.len()
            && plan
                .scenes
                .iter()
                .zip(scenes)
                .all(|(p, s)| p.scene == s.rel && (1..=count).contains(&p.shard));
        same.then_some(plan)
    }
}

/// The plan shard runs into `out` follow: the stored one for these scenes, else a new one from
/// the costs under `out`, stored so that shards starting later (after records changed the
/// costs) and reruns of a lost shard take the same scenes. Of shards planning at once, the first
/// to store its plan wins and the others follow it.
pub(crate) fn plan_for(
    out: &Path,
    scenes: &[SceneEntry],
    count: usize,
    size: Option<(u32, u32)>,
) -> Result<ShardPlan> {
    if let Some(plan) = ShardPlan::stored(out, scenes, count) {
        return Ok(plan);
    }
    let plan = fresh_plan(out, scenes, count, size);
    let path = ShardPlan::path(out, count);
    if path.exists() {
        // A plan for another scene list: replaced.
        plan.write(out)?;
        return Ok(plan);
    }
    // Written aside, then linked into place, which fails if another shard's plan got there first.
    let state = out.join(STATE_DIR);
    std::fs::create_dir_all(&state).map_err(|e| Error::file(&state, format!("cannot create folder: {e}")))?;
    let aside = state.join(format!(".plan-{count}.json.{}-{}", host(), std::process::id()));
    write_json(&aside, &plan)?;
    let linked = std::fs::hard_link(&aside, &path);
    let _ = std::fs::remove_file(&aside);
    match linked {
        Ok(()) => Ok(plan),
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
            Ok(ShardPlan::stored(out, scenes, count).unwrap_or(plan))
        }
        // No hard links on this file system: the last writer wins.
        Err(_) => plan.write(out).map(|()| plan),
    }
}

/// A plan from the costs under `out` now, not stored.
pub(crate) fn fresh_plan(
    out: &Path,
    scenes: &[SceneEntry],
    count: usize,
    size: Option<(u32, u32)>,
) -> ShardPlan {
    let costs: Vec<Cost> = scenes.iter().map(|s| cost(out, s, size)).collect();
    ShardPlan::new(scenes, &costs, count)
}

/// Before a farm submission: DIR's scenes planned on `count` shards from the costs under `out`
/// (created), the plan stored for the shards to follow, and the shard manifests of earlier runs
/// removed, so that the merge judges this submission's shards only.
pub fn prepare(dir: &Path, out: &Path, count: usize, size: Option<(u32, u32)>) -> Result<ShardPlan> {
    let all = super::find(dir)?;
    if all.is_empty() {
        return Err(Error::file(dir, "no scene files (*.ron) in this folder"));
    }
    std::fs::create_dir_all(out)
        .map_err(|e| Error::file(out, format!("cannot create the output folder: {e}")))?;
    atomic::check_writable_dir(out)?;
    let plan = fresh_plan(out, &all, count, size);
    plan.write(out)?;
    let state = out.join(STATE_DIR);
    for e in std::fs::read_dir(&state).map_err(|e| Error::file(&state, e))?.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if name.starts_with("shard-") && name.ends_with(".json") {
            std::fs::remove_file(e.path()).map_err(|err| Error::file(e.path(), err))?;
        }
    }
    Ok(plan)
}

/// The shard manifests under `out/.voltex` that say their shard finished, and all of them.
pub fn finished_shards(out: &Path) -> (usize, usize) {
    let (mut done, mut all) = (0, 0);
    for e in std::fs::read_dir(out.join(STATE_DIR)).into_iter().flatten().flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if name.starts_with("shard-") && name.ends_with(".json") {
            all += 1;
            if read_json::<Manifest>(&e.path()).is_ok_and(|m| m.finished_unix.is_some()) {
                done += 1;
            }
        }
    }
    (done, all)
}

/// What one shard run planned and whether it finished: `OUT/.voltex/shard-K-of-N.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub(crate) struct Manifest {
    pub(crate) suite: String,
    /// `k/n`.
    pub(crate) shard: String,
    pub(crate) scenes: Vec<String>,
    pub(crate) host: String,
    pub(crate) pid: u32,
    pub(crate) started_unix: u64,
    /// Unset while the shard runs, and forever when it died or was killed.
    pub(crate) finished_unix: Option<u64>,
}

impl Manifest {
    pub(crate) fn path(out: &Path, shard: Shard) -> PathBuf {
        out.join(STATE_DIR).join(format!("shard-{}-of-{}.json", shard.index, shard.count))
    }

    pub(crate) fn write(&self, out: &Path, shard: Shard) -> Result<()> {
        std::fs::create_dir_all(out.join(STATE_DIR))
            .map_err(|e| Error::file(out.join(STATE_DIR), format!("cannot create folder: {e}")))?;
        write_json(&Self::path(out, shard), self)
    }
}

/// Another voltex process on this machine running `shard` into `out` now (its unfinished
/// manifest names a live process of the same program), as `pid P on HOST`. Runs on other
/// machines cannot be seen from here.
pub(crate) fn running_elsewhere(out: &Path, shard: Shard) -> Option<String> {
    let m: Manifest = read_json(&Manifest::path(out, shard)).ok()?;
    let comm = |pid: u32| std::fs::read_to_string(format!("/proc/{pid}/comm")).ok();
    let alive = m.finished_unix.is_none()
        && m.host == host()
        && m.pid != std::process::id()
        && comm(m.pid).is_some_and(|c| Some(c) == comm(std::process::id()));
    alive.then(|| format!("pid {} on {}", m.pid, m.host))
}

/// Seconds since 1970 now.
pub(crate) fn unix_now() -> u64 {
    std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map(|d| d.as_secs()).unwrap_or(0)
}

/// This machine's name (records and manifests say where they were written).
pub(crate) fn host() -> String {
    std::fs::read_to_string("/proc/sys/kernel/hostname")
        .ok()
        .or_else(|| std::env::var("HOSTNAME").ok())
        .map(|h| h.trim().to_string())
        .unwrap_or_default()
}

fn write_json<T: Serialize>(path: &Path, value: &T) -> Result<()> {
    let text =
        serde_json::to_string_pretty(value).map_err(|e| Error::file(path, format!("cannot encode: {e}")))?;
    atomic::write_bytes(path, (text + "\n").as_bytes())
}

pub(super) fn read_json<T: for<'de> Deserialize<'de>>(path: &Path) -> Result<T> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::file(path, e))?;
    serde_json::from_str(&text).map_err(|e| Error::file(path, format!("{}:{}: {e}", e.line(), e.column())))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entries(n: usize) -> Vec<SceneEntry> {
        (0..n).map(|i| SceneEntry::new(Path::new("d"), &[format!("s{i}.ron")])).collect()
    }

    #[test]
    fn longest_first_balances_and_is_deterministic() {
        let scenes = entries(6);
        let costs: Vec<Cost> =
            [7.0, 5.0, 4.0, 3.0, 3.0, 2.0].iter().map(|&ms| Cost { ms, measured: true }).collect();
        let plan = ShardPlan::new(&scenes, &costs, 2);
        // 7 -> 1, 5 -> 2, 4 -> 2 (9), 3 -> 1 (10), 3 -> 2 (12), 2 -> 1 (12).
        assert_eq!(plan.scenes.iter().map(|p| p.shard).collect::<Vec<_>>(), [1, 2, 2, 1, 2, 1]);
        assert_eq!(plan.loads(), [12.0, 12.0]);
        assert_eq!(plan, ShardPlan::new(&scenes, &costs, 2));
        let take = plan.take(Shard { index: 1, count: 2 }, scenes.clone());
        assert_eq!(take.iter().map(|s| s.rel.as_str()).collect::<Vec<_>>(), ["s0.ron", "s3.ron", "s5.ron"]);
        // Equal costs deal the scenes out in order, as the modulo shards did.
        let equal = ShardPlan::new(&scenes, &[Cost { ms: 1.0, measured: false }; 6], 4);
        assert_eq!(equal.scenes.iter().map(|p| p.shard).collect::<Vec<_>>(), [1, 2, 3, 4, 1, 2]);
        assert_ne!(suite_id(&scenes), suite_id(&scenes[1..]));
    }
}
