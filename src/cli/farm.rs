//! `voltex farm`: regression runs on a cluster's own engine. `submit --engine slurm` submits an
//! array job (task k runs `regress --shard auto/N`, shard k of the cost plan) and a merge job after
//! it (`afterany`, so lost shards are reported, not waited for); `manifest --engine kubernetes`
//! writes an Indexed Job and its merge Job for `kubectl apply`.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

use voltex::regress::exit;
use voltex::regress::shards::{self, STATE_DIR};

#[derive(clap::Args)]
pub struct FarmArgs {
    #[command(subcommand)]
    command: FarmCommand,
}

#[derive(clap::Subcommand)]
enum FarmCommand {
    /// Submit DIR's regression run as an array job of N shards and a merge job after it; print
    /// the job ids (and with --wait, block until the merge ends and exit with its status).
    Submit(SubmitArgs),
    /// Write the engine's job files for DIR's regression run in N shards, without submitting.
    Manifest(ManifestArgs),
}

#[derive(clap::ValueEnum, Clone, Copy, PartialEq, Eq, Debug)]
enum Engine {
    Slurm,
    Kubernetes,
}

/// Options passed through to every shard's `voltex regress`.
#[derive(clap::Args, Clone)]
struct Pass {
    /// Render size WIDTHxHEIGHT for every scene (regress --size).
    #[arg(long, value_parser = super::parse_size)]
    size: Option<(u32, u32)>,
    /// Write references of new, regressed and other-size scenes (regress --update).
    #[arg(long)]
    update: bool,
    /// Mean FLIP a scene may reach, for every scene (regress --max-flip).
    #[arg(long, value_parser = voltex::regress::parse_max_flip)]
    max_flip: Option<f64>,
    /// Relative RMSE a scene may reach, for every scene (regress --max-rel-rmse).
    #[arg(long, value_parser = voltex::regress::parse_max_rel_rmse)]
    max_rel_rmse: Option<f64>,
    /// Render scenes whose record is current too (regress --force).
    #[arg(long)]
    force: bool,
    /// Scenes each shard renders at a time (regress --jobs).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=256))]
    jobs: u32,
}

impl Pass {
    fn args(&self) -> Vec<String> {
        let mut a = Vec::new();
        if let Some((w, h)) = self.size {
            a.extend(["--size".into(), format!("{w}x{h}")]);
        }
        if self.update {
            a.push("--update".into());
        }
        if self.force {
            a.push("--force".into());
        }
        if let Some(v) = self.max_flip {
            a.extend(["--max-flip".into(), v.to_string()]);
        }
        if let Some(v) = self.max_rel_rmse {
            a.extend(["--max-rel-rmse".into(), v.to_string()]);
        }
        if self.jobs != 1 {
            a.extend(["--jobs".into(), self.jobs.to_string()]);
        }
        a
    }
}

#[derive(clap::Args)]
struct SubmitArgs {
    /// The engine that runs the jobs (kubernetes: see `farm manifest`).
    #[arg(long, value_enum)]
    engine: Engine,
    /// Number of shards (array tasks).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=10_000))]
    shards: u32,
    /// Block until the merge job ends, then print its summary and exit with its status.
    #[arg(long)]
    wait: bool,
    /// Scene folder, on a file system the compute nodes see at the same path.
    dir: PathBuf,
    /// Output folder (shared with the nodes): a folder per scene, index.html, junit.xml, and
    /// .voltex/ with the plan, shard manifests, job scripts and logs.
    #[arg(short = 'o', long, visible_alias = "output")]
    out: PathBuf,
    #[command(flatten)]
    pass: Pass,
    /// Slurm partition (sbatch --partition).
    #[arg(long)]
    partition: Option<String>,
    /// Slurm account (sbatch --account).
    #[arg(long)]
    account: Option<String>,
    /// Time limit of each shard and of the merge (sbatch --time, e.g. 30:00).
    #[arg(long)]
    time: Option<String>,
    /// GPUs per shard (sbatch --gpus); the merge asks for none.
    #[arg(long)]
    gpus: Option<u32>,
    /// Further sbatch option for the shards and the merge (repeatable), e.g. --sbatch-arg=--qos=low.
    #[arg(long, value_name = "OPTION", allow_hyphen_values = true)]
    sbatch_arg: Vec<String>,
    /// The voltex binary the nodes run (default: this one, which they must see at its path).
    #[arg(long, value_name = "PATH")]
    voltex: Option<PathBuf>,
}

#[derive(clap::Args)]
struct ManifestArgs {
    /// The engine to write job files for.
    #[arg(long, value_enum)]
    engine: Engine,
    /// Number of shards (completions of the Indexed Job).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=10_000))]
    shards: u32,
    /// Scene folder (checked here; inside the pods it is --suite-path).
    dir: PathBuf,
    /// Folder to write voltex-regress.yaml into.
    #[arg(short = 'o', long, visible_alias = "output")]
    out: PathBuf,
    #[command(flatten)]
    pass: Pass,
    /// Container image with voltex on its PATH and a Vulkan driver (placeholder: your image).
    #[arg(long, default_value = "voltex:latest")]
    image: String,
    /// PersistentVolumeClaim (ReadWriteMany) mounted at /data in every pod: the suite and results.
    #[arg(long, default_value = "voltex-regress")]
    claim: String,
    /// The scene folder inside the pods.
    #[arg(long, default_value = "/data/suite")]
    suite_path: String,
    /// The output folder inside the pods (on the shared volume).
    #[arg(long, default_value = "/data/results")]
    results_path: String,
    /// GPUs per shard pod (resources.limits "nvidia.com/gpu").
    #[arg(long)]
    gpus: Option<u32>,
    /// Name of the Indexed Job (the merge Job is NAME-merge).
    #[arg(long, default_value = "voltex-regress")]
    name: String,
}

/// Why `voltex farm` failed, and its exit status.
pub enum FarmError {
    /// The engine is missing, refused the jobs or lost them.
    Engine(String),
    /// Anything else (bad folder, unwritable output).
    Input(voltex::Error),
}

impl From<voltex::Error> for FarmError {
    fn from(e: voltex::Error) -> Self {
        FarmError::Input(e)
    }
}

impl FarmError {
    pub fn code(&self) -> u8 {
        match self {
            FarmError::Engine(_) => exit::ENGINE,
            FarmError::Input(e) => exit::of_error(e),
        }
    }
}

impl std::fmt::Display for FarmError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            FarmError::Engine(m) => write!(f, "{m}"),
            FarmError::Input(e) => write!(f, "{e}"),
        }
    }
}

/// Runs `voltex farm`; the exit status on success (the merge's with `submit --wait`, else 0).
pub fn run(args: FarmArgs) -> Result<u8, FarmError> {
    match args.command {
        FarmCommand::Submit(a) => match a.engine {
            Engine::Slurm => submit_slurm(a),
            Engine::Kubernetes => Err(FarmError::Input(voltex::Error::Invalid(
                "farm submit drives Slurm only: write Kubernetes jobs with `voltex farm manifest --engine \
                 kubernetes` and apply them with kubectl"
                    .into(),
            ))),
        },
        FarmCommand::Manifest(a) => match a.engine {
            Engine::Kubernetes => kubernetes_manifest(a),
            Engine::Slurm => Err(FarmError::Input(voltex::Error::Invalid(
                "farm manifest writes Kubernetes jobs only: `voltex farm submit --engine slurm` submits to Slurm"
                    .into(),
            ))),
        },
    }
}

fn absolute(path: &Path) -> Result<PathBuf, FarmError> {
    std::fs::canonicalize(path).map_err(|e| FarmError::Input(voltex::Error::file(path, e)))
}

/// A word for `sh`, single-quoted.
fn sh(word: &str) -> String {
    format!("'{}'", word.replace('\'', "'\\''"))
}

fn submit_slurm(a: SubmitArgs) -> Result<u8, FarmError> {
    let n = a.shards as usize;
    let dir = absolute(&a.dir)?;
    let plan = shards::prepare(&dir, &a.out, n, a.pass.size)?;
    let out = absolute(&a.out)?;
    let exe = match &a.voltex {
        Some(p) => p.clone(),
        None => std::env::current_exe()
            .map_err(|e| voltex::Error::Invalid(format!("cannot find this binary: {e}")))?,
    };
    let jobs = out.join(STATE_DIR).join("slurm");
    std::fs::create_dir_all(&jobs).map_err(|e| voltex::Error::file(&jobs, e))?;
    let status_file = jobs.join("merge-status");
    let _ = std::fs::remove_file(&status_file);

    let mut shard_cmd = vec![exe.display().to_string(), "regress".into(), dir.display().to_string()];
    shard_cmd.extend(["--out".into(), out.display().to_string(), "--shard".into(), format!("auto/{n}")]);
    shard_cmd.extend(a.pass.args());
    let shard_script = jobs.join("shard.sh");
    write_script(&shard_script, &format!("{}\n", words(&shard_cmd)))?;
    let merge_cmd =
        [exe.display().to_string(), "regress".into(), "--report-only".into(), out.display().to_string()];
    let merge_script = jobs.join("merge.sh");
    write_script(
        &merge_script,
        &format!(
            "{}\nstatus=$?\necho $status > {}\nexit $status\n",
            words(&merge_cmd),
            sh(&status_file.display().to_string())
        ),
    )?;

    let mut common = Vec::new();
    for (flag, v) in [("--partition", &a.partition), ("--account", &a.account), ("--time", &a.time)] {
        if let Some(v) = v {
            common.push(format!("{flag}={v}"));
        }
    }
    common.extend(a.sbatch_arg.iter().cloned());
    let mut array = vec![
        "--parsable".to_string(),
        "--job-name=voltex-regress".into(),
        format!("--array=1-{n}"),
        format!("--output={}", jobs.join("shard-%a.log").display()),
    ];
    if let Some(g) = a.gpus {
        array.push(format!("--gpus={g}"));
    }
    array.extend(common.iter().cloned());
    array.push(shard_script.display().to_string());
    let array_id = sbatch(&array, "the array job")?;
    let mut merge = vec![
        "--parsable".to_string(),
        "--job-name=voltex-merge".into(),
        format!("--dependency=afterany:{array_id}"),
        format!("--output={}", jobs.join("merge.log").display()),
    ];
    merge.extend(common);
    merge.push(merge_script.display().to_string());
    let merge_id = match sbatch(&merge, "the merge job") {
        Ok(id) => id,
        Err(e) => {
            // No merge to judge the array: do not leave it running unjudged.
            let _ = Command::new("scancel").arg(&array_id).status();
            return Err(FarmError::Engine(format!("{e} (array job {array_id} cancelled)")));
        }
    };
    print!("{}", plan.table());
    println!("array job {array_id}: {n} shard(s), logs {}", jobs.join("shard-N.log").display());
    println!("merge job {merge_id}: after the array (afterany), report {}", out.join("index.html").display());
    if !a.wait {
        return Ok(exit::PASS);
    }
    wait_slurm(&merge_id, n, plan.makespan() / 1e3, &out, &status_file, &jobs.join("merge.log"))
}

fn words(cmd: &[String]) -> String {
    cmd.iter().map(|w| sh(w)).collect::<Vec<_>>().join(" ")
}

fn write_script(path: &Path, body: &str) -> Result<(), FarmError> {
    let text = format!("#!/bin/sh\n# Written by voltex farm submit.\n{body}");
    voltex::io::atomic::write_bytes(path, text.as_bytes())?;
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o755))
            .map_err(|e| voltex::Error::file(path, e))?;
    }
    Ok(())
}

/// Runs sbatch; its job id, or an engine error naming what was refused.
fn sbatch(args: &[String], what: &str) -> Result<String, FarmError> {
    let out = Command::new("sbatch").args(args).output().map_err(|e| {
        FarmError::Engine(if e.kind() == std::io::ErrorKind::NotFound {
            "sbatch not found on PATH: is Slurm's client installed on this machine? \
             (farm submit --engine slurm submits with sbatch)"
                .to_string()
        } else {
            format!("cannot run sbatch: {e}")
        })
    })?;
    let stderr = String::from_utf8_lossy(&out.stderr).trim().to_string();
    if !out.status.success() {
        return Err(FarmError::Engine(format!("sbatch refused {what} ({}): {stderr}", out.status)));
    }
    let stdout = String::from_utf8_lossy(&out.stdout);
    let id = stdout.trim().split(';').next().unwrap_or("").to_string();
    if id.is_empty() || !id.chars().all(|c| c.is_ascii_digit()) {
        return Err(FarmError::Engine(format!("sbatch gave no job id for {what}: {stdout:?} {stderr}")));
    }
    Ok(id)
}

/// Waits for the merge job: its state from `scontrol`, else (once Slurm forgot the job) the
/// status its script wrote. Prints shard progress as manifests finish, against the plan's
/// predicted makespan (queueing not included).
fn wait_slurm(
    merge_id: &str,
    count: usize,
    makespan_s: f64,
    out: &Path,
    status_file: &Path,
    log: &Path,
) -> Result<u8, FarmError> {
    let start = std::time::Instant::now();
    let mut shown = None;
    loop {
        let progress = shards::finished_shards(out);
        if shown != Some(progress) {
            let mmss = |s: f64| format!("{}:{:02}", s as u64 / 60, s as u64 % 60);
            eprintln!(
                "shards: {} of {count} finished, {} started; {} elapsed (the plan predicts {} once running)",
                progress.0,
                progress.1,
                mmss(start.elapsed().as_secs_f64()),
                mmss(makespan_s.ceil())
            );
            shown = Some(progress);
        }
        let info = Command::new("scontrol").args(["show", "job", "-o", merge_id]).output();
        let line = info.as_ref().map(|o| String::from_utf8_lossy(&o.stdout).into_owned()).unwrap_or_default();
        let field = |key: &str| line.split_whitespace().find_map(|w| w.strip_prefix(key)).map(str::to_string);
        let state = field("JobState=");
        let terminal = match state.as_deref() {
            Some("PENDING" | "RUNNING" | "CONFIGURING" | "COMPLETING" | "SUSPENDED" | "REQUEUED") => false,
            Some(_) => true,
            // Unknown to scontrol: finished long ago, or scontrol is missing.
            None => true,
        };
        if terminal {
            let text = std::fs::read_to_string(log).unwrap_or_default();
            print!("{text}");
            if let Some(code) =
                std::fs::read_to_string(status_file).ok().and_then(|s| s.trim().parse::<u8>().ok())
            {
                return Ok(code);
            }
            let state = state.unwrap_or_else(|| "unknown to scontrol".into());
            return Err(FarmError::Engine(format!(
                "merge job {merge_id} ended ({state}, exit {}) without a verdict; see {}",
                field("ExitCode=").unwrap_or_else(|| "?".into()),
                log.display()
            )));
        }
        std::thread::sleep(Duration::from_millis(500));
    }
}

fn kubernetes_manifest(a: ManifestArgs) -> Result<u8, FarmError> {
    let n = a.shards as usize;
    let all = voltex::regress::find(&a.dir)?;
    if all.is_empty() {
        return Err(voltex::Error::file(&a.dir, "no scene files (*.ron) in this folder").into());
    }
    std::fs::create_dir_all(&a.out).map_err(|e| voltex::Error::file(&a.out, e))?;
    let mut shard_cmd = vec![
        "voltex".to_string(),
        "regress".into(),
        a.suite_path.clone(),
        "--out".into(),
        a.results_path.clone(),
        "--shard".into(),
        format!("auto/{n}"),
    ];
    shard_cmd.extend(a.pass.args());
    let merge_cmd = ["voltex".to_string(), "regress".into(), "--report-only".into(), a.results_path.clone()];
    // Regressions (status 1) are results, not a failed shard: only other failures retry the pod.
    let shard_sh = format!("{}; s=$?; if [ $s -eq 1 ]; then exit 0; fi; exit $s", words(&shard_cmd));
    let gpus = a
        .gpus
        .map(|g| format!("\n          resources:\n            limits:\n              nvidia.com/gpu: {g}"));
    let yaml = format!(
        "# voltex farm manifest --engine kubernetes: {n} shard(s) of {dir} ({scenes} scenes).\n\
         # Placeholders: the image ({image}) must hold voltex on its PATH and a Vulkan driver; the\n\
         # PersistentVolumeClaim {claim} (ReadWriteMany) holds the suite at {suite} and the results at\n\
         # {results}. Apply the first Job, wait for it, then the merge:\n\
         #   kubectl apply -f voltex-regress.yaml -l voltex-part=shards\n\
         #   kubectl wait --for=condition=complete --timeout=-1s job/{name}\n\
         #   kubectl apply -f voltex-regress.yaml -l voltex-part=merge\n\
         apiVersion: batch/v1\n\
         kind: Job\n\
         metadata:\n  name: {name}\n  labels:\n    app: voltex-regress\n    voltex-part: shards\n\
         spec:\n  completionMode: Indexed\n  completions: {n}\n  parallelism: {n}\n  backoffLimit: {retries}\n\
         \x20 podFailurePolicy:\n    rules:\n      - action: FailJob\n        onExitCodes:\n          containerName: shard\n          operator: In\n          values: [{usage}]\n\
         \x20 template:\n    metadata:\n      labels:\n        app: voltex-regress\n    spec:\n      restartPolicy: Never\n\
         \x20     containers:\n        - name: shard\n          image: {image_q}\n          command: [\"sh\", \"-c\", {shard_q}]{gpus}\n\
         \x20         volumeMounts:\n            - name: data\n              mountPath: /data\n\
         \x20     volumes:\n        - name: data\n          persistentVolumeClaim:\n            claimName: {claim_q}\n\
         ---\n\
         apiVersion: batch/v1\n\
         kind: Job\n\
         metadata:\n  name: {name}-merge\n  labels:\n    app: voltex-regress\n    voltex-part: merge\n\
         spec:\n  completions: 1\n  backoffLimit: 0\n\
         \x20 template:\n    metadata:\n      labels:\n        app: voltex-regress\n    spec:\n      restartPolicy: Never\n\
         \x20     containers:\n        - name: merge\n          image: {image_q}\n          command: [{merge_q}]\n\
         \x20         volumeMounts:\n            - name: data\n              mountPath: /data\n\
         \x20     volumes:\n        - name: data\n          persistentVolumeClaim:\n            claimName: {claim_q}\n",
        dir = a.dir.display(),
        scenes = all.len(),
        image = a.image,
        claim = a.claim,
        suite = a.suite_path,
        results = a.results_path,
        name = a.name,
        retries = n.max(1),
        usage = exit::USAGE,
        image_q = json(&a.image),
        shard_q = json(&shard_sh),
        gpus = gpus.unwrap_or_default(),
        claim_q = json(&a.claim),
        merge_q = merge_cmd.iter().map(|w| json(w)).collect::<Vec<_>>().join(", "),
    );
    let path = a.out.join("voltex-regress.yaml");
    voltex::io::atomic::write_bytes(&path, yaml.as_bytes())?;
    println!("wrote {} (Indexed Job {} of {n} shard(s), merge Job {}-merge)", path.display(), a.name, a.name);
    Ok(exit::PASS)
}

/// A YAML double-quoted scalar (JSON strings are valid YAML).
fn json(s: &str) -> String {
    serde_json::to_string(s).unwrap_or_default()
}
