//! What a merged output folder must not silently hide: records of different suites, two records
//! of one scene, and shards that are missing or died (from the plan and the shard manifests in
//! `.voltex/` folders).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use super::record::Found;
use super::shards::{read_json, Manifest, ShardPlan, STATE_DIR};
use super::Shard;
use crate::Result;

/// One thing wrong with a merged folder; `what` names the shard or scene, `message` says what
/// happened.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub(crate) struct Problem {
    pub(crate) what: String,
    pub(crate) message: String,
}

impl std::fmt::Display for Problem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.what, self.message)
    }
}

/// Checks the records found under `out` against each other and the shard state beside them.
pub(crate) fn check(out: &Path, found: &[Found]) -> Result<Vec<Problem>> {
    let mut problems = Vec::new();
    let (plans, manifests) = state(out);

    // Suites: records (and shard manifests) must agree.
    let mut suites: BTreeMap<&str, Vec<&str>> = BTreeMap::new();
    for f in found.iter().filter(|f| !f.record.suite.is_empty()) {
        suites.entry(&f.record.suite).or_default().push(&f.record.scene);
    }
    if suites.len() > 1 {
        let parts: Vec<String> = suites
            .iter()
            .map(|(id, scenes)| format!("{} record(s) of suite {id} (e.g. {})", scenes.len(), scenes[0]))
            .collect();
        problems.push(Problem {
            what: "suite".into(),
            message: format!(
                "results from different suites in one folder: {} (merge each suite's results into a folder of its own)",
                parts.join(", ")
            ),
        });
    }

    // Duplicates: one scene in two folders (shard folders copied side by side, say).
    let mut folders: BTreeMap<&str, Vec<&Path>> = BTreeMap::new();
    for f in found {
        folders.entry(&f.record.scene).or_default().push(&f.folder);
    }
    for (scene, dirs) in folders.iter().filter(|(_, d)| d.len() > 1) {
        let dirs: Vec<String> = dirs.iter().map(|d| d.display().to_string()).collect();
        problems.push(Problem {
            what: (*scene).to_string(),
            message: format!("duplicate records in {} (keep one)", dirs.join(", ")),
        });
    }

    // Shards: every shard of a plan ran to its end, or at least left a record of each of its scenes.
    let have: BTreeSet<&str> = found.iter().map(|f| f.record.scene.as_str()).collect();
    let record_suite = (suites.len() == 1).then(|| *suites.keys().next().unwrap());
    let mut counts: BTreeSet<usize> = plans.keys().copied().collect();
    counts.extend(manifests.keys().map(|s| s.count));
    for n in counts.into_iter().filter(|&n| n > 1 || manifests.keys().any(|s| s.count == n)) {
        let plan = plans.get(&n);
        for k in 1..=n {
            let shard = Shard { index: k, count: n };
            let planned: Vec<&str> = match (manifests.get(&shard), plan) {
                (Some((_, m)), _) => m.scenes.iter().map(String::as_str).collect(),
                (None, Some(p)) => {
                    p.scenes.iter().filter(|s| s.shard == k).map(|s| s.scene.as_str()).collect()
                }
                (None, None) => Vec::new(),
            };
            let lacking: Vec<&str> = planned.iter().copied().filter(|s| !have.contains(s)).collect();
            let what = format!("shard {shard}");
            match manifests.get(&shard) {
                None if plan.is_none() || !lacking.is_empty() => problems.push(Problem {
                    what,
                    message: format!(
                        "missing: no results from this shard (it never started, or its folder was not copied){}",
                        without(&lacking, planned.len())
                    ),
                }),
                Some((path, m)) if m.finished_unix.is_none() && !lacking.is_empty() => problems.push(Problem {
                    what,
                    message: format!(
                        "started on {} (pid {}) and did not finish: killed, timed out or still running \
                         ({}){}; rerun it alone with the same --shard",
                        or_unknown(&m.host),
                        m.pid,
                        path.display(),
                        without(&lacking, planned.len())
                    ),
                }),
                Some((_, m)) if record_suite.is_some_and(|s| s != m.suite) => problems.push(Problem {
                    what,
                    message: format!("ran suite {} but the records are of suite {}", m.suite, record_suite.unwrap()),
                }),
                Some((_, _)) if !lacking.is_empty() => problems.push(Problem {
                    what,
                    message: format!("finished{}", without(&lacking, planned.len())),
                }),
                _ => {}
            }
        }
    }
    Ok(problems)
}

fn without(lacking: &[&str], planned: usize) -> String {
    match lacking {
        [] => String::new(),
        [first, ..] => {
            format!("; {} of its {planned} scene(s) have no record (first: {first})", lacking.len())
        }
    }
}

fn or_unknown(host: &str) -> &str {
    if host.is_empty() {
        "an unknown host"
    } else {
        host
    }
}

type Manifests = BTreeMap<Shard, (PathBuf, Manifest)>;

/// Plans (by shard count) and shard manifests in every `.voltex/` folder under `out`.
fn state(out: &Path) -> (BTreeMap<usize, ShardPlan>, Manifests) {
    let mut plans = BTreeMap::new();
    let mut manifests = BTreeMap::new();
    let mut dirs = vec![out.to_path_buf()];
    while let Some(dir) = dirs.pop() {
        let Ok(entries) = std::fs::read_dir(&dir) else { continue };
        for e in entries.flatten() {
            let path = e.path();
            let name = e.file_name().to_string_lossy().into_owned();
            if !e.file_type().is_ok_and(|t| t.is_dir()) {
                continue;
            }
            if name == STATE_DIR {
                read_state(&path, &mut plans, &mut manifests);
            } else if !name.starts_with('.') {
                dirs.push(path);
            }
        }
    }
    (plans, manifests)
}

fn read_state(dir: &Path, plans: &mut BTreeMap<usize, ShardPlan>, manifests: &mut Manifests) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for e in entries.flatten() {
        let path = e.path();
        let name = e.file_name().to_string_lossy().into_owned();
        if name.starts_with("plan-") && name.ends_with(".json") {
            if let Ok(p) = read_json::<ShardPlan>(&path) {
                plans.insert(p.count, p);
            }
        } else if name.starts_with("shard-") && name.ends_with(".json") {
            if let Ok(m) = read_json::<Manifest>(&path) {
                if let Ok(shard) = Shard::parse(&m.shard, &|_| None) {
                    // Of two copies of one shard's manifest, the finished one tells more.
                    let better = match manifests.get(&shard) {
                        Some((_, old)) => old.finished_unix.is_none() && m.finished_unix.is_some(),
                        None => true,
                    };
                    if better {
                        manifests.insert(shard, (path, m));
                    }
                }
            }
        }
    }
}
