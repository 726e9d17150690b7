//! The `pool` and `split` executors: rayon pools of named threads.
//!
//! A pool of `K` threads on `C` cores runs its lanes on a rayon pool of
//! `L = min(K, C)` threads, `pool-0..L-1`; the lane rule (`lanes_for`)
//! never gives a section more than `L` lanes, so threads beyond the cores
//! could never help. They are started all the same, `pool-L..K-1`, as real
//! threads that block until the pool ends: the user asked for `K`, the
//! panel shows them (idle, no CPU) and the system's refusal of one still
//! counts. Were they in the rayon pool, every woken rayon thread that finds
//! work wakes another sleeping one (`Sleep::work_found`) and spins 32
//! yields before sleeping again: with 256 threads on 2 cores each section
//! set off a chain of wakes (4.4x slower than worker at 10k spheres).
//! A section of all `L` lanes is a broadcast, lane `i` on `pool-i`, which
//! wakes the other `L - 1` threads and no others.
use crate::cpu::ThreadRole;
use crate::physics::Exec;
use crate::physics::exec::{Bound, Busy};
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, mpsc};
use std::time::Instant;

/// Data decomposition: `K` threads `pool-0..K-1`, at most one lane a core.
pub struct PoolExec {
    /// `pool-0..L-1`, the threads that run lanes.
    pool: rayon::ThreadPool,
    /// `pool-L..K-1`, blocked until the pool is dropped.
    _spare: Spare,
    /// `(name, tid)` of all `K`, read once at start (asking a rayon pool
    /// again would wake every thread).
    tids: Vec<(String, i32)>,
    threads: usize,
    cores: usize,
    /// The widest section since `take_busy`, and what bound it (`Bound` as
    /// its index).
    busy: AtomicUsize,
    bound: AtomicUsize,
    /// Nanoseconds spent inside sections of more than one lane, for a
    /// step's serial fraction: two clock reads a section.
    parallel_ns: AtomicU64,
}

impl PoolExec {
    /// # Errors
    /// When the system refuses a thread (`ulimit -u`, `ulimit -v`).
    pub fn new(threads: usize) -> Result<PoolExec, Refused> {
        let cores = std::thread::available_parallelism().map_or(1, std::num::NonZero::get);
        PoolExec::on_cores(threads, cores)
    }

    /// A pool of `threads` as if the machine had `cores` cores (tests of a
    /// machine wider than this one).
    ///
    /// # Errors
    /// When the system refuses a thread (`ulimit -u`, `ulimit -v`).
    pub fn on_cores(threads: usize, cores: usize) -> Result<PoolExec, Refused> {
        let threads = threads.max(1);
        let cores = cores.max(1);
        let what = || format!("{threads} pool threads");
        // The build error's text is its cause's, and its source that cause
        // again: say it once, as bad input (exit 2), naming what failed.
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads.min(cores))
            .thread_name(pool_name)
            .build()
            .map_err(|e| Refused::new(what(), e.to_string()))?;
        let spare = Spare::start(threads.min(cores), threads)
            .map_err(|e| Refused::new(what(), e.to_string()))?;
        let mut tids = thread_ids(&pool);
        tids.extend(spare.tids.iter().cloned());
        Ok(PoolExec {
            pool,
            _spare: spare,
            tids,
            threads,
            cores,
            busy: AtomicUsize::new(0),
            bound: AtomicUsize::new(0),
            parallel_ns: AtomicU64::new(0),
        })
    }

    /// Seconds spent so far inside sections that ran on more than one lane.
    pub fn parallel_seconds(&self) -> f64 {
        self.parallel_ns.load(Ordering::Relaxed) as f64 * 1e-9
    }

    pub fn threads(&self) -> usize {
        self.threads
    }

    /// How many of the threads can run lanes (`min(threads, cores)`); the
    /// rest wait without a lane.
    pub fn lane_threads(&self) -> usize {
        self.pool.current_num_threads()
    }

    /// `(name, kernel thread id)` of every pool thread (Linux).
    pub fn thread_ids(&self) -> Vec<(String, i32)> {
        self.tids.clone()
    }
}

/// The threads beyond the cores: each parks until the pool is dropped, so
/// it takes no CPU. They allocate nothing once started (a preallocated
/// channel, `gettid`, `park`): at the edge of `ulimit -v` a refused start
/// stays a refusal, never an aborted allocation in a thread that did start.
struct Spare {
    stop: Arc<AtomicBool>,
    handles: Vec<std::thread::JoinHandle<()>>,
    tids: Vec<(String, i32)>,
}

impl Spare {
    fn start(from: usize, to: usize) -> std::io::Result<Spare> {
        let n = to.saturating_sub(from);
        let (told, heard) = mpsc::sync_channel(n);
        let mut spare = Spare {
            stop: Arc::new(AtomicBool::new(false)),
            handles: Vec::with_capacity(n),
            tids: Vec::with_capacity(n),
        };
        for i in from..to {
            let (told, stop) = (told.clone(), spare.stop.clone());
            let spawned = std::thread::Builder::new()
                .name(pool_name(i))
                .spawn(move || {
                    let _ = told.send((i, crate::cpu::current_tid()));
                    drop(told);
                    while !stop.load(Ordering::Acquire) {
                        std::thread::park();
                    }
                });
            // On a refusal `spare` drops: the started threads end and give
            // their stacks back before the refusal is reported.
            spare.handles.push(spawned?);
        }
        drop(told);
        let mut tids: Vec<(usize, i32)> = heard
            .iter()
            .filter_map(|(i, tid)| tid.map(|t| (i, t)))
            .collect();
        tids.sort_unstable_by_key(|t| t.0);
        spare.tids = tids
            .into_iter()
            .map(|(i, tid)| (pool_name(i), tid))
            .collect();
        Ok(spare)
    }
}

impl Drop for Spare {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Release);
        for h in self.handles.drain(..) {
            h.thread().unpark();
            let _ = h.join();
        }
    }
}

/// The system would not start a thread (`ulimit -u`, `ulimit -v`). Its
/// text is the start-up message; running, the engine keeps the threads it
/// has and says so in a notice.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Refused {
    /// What could not start, e.g. `64 pool threads`.
    pub what: String,
    /// The system's reason, once (rayon's error repeats its cause).
    pub cause: String,
}

impl Refused {
    fn new(what: String, cause: String) -> Refused {
        Refused { what, cause }
    }
}

impl Refused {
    /// The cause for a notice of two short rows: `os error 11` out of
    /// `Resource temporarily unavailable (os error 11)`.
    #[must_use]
    pub fn short_cause(&self) -> &str {
        match self.cause.rfind("(os error") {
            Some(i) => self.cause[i + 1..].trim_end_matches(')'),
            None => &self.cause,
        }
    }
}

/// What the engine falls back to when threads are refused while running.
pub const KEPT_WORKER: &str = "running on worker";

/// The fallback to the pool that exists.
#[must_use]
pub fn kept_pool(threads: usize) -> String {
    format!("kept the {threads} it has")
}

impl Refused {
    /// The screen's notice: what was refused and what runs instead.
    #[must_use]
    pub fn notice(&self, kept: &str) -> String {
        format!(
            "the system refused {} ({}): {kept}",
            self.what,
            self.short_cause()
        )
    }
}

impl std::fmt::Display for Refused {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "cannot start {}: the system refused a thread ({}); try fewer --threads or raise ulimit -u / ulimit -v",
            self.what, self.cause
        )
    }
}

impl std::error::Error for Refused {}

fn thread_ids(pool: &rayon::ThreadPool) -> Vec<(String, i32)> {
    pool.broadcast(|_| {
        let name = std::thread::current().name().unwrap_or("").to_string();
        crate::cpu::current_tid().map(|tid| (name, tid))
    })
    .into_iter()
    .flatten()
    .collect()
}

const BOUNDS: [Bound; 4] = [Bound::Threads, Bound::Cores, Bound::Blocks, Bound::Work];

impl Exec for PoolExec {
    fn lanes(&self) -> usize {
        self.threads
    }

    fn cores(&self) -> usize {
        self.cores
    }

    fn for_each_lane(&self, f: &(dyn Fn(usize) + Sync)) {
        self.for_lanes(self.threads, f);
    }

    fn for_lanes(&self, lanes: usize, f: &(dyn Fn(usize) + Sync)) {
        if lanes <= 1 {
            f(0);
            return;
        }
        let t0 = Instant::now();
        let width = self.lane_threads();
        if lanes >= width {
            // Lane `i` (and `i + L`, … past `L` lanes) on `pool-i`: the
            // other `L - 1` threads wake, and no others; a panic in any
            // comes back here.
            self.pool.broadcast(|ctx| {
                (ctx.index()..lanes).step_by(width).for_each(f);
            });
        } else {
            // Fewer lanes than threads (more than 2 cores): lane 0 on the
            // caller, the others as jobs the idle threads steal.
            self.pool.in_place_scope(|s| {
                for lane in 1..lanes {
                    s.spawn(move |_| f(lane));
                }
                f(0);
            });
        }
        let ns = u64::try_from(t0.elapsed().as_nanos()).unwrap_or(u64::MAX);
        self.parallel_ns.fetch_add(ns, Ordering::Relaxed);
    }

    fn note_lanes(&self, lanes: usize, bound: Bound) {
        if self.busy.fetch_max(lanes, Ordering::Relaxed) < lanes {
            let i = BOUNDS.iter().position(|&b| b == bound).unwrap_or(0);
            self.bound.store(i, Ordering::Relaxed);
        }
    }

    fn take_busy(&self) -> Option<Busy> {
        let busy = self.busy.swap(0, Ordering::Relaxed);
        let bound = BOUNDS[self.bound.swap(0, Ordering::Relaxed).min(3)];
        (busy > 0).then_some(Busy {
            busy,
            threads: self.threads,
            bound,
        })
    }

    fn join(&self, a: &(dyn Fn() + Sync), b: &(dyn Fn() + Sync)) {
        self.pool.join(a, b);
    }

    /// The frame runs on a pool thread: a broadcast from inside the pool
    /// runs one lane on the caller, which is awake, and the other lanes are
    /// still spinning when sections follow closely (an empty section costs
    /// about 1 µs then, against 12 µs from outside; `examples/handoff`).
    /// After a long serial stretch they sleep, and waking them costs about
    /// what it did from outside, less the caller's own wake-up.
    fn host(&self, job: &mut (dyn FnMut() + Send)) {
        self.pool.install(job);
    }
}

/// Names of the `split` threads, by the work they take.
pub const SPLIT_ROLES: [ThreadRole; 2] = [ThreadRole::SplitPair, ThreadRole::SplitWall];

/// Pool thread `i`'s name, from its role.
pub fn pool_name(i: usize) -> String {
    ThreadRole::Pool(u32::try_from(i).unwrap_or(u32::MAX))
        .name()
        .into_owned()
}

/// Functional decomposition: `join`'s first job (sphere–sphere work) on
/// `split-pair`, its second (sphere–wall work) on `split-wall`. Data-parallel
/// work is not cut up: it runs on the calling thread.
pub struct SplitExec {
    pool: rayon::ThreadPool,
}

impl SplitExec {
    /// # Errors
    /// When the system refuses a thread.
    pub fn new() -> Result<SplitExec, Refused> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .thread_name(|i| SPLIT_ROLES[i].name().into_owned())
            .build()
            .map_err(|e| Refused::new("the two split threads".into(), e.to_string()))?;
        Ok(SplitExec { pool })
    }

    /// `(name, kernel thread id)` of both threads (Linux).
    pub fn thread_ids(&self) -> Vec<(String, i32)> {
        thread_ids(&self.pool)
    }
}

impl Exec for SplitExec {
    fn lanes(&self) -> usize {
        1
    }

    fn for_each_lane(&self, f: &(dyn Fn(usize) + Sync)) {
        f(0);
    }

    fn join(&self, a: &(dyn Fn() + Sync), b: &(dyn Fn() + Sync)) {
        // Broadcast runs once on each thread, so the jobs land on the thread
        // named for them (work stealing could swap them).
        self.pool
            .broadcast(|ctx| if ctx.index() == 0 { a() } else { b() });
    }

    fn functional(&self) -> bool {
        true
    }
}
