//! `voltex farm` for real: a single-node Slurm cluster (munged, slurmctld and slurmd from Debian's
//! `munge` and `slurm-wlm`, configured in a temporary folder, stopped by their process ids) runs
//! a small suite as an array of 3 shards and a merge, whose verdicts and metrics must equal a
//! one-machine run; sbatch missing or refusing; and the Kubernetes manifest parsed as YAML and
//! validated against Kubernetes' schemas.
//!
//! Without slurmctld (or as a user other than root, which slurmd needs to start jobs) the Slurm
//! test prints why and passes, unless `VOLTEX_REQUIRE_SLURM=1` (as `.ci/run` sets) makes it fail.

use crate::common;

use common::{root, s, scratch_dir};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

use voltex::regress::Record;

const BIN: &str = env!("CARGO_BIN_EXE_voltex");

/// Three small scenes (two methods, one in a subfolder) without references.
fn suite(dir: &Path) -> PathBuf {
    let suite = dir.join("suite");
    for (from, to) in [
        ("view_slices/flat_box.ron", "flat_box.ron"),
        ("hard_cases/tiny_scene.ron", "hard/tiny_scene.ron"),
        ("hard_cases/single_slice.ron", "hard/single_slice.ron"),
    ] {
        let to = suite.join(to);
        std::fs::create_dir_all(to.parent().unwrap()).unwrap();
        std::fs::copy(root().join("scenes").join(from), to).unwrap();
    }
    suite
}

fn voltex(args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut cmd = Command::new(BIN);
    cmd.args(args).env("VOLTEX_ROOT", root()).env_remove("VOLTEX_FAULT");
    for (k, v) in env {
        cmd.env(k, v);
    }
    let out = cmd.output().unwrap();
    eprintln!(
        "voltex {args:?}: {}\n{}{}",
        out.status,
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn text(out: &Output) -> String {
    format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr))
}

/// scene -> (status, FLIP, rel RMSE, size) of every record under `out`.
fn verdicts(out: &Path) -> BTreeMap<String, String> {
    let (found, bad) = voltex::regress::record::collect(out).unwrap();
    assert!(bad.is_empty(), "{bad:?}");
    found
        .into_iter()
        .map(|f| {
            let r: Record = f.record;
            (r.scene.clone(), format!("{:?} {:?} {:?} {:?}", r.status, r.flip, r.rel_rmse, r.size))
        })
        .collect()
}

/// A program on PATH or in the sbin folders (not on a user's PATH on Debian).
fn program(name: &str) -> Option<PathBuf> {
    let path = std::env::var_os("PATH").unwrap_or_default();
    std::env::split_paths(&path)
        .chain(["/usr/sbin", "/sbin", "/usr/local/sbin"].map(PathBuf::from))
        .map(|d| d.join(name))
        .find(|p| p.is_file())
}

fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port()
}

/// munged, slurmctld and slurmd started by this test; stopped (SIGTERM, then SIGKILL) by pid.
struct Cluster {
    dir: PathBuf,
    conf: PathBuf,
    daemons: Vec<(&'static str, Child)>,
}

impl Cluster {
    /// Why the cluster cannot start here, if it cannot.
    fn missing() -> Option<String> {
        for p in ["munged", "slurmctld", "slurmd", "sbatch", "scontrol", "sinfo"] {
            if program(p).is_none() {
                return Some(format!("{p} is not installed (apt-get install slurm-wlm munge)"));
            }
        }
        let uid = std::fs::read_to_string("/proc/self/status")
            .ok()
            .and_then(|s| s.lines().find(|l| l.starts_with("Uid:")).map(|l| l.to_string()))
            .and_then(|l| l.split_whitespace().nth(1).map(|u| u.to_string()));
        (uid.as_deref() != Some("0")).then(|| "not root: slurmd must run as root to start jobs".to_string())
    }

    fn start(dir: &Path) -> Cluster {
        let host = std::fs::read_to_string("/proc/sys/kernel/hostname").unwrap();
        let host = host.trim().split('.').next().unwrap().to_string();
        for d in ["state", "spool"] {
            std::fs::create_dir_all(dir.join(d)).unwrap();
        }
        let key = dir.join("munge.key");
        let mut bytes = vec![0u8; 128];
        use std::io::Read;
        std::fs::File::open("/dev/urandom").unwrap().read_exact(&mut bytes).unwrap();
        std::fs::write(&key, &bytes).unwrap();
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&key, std::fs::Permissions::from_mode(0o600)).unwrap();
        let d = |name: &str| dir.join(name).display().to_string();
        let conf = dir.join("slurm.conf");
        std::fs::write(
            &conf,
            format!(
                "ClusterName=voltextest\nSlurmctldHost={host}(127.0.0.1)\nAuthType=auth/munge\n\
                 AuthInfo=socket={sock}\nCredType=cred/munge\nSlurmUser=root\nSlurmdUser=root\n\
                 SlurmctldPort={p1}\nSlurmdPort={p2}\nStateSaveLocation={state}\nSlurmdSpoolDir={spool}\n\
                 SlurmctldPidFile={cpid}\nSlurmdPidFile={dpid}\nSlurmctldLogFile={clog}\nSlurmdLogFile={dlog}\n\
                 ProctrackType=proctrack/linuxproc\nTaskPlugin=task/none\nSchedulerType=sched/builtin\n\
                 SelectType=select/cons_tres\nSelectTypeParameters=CR_Core\nReturnToService=2\nMpiDefault=none\n\
                 JobCompType=jobcomp/none\nAccountingStorageType=accounting_storage/none\n\
                 JobAcctGatherType=jobacct_gather/none\nSwitchType=switch/none\nMailProg=/bin/true\n\
                 NodeName={host} NodeAddr=127.0.0.1 CPUs=2 RealMemory=1000 State=UNKNOWN\n\
                 PartitionName=debug Nodes={host} Default=YES MaxTime=INFINITE State=UP\n",
                sock = d("munge.sock"),
                p1 = free_port(),
                p2 = free_port(),
                state = d("state"),
                spool = d("spool"),
                cpid = d("slurmctld.pid"),
                dpid = d("slurmd.pid"),
                clog = d("slurmctld.log"),
                dlog = d("slurmd.log"),
            ),
        )
        .unwrap();
        let mut cluster = Cluster { dir: dir.to_path_buf(), conf: conf.clone(), daemons: Vec::new() };
        let munged = [
            "-F".to_string(),
            format!("--socket={}", d("munge.sock")),
            format!("--key-file={}", key.display()),
            format!("--pid-file={}", d("munged.pid")),
            format!("--log-file={}", d("munged.log")),
            format!("--seed-file={}", d("munged.seed")),
        ];
        cluster.spawn("munged", &munged);
        let sock = dir.join("munge.sock");
        cluster.until("munged's socket", || sock.exists());
        let conf_s = conf.display().to_string();
        cluster.spawn("slurmctld", &["-D".into(), "-f".into(), conf_s.clone()]);
        cluster.spawn("slurmd", &["-D".into(), "-f".into(), conf_s]);
        let conf_env = cluster.conf.clone();
        cluster.until("an idle node", || {
            Command::new(program("sinfo").unwrap())
                .args(["-h", "-o", "%T"])
                .env("SLURM_CONF", &conf_env)
                .output()
                .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "idle")
        });
        cluster
    }

    fn spawn(&mut self, name: &'static str, args: &[String]) {
        let log = std::fs::File::create(self.dir.join(format!("{name}.out"))).unwrap();
        let child = Command::new(program(name).unwrap())
            .args(args)
            .stdin(Stdio::null())
            .stdout(log.try_clone().unwrap())
            .stderr(log)
            .spawn()
            .unwrap();
        self.daemons.push((name, child));
    }

    fn until(&mut self, what: &str, ready: impl Fn() -> bool) {
        let start = Instant::now();
        while !ready() {
            for (name, child) in &mut self.daemons {
                if let Ok(Some(status)) = child.try_wait() {
                    panic!("{name} exited ({status}); see {}", self.dir.display());
                }
            }
            assert!(
                start.elapsed() < Duration::from_secs(60),
                "no {what} after 60 s; see {}",
                self.dir.display()
            );
            std::thread::sleep(Duration::from_millis(200));
        }
    }
}

impl Drop for Cluster {
    fn drop(&mut self) {
        // Stop the daemons this test started, by their pids, newest first.
        for (_, child) in self.daemons.iter_mut().rev() {
            let _ = Command::new("kill").args(["-TERM", &child.id().to_string()]).status();
            let start = Instant::now();
            while matches!(child.try_wait(), Ok(None)) && start.elapsed() < Duration::from_secs(10) {
                std::thread::sleep(Duration::from_millis(50));
            }
            if matches!(child.try_wait(), Ok(None)) {
                let _ = child.kill();
                let _ = child.wait();
            }
        }
    }
}

#[test]
fn slurm_array_and_merge_equal_a_one_machine_run() {
    if let Some(why) = Cluster::missing() {
        if std::env::var("VOLTEX_REQUIRE_SLURM").as_deref() == Ok("1") {
            panic!("VOLTEX_REQUIRE_SLURM=1 but {why}");
        }
        println!("skipped slurm_array_and_merge_equal_a_one_machine_run: {why}");
        eprintln!("skipped slurm_array_and_merge_equal_a_one_machine_run: {why}");
        return;
    }
    let start = Instant::now();
    let dir = scratch_dir("voltex-farm-slurm");
    let suite = suite(&dir);
    // One machine: references at 32x32, then the run to compare with.
    let size = ["--size", "32x32"];
    let update = voltex(
        &[&["regress", s(&suite), "--out", s(&dir.join("update")), "--update"][..], &size].concat(),
        &[],
    );
    assert_eq!(update.status.code(), Some(0));
    let local = dir.join("local");
    assert_eq!(
        voltex(&[&["regress", s(&suite), "--out", s(&local)][..], &size].concat(), &[]).status.code(),
        Some(0)
    );

    let cluster = Cluster::start(&dir.join("slurm"));
    let conf = cluster.conf.display().to_string();
    let env = [("SLURM_CONF", conf.as_str())];
    let farm = dir.join("farm");
    let args = [
        &["farm", "submit", "--engine", "slurm", "--shards", "3", "--wait", s(&suite), "--out", s(&farm)][..],
        &size,
    ];
    let run = voltex(&args.concat(), &env);
    assert_eq!(run.status.code(), Some(0), "{}", text(&run));
    let out = text(&run);
    assert!(
        out.contains("array job ") && out.contains("merge job ") && out.contains("3 scenes: 3 pass"),
        "{out}"
    );
    assert_eq!(verdicts(&farm), verdicts(&local));
    let (found, _) = voltex::regress::record::collect(&farm).unwrap();
    let mut shards: Vec<String> = found.iter().map(|f| f.record.shard.clone()).collect();
    shards.sort();
    assert_eq!(shards, ["1/3", "2/3", "3/3"], "one scene per shard");
    assert!(std::fs::read_to_string(farm.join("junit.xml")).unwrap().contains("tests=\"3\" failures=\"0\""));

    // A refused submission is an engine failure naming what was refused.
    let refused = voltex(
        &[
            "farm",
            "submit",
            "--engine",
            "slurm",
            "--shards",
            "2",
            s(&suite),
            "--out",
            s(&dir.join("r")),
            "--partition",
            "nope",
        ],
        &env,
    );
    assert_eq!(refused.status.code(), Some(4), "{}", text(&refused));
    assert!(text(&refused).contains("sbatch refused the array job"), "{}", text(&refused));
    // A shard that dies: jobs held at submission, shard 2 cancelled, the others released. The
    // merge names the lost shard; rerun alone, it completes the merge.
    let lost = dir.join("lost");
    let args = [
        &[
            "farm",
            "submit",
            "--engine",
            "slurm",
            "--shards",
            "3",
            s(&suite),
            "--out",
            s(&lost),
            "--sbatch-arg=--hold",
        ][..],
        &size,
    ];
    let held = voltex(&args.concat(), &env);
    assert_eq!(held.status.code(), Some(0), "{}", text(&held));
    let stdout = String::from_utf8_lossy(&held.stdout).into_owned();
    let id = |what: &str| {
        let line = stdout.lines().find(|l| l.starts_with(what)).unwrap_or_else(|| panic!("{what}: {stdout}"));
        line[what.len()..].split(':').next().unwrap().to_string()
    };
    let (array, merge) = (id("array job "), id("merge job "));
    let slurm = |cmd: &str, args: &[&str]| {
        let ok = Command::new(program(cmd).unwrap()).args(args).env("SLURM_CONF", &conf).status().unwrap();
        assert!(ok.success(), "{cmd} {args:?}");
    };
    slurm("scancel", &[&format!("{array}_2")]);
    for job in [format!("{array}_1"), format!("{array}_3"), merge.clone()] {
        slurm("scontrol", &["release", &job]);
    }
    let status = lost.join(".voltex/slurm/merge-status");
    let waited = Instant::now();
    while !status.exists() {
        assert!(waited.elapsed() < Duration::from_secs(60), "merge job {merge} did not end");
        std::thread::sleep(Duration::from_millis(200));
    }
    std::thread::sleep(Duration::from_millis(200));
    assert_eq!(
        std::fs::read_to_string(&status).unwrap().trim(),
        "3",
        "a merge with a lost shard is broken input"
    );
    let log = std::fs::read_to_string(lost.join(".voltex/slurm/merge.log")).unwrap();
    assert!(log.contains("merge: shard 2/3: missing"), "{log}");
    let rerun =
        voltex(&[&["regress", s(&suite), "--out", s(&lost), "--shard", "2/3"][..], &size].concat(), &[]);
    assert_eq!(rerun.status.code(), Some(0));
    let merged = voltex(&["regress", "--report-only", s(&lost)], &[]);
    assert_eq!(merged.status.code(), Some(0), "{}", text(&merged));
    assert_eq!(verdicts(&lost), verdicts(&local));

    drop(cluster);
    eprintln!("slurm test: {:.1} s", start.elapsed().as_secs_f64());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn farm_submit_without_sbatch_is_an_engine_failure() {
    let dir = scratch_dir("voltex-farm-nosbatch");
    let suite = suite(&dir);
    let empty = dir.join("empty-path");
    std::fs::create_dir_all(&empty).unwrap();
    let run = voltex(
        &["farm", "submit", "--engine", "slurm", "--shards", "2", s(&suite), "--out", s(&dir.join("out"))],
        &[("PATH", s(&empty))],
    );
    assert_eq!(run.status.code(), Some(4));
    assert!(text(&run).contains("sbatch not found on PATH"), "{}", text(&run));
    let missing = voltex(
        &[
            "farm",
            "submit",
            "--engine",
            "slurm",
            "--shards",
            "2",
            s(&dir.join("nope")),
            "--out",
            s(&dir.join("o")),
        ],
        &[],
    );
    assert_eq!(missing.status.code(), Some(3), "a missing scene folder is broken input");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn kubernetes_manifest_is_an_indexed_job_and_a_merge_job() {
    let dir = scratch_dir("voltex-farm-k8s");
    let suite = suite(&dir);
    let out = dir.join("k8s");
    let run = voltex(
        &[
            "farm",
            "manifest",
            "--engine",
            "kubernetes",
            "--shards",
            "4",
            s(&suite),
            "--out",
            s(&out),
            "--size",
            "64x64",
            "--gpus",
            "1",
            "--image",
            "example/voltex:1",
        ],
        &[],
    );
    assert_eq!(run.status.code(), Some(0));
    let text = std::fs::read_to_string(out.join("voltex-regress.yaml")).unwrap();
    let docs: Vec<serde_norway::Value> = serde_norway::Deserializer::from_str(&text)
        .map(|d| serde::Deserialize::deserialize(d).unwrap())
        .collect();
    assert_eq!(docs.len(), 2, "{text}");
    let (job, merge) = (&docs[0], &docs[1]);
    assert_eq!(job["kind"], "Job");
    assert_eq!(job["spec"]["completionMode"], "Indexed");
    assert_eq!(job["spec"]["completions"], 4);
    assert_eq!(job["spec"]["parallelism"], 4);
    let pod = &job["spec"]["template"]["spec"];
    assert_eq!(pod["restartPolicy"], "Never");
    let shard = &pod["containers"][0];
    assert_eq!(shard["image"], "example/voltex:1");
    assert_eq!(shard["resources"]["limits"]["nvidia.com/gpu"], 1);
    let cmd = shard["command"][2].as_str().unwrap();
    for w in
        ["'regress'", "'/data/suite'", "'--out' '/data/results'", "'--shard' 'auto/4'", "'--size' '64x64'"]
    {
        assert!(cmd.contains(w), "{w} in {cmd}");
    }
    assert_eq!(shard["volumeMounts"][0]["mountPath"], "/data");
    assert_eq!(pod["volumes"][0]["persistentVolumeClaim"]["claimName"], "voltex-regress");
    assert_eq!(merge["metadata"]["name"], "voltex-regress-merge");
    let merge_cmd: Vec<&str> = merge["spec"]["template"]["spec"]["containers"][0]["command"]
        .as_sequence()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    assert_eq!(merge_cmd, ["voltex", "regress", "--report-only", "/data/results"]);
    validate_with_kubernetes_schemas(&out.join("voltex-regress.yaml"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// Both Jobs against Kubernetes' own OpenAPI schemas, strictly (unknown fields rejected), with
/// `kubernetes-validate` from PyPI (`.ci/run` installs it and sets `VOLTEX_REQUIRE_K8S_VALIDATE=1`;
/// elsewhere the check is skipped with a message when the tool is missing).
fn validate_with_kubernetes_schemas(manifest: &Path) {
    let Some(tool) = program("kubernetes-validate") else {
        let why = "kubernetes-validate is not on PATH (pip install kubernetes-validate)";
        if std::env::var("VOLTEX_REQUIRE_K8S_VALIDATE").as_deref() == Ok("1") {
            panic!("VOLTEX_REQUIRE_K8S_VALIDATE=1 but {why}");
        }
        eprintln!("skipped the schema check of the Kubernetes manifest: {why}");
        return;
    };
    let run = Command::new(tool).arg("--strict").arg(manifest).output().unwrap();
    let said = text(&run);
    assert!(run.status.success(), "kubernetes-validate --strict rejects the manifest:\n{said}");
    assert_eq!(said.matches(" passed for resource job/").count(), 2, "{said}");
}
