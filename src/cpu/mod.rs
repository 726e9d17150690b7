//! Per-thread CPU load of this process. (Placeholder API: the threading
//! issue fills it in.)

/// One thread's load.
#[derive(Clone, Debug, PartialEq)]
pub struct ThreadLoad {
    pub tid: i32,
    pub name: String,
    /// Percent of one core over the sliding window (100 = one core busy).
    pub percent: f64,
    /// Total CPU seconds since the thread started.
    pub cpu_seconds: f64,
    /// Recent `percent` samples, oldest first, for sparklines.
    pub history: Vec<f64>,
}

/// All threads, the process total and the core count.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CpuReport {
    pub threads: Vec<ThreadLoad>,
    pub total_percent: f64,
    pub cores: usize,
}

/// Samples `/proc/self/task/*` (Linux) on demand.
#[derive(Default)]
pub struct Sampler {
    report: CpuReport,
}

impl Sampler {
    pub fn new() -> Sampler {
        Sampler::default()
    }
    /// Take a sample now and return the updated report.
    pub fn sample(&mut self) -> &CpuReport {
        &self.report
    }
    pub fn report(&self) -> &CpuReport {
        &self.report
    }
}

/// Every thread of the process with its CPU seconds, for the bench JSON.
pub fn thread_cpu_seconds() -> Vec<(String, f64)> {
    Vec::new()
}
