//! The fuzz driver: a target's inputs under proptest, each with bounds on time and memory, and
//! the counts a campaign reports (inputs tried and accepted, the slowest and largest input).
//!
//! Time: an input over [`case_secs`] (10 s by default, `VOLTEX_FUZZ_CASE_SECS`) of its thread's
//! CPU time fails the target when it returns; the GPU targets, whose work runs in the driver's
//! threads, have three times the bound in the process's CPU time (all threads: software Vulkan's
//! work, which a loaded machine or `nice` does not inflate as it does wall time). A watchdog
//! thread prints the input and aborts the test binary (a blocked read cannot be interrupted) when
//! a case is a hang: its clock made no progress (0.1 s of CPU) for three times its bound of wall
//! time, or it has run three times its bound of CPU time. A case merely starved by a loaded
//! machine (a campaign under `nice -n 19` beside a build) still progresses, and is waited for.
//! Memory: the Rust heap a case has live at once (the counting allocator, per thread), and for
//! the GPU targets the growth of the process's resident memory, sampled by the watchdog (the
//! driver allocates outside Rust).
//!
//! Work that a mutated kernel decides (its draws and dispatches: an instance count of 16,384 where
//! voltex writes 1) is the user's, not voltex's: a target runs it inside [`kernel_work`], whose
//! CPU time and resident growth the case's bounds do not count. The watchdog still aborts a
//! kernel that runs on for [`KERNEL_FACTOR`] times the bound (a software driver has no timeout to
//! stop it).

use super::Tracked;
use proptest::prelude::*;
use proptest::test_runner::{RngAlgorithm, TestCaseError, TestRng, TestRunner};
use std::cell::{Cell, RefCell};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Memory bounds of one input.
#[derive(Debug, Clone, Copy)]
pub struct Bounds {
    /// Most bytes of Rust heap one case may have live at once.
    pub heap: usize,
    /// Most growth of the process's resident memory during one case; `None`: not sampled.
    pub rss: Option<u64>,
}

const MIB: usize = 1 << 20;

/// Inputs of a few KiB: a case has no reason to allocate more than this.
pub const SMALL: Bounds = Bounds { heap: 256 * MIB, rss: None };
/// Inputs that are large by design (counts near the budgets): the bound of 1 GiB.
pub const LARGE: Bounds = Bounds { heap: 1024 * MIB, rss: None };
/// Renders: 1 GiB of Rust heap, and 1 GiB of resident memory (the driver's allocations).
pub const GPU: Bounds = Bounds { heap: 1024 * MIB, rss: Some(1 << 30) };

thread_local! {
    /// Inputs of the running target that got through every stage without an error.
    static ACCEPTED: Cell<u64> = const { Cell::new(0) };
}

/// Counts the input as accepted (a target's test returns this after every stage passed).
pub fn accepted() -> Result<(), String> {
    ACCEPTED.with(|a| a.set(a.get() + 1));
    Ok(())
}

fn env<T: std::str::FromStr>(name: &str) -> Option<T> {
    std::env::var(name).ok().and_then(|v| v.parse().ok())
}

/// Seconds one input may take (`VOLTEX_FUZZ_CASE_SECS`, default 10).
pub fn case_secs() -> f64 {
    env("VOLTEX_FUZZ_CASE_SECS").unwrap_or(10.0)
}

/// CPU time in seconds on `clock`: `CLOCK_THREAD_CPUTIME_ID` (the calling thread) or
/// `CLOCK_PROCESS_CPUTIME_ID` (every thread, the driver's included). Either is the work of a
/// case, whatever the machine's load.
fn cpu_secs(clock: libc::clockid_t) -> f64 {
    let mut t = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: a valid timespec to fill.
    unsafe { libc::clock_gettime(clock, &mut t) };
    t.tv_sec as f64 + t.tv_nsec as f64 * 1e-9
}

/// The CPU clock of the calling thread, which another thread can read.
fn thread_clock() -> libc::clockid_t {
    let mut id: libc::clockid_t = libc::CLOCK_THREAD_CPUTIME_ID;
    // SAFETY: the calling thread's handle, and a clock id to fill.
    unsafe { libc::pthread_getcpuclockid(libc::pthread_self(), &mut id) };
    id
}

/// The process's resident memory in bytes (Linux; 0 elsewhere).
pub fn rss() -> u64 {
    let statm = std::fs::read_to_string("/proc/self/statm").unwrap_or_default();
    let pages: u64 = statm.split_whitespace().nth(1).and_then(|p| p.parse().ok()).unwrap_or(0);
    pages * 4096
}

/// The running case, as the watchdog sees it.
struct Case {
    /// Its input (`Debug`, shortened), and its number in the campaign.
    input: String,
    number: u64,
    /// The CPU clock its time is measured on, and its reading at the start.
    clock: libc::clockid_t,
    cpu_start: f64,
    /// When its clock last advanced by [`PROGRESS_SECS`], and the reading then.
    progress: (Instant, f64),
    /// CPU time spent in [`kernel_work`], and the case's time when the open section began.
    kernel: f64,
    kernel_since: Option<f64>,
}

impl Case {
    /// The case's CPU time so far, and how much of it was [`kernel_work`].
    fn cpu(&self) -> (f64, f64) {
        let cpu = cpu_secs(self.clock) - self.cpu_start;
        (cpu, self.kernel + self.kernel_since.map_or(0.0, |since| cpu - since))
    }
}

/// How many times its bound a case's [`kernel_work`] may run before the watchdog aborts.
pub const KERNEL_FACTOR: f64 = 20.0;

/// A case's growth of resident memory, less what its [`kernel_work`] grew (seed 30, input 81,215:
/// an instance count of 16,384 made llvmpipe's draw grow it by 2.3 GiB). Fed readings in bytes.
#[derive(Debug, Default, Clone, Copy)]
pub struct Resident {
    start: u64,
    /// Net growth inside kernel work, and the reading when the open section began.
    kernel: i64,
    open: Option<u64>,
    /// Highest reading outside kernel work, less `kernel`; largest growth inside a section.
    peak: u64,
    kernel_peak: u64,
}

impl Resident {
    pub fn new(rss: u64) -> Self {
        Self { start: rss, peak: rss, ..Self::default() }
    }

    pub fn sample(&mut self, rss: u64) {
        match self.open {
            Some(open) => self.kernel_peak = self.kernel_peak.max(rss.saturating_sub(open)),
            None => self.peak = self.peak.max((rss as i64 - self.kernel).max(0) as u64),
        }
    }

    /// A kernel section opens (`true`) or closes at reading `rss`.
    pub fn kernel_work(&mut self, open: bool, rss: u64) {
        if open {
            self.sample(rss);
            self.open = Some(rss);
        } else if let Some(at) = self.open.take() {
            self.kernel += rss as i64 - at as i64;
            self.sample(rss);
        }
    }

    /// The case's own growth: the bounded one.
    pub fn growth(&self) -> u64 {
        self.peak.saturating_sub(self.start)
    }
}

thread_local! {
    /// The watch of the campaign running on this thread, for [`kernel_work`].
    static RUNNING: RefCell<Option<Arc<Mutex<Watch>>>> = const { RefCell::new(None) };
}

/// Runs `work`, the GPU work of a kernel the input mutated, outside the case's time bound (not
/// nested: the inner section's end ends it).
pub fn kernel_work<T>(work: impl FnOnce() -> T) -> T {
    let mark = |open: bool| {
        let Some(watch) = RUNNING.with(|r| r.borrow().clone()) else { return };
        let w = &mut *watch.lock().unwrap();
        if let Some(case) = &mut w.case {
            let cpu = case.cpu().0;
            if open {
                case.kernel_since = Some(cpu);
            } else if let Some(since) = case.kernel_since.take() {
                case.kernel += cpu - since;
            }
            w.resident.kernel_work(open, rss());
        }
    };
    mark(true);
    let out = work();
    mark(false);
    out
}

/// CPU time a case must gain within its hang window to count as running (the watchdog's own
/// sampling stays far below it; a case starved under `nice -n 19` still gets more).
const PROGRESS_SECS: f64 = 0.1;

/// What the watchdog knows of the running case.
#[derive(Default)]
struct Watch {
    case: Option<Case>,
    /// The running case's resident memory (the GPU targets).
    resident: Resident,
    stop: bool,
}

/// Clears the running case when it ends, also by a panic.
struct CaseGuard<'a>(&'a Mutex<Watch>);

impl Drop for CaseGuard<'_> {
    fn drop(&mut self) {
        self.0.lock().unwrap().case = None;
    }
}

/// Whether a case whose clock reads `cpu` seconds at `now`, `kernel` of them in [`kernel_work`],
/// is a hang, within a bound of `limit` seconds: its clock gained under [`PROGRESS_SECS`] in
/// `3 limit` seconds of wall time since `progress` (updated here when it gained more), or it has
/// run `3 limit` seconds of CPU time outside kernel work, or [`KERNEL_FACTOR`]` limit` in it.
pub fn hang_verdict(
    progress: &mut (Instant, f64),
    (cpu, kernel): (f64, f64),
    now: Instant,
    limit: f64,
) -> Option<String> {
    if cpu - progress.1 >= PROGRESS_SECS {
        *progress = (now, cpu);
    }
    let window = 3.0 * limit;
    if now.duration_since(progress.0).as_secs_f64() > window {
        Some(format!("its CPU time stopped at {cpu:.1} s for {window:.0} s"))
    } else if cpu - kernel > window {
        Some(format!("it still runs after {:.0} s of CPU time", cpu - kernel))
    } else if kernel > KERNEL_FACTOR * limit {
        Some(format!("a mutated kernel's own work still runs after {kernel:.0} s of CPU time"))
    } else {
        None
    }
}

fn watchdog(
    name: String,
    watch: Arc<Mutex<Watch>>,
    sample_rss: bool,
    limit: f64,
) -> std::thread::JoinHandle<()> {
    std::thread::spawn(move || loop {
        std::thread::sleep(Duration::from_millis(if sample_rss { 20 } else { 200 }));
        let mut w = watch.lock().unwrap();
        if w.stop {
            return;
        }
        if sample_rss && w.case.is_some() {
            w.resident.sample(rss());
        }
        if let Some(case) = &mut w.case {
            let cpu = case.cpu();
            if let Some(why) = hang_verdict(&mut case.progress, cpu, Instant::now(), limit) {
                let (n, input) = (case.number, &case.input);
                eprintln!(
                    "fuzz {name}: a hang ({why}; the bound is {limit} s) at input {n} (alone: VOLTEX_FUZZ_FROM={n} \
                     VOLTEX_FUZZ_CASES={}), aborting: {input}",
                    n + 1,
                );
                std::process::abort();
            }
        }
    })
}

fn shorten(mut s: String, max: usize) -> String {
    if s.len() > max {
        let mut cut = max;
        while !s.is_char_boundary(cut) {
            cut -= 1;
        }
        s.truncate(cut);
        s += "…";
    }
    s
}

/// Which inputs of a target a run tries: inputs `from..cases` of the stream `seed` generates.
#[derive(Debug, Clone, Copy)]
pub struct Campaign {
    /// Inputs generated in all (`VOLTEX_FUZZ_CASES`, else the target's default).
    pub cases: u32,
    /// The random seed (`VOLTEX_FUZZ_SEED`, default 0, so CI is reproducible).
    pub seed: u64,
    /// Inputs generated but not run (`VOLTEX_FUZZ_FROM`, default 0): a resumed campaign. The
    /// inputs are the same, since generating one does not depend on what a test did, so a long
    /// campaign can run in pieces, or in shards on several machines, and still cover `0..cases`.
    pub from: u64,
    /// An input's bound in seconds ([`case_secs`]; three times it for the GPU targets).
    pub case_secs: f64,
}

impl Campaign {
    /// The campaign the environment asks for, `default_cases` inputs unless it says.
    pub fn from_env(default_cases: u32) -> Self {
        Self {
            cases: env("VOLTEX_FUZZ_CASES").unwrap_or(default_cases),
            seed: env("VOLTEX_FUZZ_SEED").unwrap_or(0),
            from: env("VOLTEX_FUZZ_FROM").unwrap_or(0),
            case_secs: case_secs(),
        }
    }
}

/// Runs `test` on the inputs of `strategy` the environment asks for (see [`Campaign`]), each
/// within `bounds`; proptest shrinks a failure.
pub fn fuzz<S: Strategy>(
    name: &str,
    default_cases: u32,
    bounds: Bounds,
    strategy: S,
    test: impl Fn(S::Value) -> Result<(), String>,
) where
    S::Value: std::fmt::Debug,
{
    run_campaign(name, Campaign::from_env(default_cases), bounds, strategy, test);
}

/// Runs `test` on inputs `from..cases` of `strategy` within `bounds`. Prints the inputs tried
/// and accepted, the slowest input, the largest heap and resident memory of one input, and the
/// target's wall time.
pub fn run_campaign<S: Strategy>(
    name: &str,
    Campaign { cases, seed, from, case_secs }: Campaign,
    bounds: Bounds,
    strategy: S,
    test: impl Fn(S::Value) -> Result<(), String>,
) where
    S::Value: std::fmt::Debug,
{
    let config = ProptestConfig {
        cases,
        failure_persistence: None,
        // `VOLTEX_FUZZ_SHRINK_ITERS=0` reports a failure as found, where shrinking would rerun
        // it after other inputs changed shared state (the GPU targets' cache).
        max_shrink_iters: env("VOLTEX_FUZZ_SHRINK_ITERS").unwrap_or(4096),
        // Shrinking a slow input runs it again and again: two minutes, then the input as it is.
        max_shrink_time: 120_000,
        ..ProptestConfig::default()
    };
    let mut seed_bytes = [0u8; 32];
    seed_bytes[..8].copy_from_slice(&seed.to_le_bytes());
    let rng = TestRng::from_seed(RngAlgorithm::ChaCha, &seed_bytes);
    let mut runner = TestRunner::new_with_rng(config, rng);
    let rss_text = |grew: u64| match bounds.rss {
        Some(_) => format!(", resident +{} MiB", grew >> 20),
        None => String::new(),
    };
    let watch = Arc::new(Mutex::new(Watch::default()));
    // GPU targets: three times the bound (software Vulkan's work counts from every thread).
    let limit = if bounds.rss.is_some() { 3.0 * case_secs } else { case_secs };
    let dog = watchdog(name.to_string(), watch.clone(), bounds.rss.is_some(), limit);
    let outer = RUNNING.with(|r| r.replace(Some(watch.clone())));
    let (tried, slowest, heap_peak, rss_peak) =
        (Cell::new(0u64), Cell::new(0f64), Cell::new(0usize), Cell::new(0u64));
    // The most CPU time and resident growth of one input's kernel work.
    let kernel_peak = Cell::new((0f64, 0u64));
    let start = Instant::now();
    let last_report = Cell::new(start);
    let accepted_before = ACCEPTED.with(Cell::get);
    let result = runner.run(&strategy, |value| {
        tried.set(tried.get() + 1);
        if tried.get() <= from {
            return Ok(());
        }
        // A long campaign's progress, once a minute (its figures if it is stopped).
        if last_report.get().elapsed() > Duration::from_secs(60) {
            last_report.set(Instant::now());
            eprintln!(
                "fuzz {name}: {} inputs so far, {} accepted, {:.0} s; slowest input {:.2} s, largest heap {} MiB{}",
                tried.get() - 1 - from,
                ACCEPTED.with(Cell::get) - accepted_before,
                start.elapsed().as_secs_f64(),
                slowest.get(),
                heap_peak.get() >> 20,
                rss_text(rss_peak.get()),
            );
        }
        let input = shorten(format!("{value:?}"), 2000);
        let clock = match bounds.rss {
            // GPU targets: the driver works in threads of its own.
            Some(_) => libc::CLOCK_PROCESS_CPUTIME_ID,
            // This thread's clock by its id, which the watchdog can read too.
            None => thread_clock(),
        };
        let cpu_start = cpu_secs(clock);
        {
            let mut w = watch.lock().unwrap();
            w.resident = Resident::new(if bounds.rss.is_some() { rss() } else { 0 });
            let progress = (Instant::now(), 0.0);
            let number = tried.get() - 1;
            let (kernel, kernel_since) = (0.0, None);
            w.case = Some(Case { input: input.clone(), number, clock, cpu_start, progress, kernel, kernel_since });
        }
        let guard = CaseGuard(&watch);
        let heap_start = Tracked::begin_case();
        let outcome = test(value);
        let heap = Tracked::peak_since(heap_start);
        let (secs, grew) = {
            let w = watch.lock().unwrap();
            let (cpu, kernel) = w.case.as_ref().map_or((0.0, 0.0), Case::cpu);
            let mut resident = w.resident;
            resident.sample(rss());
            let (most_cpu, most_rss) = kernel_peak.get();
            kernel_peak.set((most_cpu.max(kernel), most_rss.max(resident.kernel_peak)));
            (cpu - kernel, if bounds.rss.is_some() { resident.growth() } else { 0 })
        };
        drop(guard);
        slowest.set(slowest.get().max(secs));
        heap_peak.set(heap_peak.get().max(heap));
        rss_peak.set(rss_peak.get().max(grew));
        outcome.map_err(TestCaseError::fail)?;
        if secs > limit {
            return Err(TestCaseError::fail(format!("took {secs:.1} s, over the bound of {limit} s")));
        }
        if heap > bounds.heap {
            let msg =
                format!("allocated {} MiB at once, over the bound of {} MiB", heap >> 20, bounds.heap >> 20);
            return Err(TestCaseError::fail(msg));
        }
        if let Some(max) = bounds.rss.filter(|&m| grew > m) {
            let msg =
                format!("resident memory grew by {} MiB, over the bound of {} MiB", grew >> 20, max >> 20);
            return Err(TestCaseError::fail(msg));
        }
        Ok(())
    });
    RUNNING.with(|r| r.replace(outer));
    watch.lock().unwrap().stop = true;
    dog.join().unwrap();
    eprintln!(
        "fuzz {name}: {} inputs tried, {} accepted (seed {seed}, inputs {from}..{cases}, {:.1} s; slowest input \
         {:.2} s, largest heap {} MiB{}; most kernel work {:.2} s, resident +{} MiB)",
        tried.get().saturating_sub(from),
        ACCEPTED.with(Cell::get) - accepted_before,
        start.elapsed().as_secs_f64(),
        slowest.get(),
        heap_peak.get() >> 20,
        rss_text(rss_peak.get()),
        kernel_peak.get().0,
        kernel_peak.get().1 >> 20,
    );
    if let Err(e) = result {
        panic!("fuzz {name}: {e}");
    }
}
