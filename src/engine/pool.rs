//! The `pool` and `split` executors: rayon pools of named threads. Rayon's
//! idle threads spin for a few dozen yields and then sleep on a condition
//! variable, so a pool that is not in use costs no CPU.
use crate::physics::Exec;

/// Data decomposition: `K` threads `pool-0..K-1`, lane `i` on `pool-i`.
pub struct PoolExec {
    pool: rayon::ThreadPool,
    threads: usize,
}

impl PoolExec {
    pub fn new(threads: usize) -> anyhow::Result<PoolExec> {
        let threads = threads.max(1);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .thread_name(|i| format!("pool-{i}"))
            .build()?;
        Ok(PoolExec { pool, threads })
    }

    pub fn threads(&self) -> usize {
        self.threads
    }

    /// `(name, kernel thread id)` of every pool thread (Linux).
    pub fn thread_ids(&self) -> Vec<(String, i32)> {
        thread_ids(&self.pool)
    }
}

fn thread_ids(pool: &rayon::ThreadPool) -> Vec<(String, i32)> {
    pool.broadcast(|_| {
        let name = std::thread::current().name().unwrap_or("").to_string();
        crate::cpu::current_tid().map(|tid| (name, tid))
    })
    .into_iter()
    .flatten()
    .collect()
}

impl Exec for PoolExec {
    fn lanes(&self) -> usize {
        self.threads
    }

    fn for_each_lane(&self, f: &(dyn Fn(usize) + Sync)) {
        // One call per pool thread; a panic in any comes back here.
        self.pool.broadcast(|ctx| f(ctx.index()));
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
pub const SPLIT_NAMES: [&str; 2] = ["split-pair", "split-wall"];

/// Functional decomposition: `join`'s first job (sphere–sphere work) on
/// `split-pair`, its second (sphere–wall work) on `split-wall`. Data-parallel
/// work is not cut up: it runs on the calling thread.
pub struct SplitExec {
    pool: rayon::ThreadPool,
}

impl SplitExec {
    pub fn new() -> anyhow::Result<SplitExec> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .thread_name(|i| SPLIT_NAMES[i].to_string())
            .build()?;
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
