//! Per-thread CPU load of this process, read from procfs on Linux
//! (`/proc/self/task/*/schedstat`, nanosecond run time, falling back to the
//! clock ticks of `stat`), by thread name from `comm`, and what other
//! processes take (`machine`). Elsewhere the report holds only the core count.
pub(crate) mod history;
mod machine;
mod role;
mod task;

pub use role::ThreadRole;

pub use task::{current_tid, thread_cpu_ns, thread_cpu_seconds_of};

use history::History;
use machine::Others;
use std::collections::{HashMap, VecDeque};
use std::time::{Duration, Instant};

/// One thread's load.
#[derive(Clone, Debug, PartialEq)]
pub struct ThreadLoad {
    pub tid: i32,
    pub name: String,
    /// What the thread is for, read from its name once.
    pub role: ThreadRole,
    /// Percent of one core over the sliding window (100 = one core busy).
    pub percent: f64,
    /// Total CPU seconds since the thread started.
    pub cpu_seconds: f64,
    /// `percent` once a second over the last minute (`history::LEN` at
    /// most), oldest first, for the sparklines and the chart.
    pub history: Vec<f64>,
}

/// All threads, the process total and the core count.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CpuReport {
    pub threads: Vec<ThreadLoad>,
    pub total_percent: f64,
    /// The CPUs this process may run on: the base of the total and others.
    pub cores: usize,
    /// What other processes took on this process's CPUs, percent of one
    /// core (None until two readings, or off Linux).
    pub others_percent: Option<f64>,
}

impl CpuReport {
    /// The report of `threads`, their total the process's.
    pub fn new(threads: Vec<ThreadLoad>, cores: usize, others_percent: Option<f64>) -> Self {
        CpuReport {
            total_percent: threads.iter().map(|t| t.percent).sum(),
            threads,
            cores,
            others_percent,
        }
    }
}

/// How long the load is averaged over.
pub const WINDOW: Duration = Duration::from_secs(1);

struct Track {
    name: String,
    role: ThreadRole,
    /// (when, CPU seconds) samples covering at least the window.
    samples: VecDeque<(Instant, f64)>,
    history: History,
    seen: bool,
}

/// Samples `/proc/self/task/*` (Linux) on demand; call `sample` as often as
/// the screen refreshes, the window and history are kept in wall time.
pub struct Sampler {
    report: CpuReport,
    tracks: HashMap<i32, Track>,
    /// Shared by every thread's history, so their seconds line up.
    origin: Instant,
    others: Others,
    cores: usize,
}

impl Default for Sampler {
    fn default() -> Self {
        Sampler::new()
    }
}

impl Sampler {
    pub fn new() -> Sampler {
        // The total and the others share one base: the CPUs we may run on.
        let allowed = machine::allowed_cpus();
        let cores = allowed.as_ref().map_or_else(
            || std::thread::available_parallelism().map_or(1, std::num::NonZero::get),
            Vec::len,
        );
        Sampler {
            report: CpuReport {
                cores,
                ..CpuReport::default()
            },
            tracks: HashMap::new(),
            origin: Instant::now(),
            others: Others::on(allowed),
            cores,
        }
    }

    /// Take a sample now and return the updated report.
    pub fn sample(&mut self) -> &CpuReport {
        let now = Instant::now();
        for t in self.tracks.values_mut() {
            t.seen = false;
        }
        let origin = self.origin;
        for (tid, name, secs) in task::read_threads() {
            let t = self.tracks.entry(tid).or_insert_with(|| Track {
                name: String::new(),
                role: ThreadRole::Other,
                samples: VecDeque::new(),
                history: History::new(origin),
                seen: false,
            });
            if t.name != name {
                // A thread may rename itself (rayon names its threads after
                // they start): the role follows the name.
                t.role = ThreadRole::of(&name);
                t.name = name;
            }
            t.seen = true;
            t.samples.push_back((now, secs));
            // Keep one sample at least a window old, so the rate spans it.
            while t.samples.len() > 2 && now.duration_since(t.samples[1].0) >= WINDOW {
                t.samples.pop_front();
            }
        }
        self.tracks.retain(|_, t| t.seen);
        let mut threads: Vec<ThreadLoad> = self
            .tracks
            .iter_mut()
            .filter_map(|(&tid, t)| {
                // Every track kept was sampled just now.
                let (&(t1, c1), &(t0, c0)) = (t.samples.back()?, t.samples.front()?);
                let wall = t1.duration_since(t0).as_secs_f64();
                let percent = if wall > 0.0 {
                    ((c1 - c0) / wall * 100.0).max(0.0)
                } else {
                    0.0
                };
                t.history.push(now, percent);
                Some(ThreadLoad {
                    tid,
                    name: t.name.clone(),
                    role: t.role,
                    percent,
                    cpu_seconds: c1,
                    history: t.history.values(),
                })
            })
            .collect();
        threads.sort_by(|a, b| order_key(a).cmp(&order_key(b)));
        self.report = CpuReport::new(threads, self.cores, self.others.sample());
        &self.report
    }

    pub fn report(&self) -> &CpuReport {
        &self.report
    }
}

/// The order every reader shows threads in, stable from frame to frame:
/// by role (`main`, `physics`, the pool by number, the split's threads),
/// then the rest by name (and id, for twins).
pub fn order_key(t: &ThreadLoad) -> (ThreadRole, &str, i32) {
    let name = if t.role == ThreadRole::Other {
        t.name.as_str()
    } else {
        ""
    };
    (t.role, name, t.tid)
}

/// Every thread of the process with its CPU seconds, for the bench JSON.
pub fn thread_cpu_seconds() -> Vec<(String, f64)> {
    task::read_threads()
        .into_iter()
        .map(|(_, name, secs)| (name, secs))
        .collect()
}
