//! `ballpit scaling`: what threading buys on this machine, for one scene.
//! Runs `off`, `worker`, `split`, and `pool` at 1, 2, 4, … threads up to the
//! cores and once oversubscribed (twice that), every configuration once a
//! round, the rounds in alternation so that a change in the host's load
//! falls on all of them alike. Every run steps the same scene the same
//! number of steps (fixed from a probe of `off`), so every run ends in the
//! same bits, which the sweep checks.
//!
//! Per configuration: steps/s (median of the rounds), speed-up over `off`,
//! efficiency (speed-up per processor it can use), physics CPU seconds, and
//! CPU seconds over `off`'s (what the threading itself costs), and for the
//! pool the serial fraction two ways: measured, from the pool's own account
//! of the time a step spends outside its parallel sections (over that run's
//! own physics time, so in [0, 1] whatever the overhead), and the
//! Karp–Flatt fraction of its speed-up (none where there is no speed-up).
//! One Amdahl fit of the pool's speed-ups then predicts 16, 64 and 128
//! cores. A scene whose sections never get a second lane is said so.
mod fit;
mod report;

pub use report::{CSV_COLUMNS, csv, markdown, svg};

use crate::bench;
use crate::engine::{MAX_THREADS, Settings, Threading};
use crate::physics::{ModelKind, World};
use std::path::Path;

/// One configuration of the sweep.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Config {
    pub threading: Threading,
    /// Pool size in `pool`; the threads doing physics work otherwise.
    pub threads: usize,
}

impl Config {
    /// Processors the configuration can use at once on `cores` cores: what
    /// its speed-up is judged against.
    #[must_use]
    pub fn processors(self, cores: usize) -> usize {
        self.threads.min(cores).max(1)
    }

    #[must_use]
    pub fn label(self) -> String {
        match self.threading {
            Threading::Pool => format!("pool {}", self.threads),
            t => t.name().to_string(),
        }
    }
}

/// The configurations for a largest pool of `top` threads: `off`, `worker`,
/// `split`, then pools of 1, 2, 4, … up to `top`, and `2 × top` (at most
/// [`MAX_THREADS`]).
#[must_use]
pub fn configs(top: usize) -> Vec<Config> {
    let top = top.clamp(1, MAX_THREADS);
    let mut pools: Vec<usize> = std::iter::successors(Some(1usize), |k| Some(k * 2))
        .take_while(|&k| k < top)
        .collect();
    pools.push(top);
    let over = (2 * top).min(MAX_THREADS);
    if over > top {
        pools.push(over);
    }
    let fixed = [
        (Threading::Off, 1),
        (Threading::Worker, 1),
        (Threading::Split, 2),
    ];
    fixed
        .into_iter()
        .chain(pools.into_iter().map(|k| (Threading::Pool, k)))
        .map(|(threading, threads)| Config { threading, threads })
        .collect()
}

/// What the sweep runs: the scene's model and step, the largest pool,
/// rounds, and how long an `off` run should take.
#[derive(Clone, Copy, Debug)]
pub struct Plan {
    pub model: ModelKind,
    pub dt: f64,
    pub top: usize,
    pub rounds: usize,
    pub seconds: f64,
    pub cores: usize,
}

/// One configuration's figures over the rounds.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    pub config: Config,
    pub processors: usize,
    pub steps_per_second: f64,
    /// Slowest and fastest round, so a reader sees the spread.
    pub steps_per_second_range: (f64, f64),
    pub speedup: f64,
    pub efficiency: f64,
    pub physics_cpu_seconds: f64,
    /// `physics_cpu_seconds` less `off`'s: the CPU the threading itself
    /// costs (hand-offs, waking, spinning; negative only by noise).
    pub cpu_over_off: f64,
    /// Pool on more than one processor: the serial part of its time over
    /// its own physics time, in [0, 1] (`None` elsewhere).
    pub serial_measured: Option<f64>,
    /// Pool on more than one processor with a speed-up from 1 to linear:
    /// the Karp–Flatt fraction, in [0, 1]. `None` below a speed-up of 1
    /// ("no speed-up") or above linear, where no serial fraction gives it.
    pub karp_flatt: Option<f64>,
    /// The run ended in the same bits as `off` (every round).
    pub same_bits: bool,
}

/// The sweep's result.
#[derive(Clone, Debug)]
pub struct Sweep {
    pub plan: Plan,
    pub n: usize,
    pub packing: f64,
    pub steps: u64,
    pub load_average: Vec<f64>,
    pub rows: Vec<Row>,
    /// Amdahl's serial fraction fitted to the pool's speed-ups.
    pub fitted: Option<f64>,
    /// The pool rows' measured serial fractions, their median.
    pub measured: Option<f64>,
    /// Why no configuration can beat `off` here, when a probe of a pool
    /// found no section with a second lane.
    pub nothing_to_share: Option<String>,
}

impl Sweep {
    /// Predicted speed-ups at `fit::PREDICT_AT` cores from the fit.
    #[must_use]
    pub fn predictions(&self) -> Vec<(usize, f64)> {
        self.fitted.map_or_else(Vec::new, |f| {
            fit::PREDICT_AT
                .iter()
                .map(|&p| (p, fit::amdahl(f, p as f64)))
                .collect()
        })
    }
}

/// One run's figures.
struct Run {
    steps_per_second: f64,
    wall: f64,
    cpu: f64,
    parallel: Option<f64>,
    same_bits: bool,
}

/// Runs the sweep, calling `progress(done, next)` before each run.
///
/// # Errors
/// When the engine cannot start its threads (bad input, exit 2).
pub fn measure(
    world: &World,
    plan: &Plan,
    progress: &mut dyn FnMut(usize, &str),
) -> anyhow::Result<Sweep> {
    let load_start = bench::load_average();
    progress(0, "probe");
    let steps = probe_steps(world, plan)?;
    let nothing_to_share = probe_sharing(world, plan)?;
    let configs = configs(plan.top);
    // Round 0 runs `off` first: its end is what every run must end in.
    let mut reference: Option<World> = None;
    let mut runs: Vec<Vec<Run>> = configs.iter().map(|_| Vec::new()).collect();
    let mut done = 0;
    for round in 0..plan.rounds {
        // Each round starts one configuration later, so none always runs first.
        for i in (0..configs.len()).map(|i| (i + round) % configs.len()) {
            let c = configs[i];
            progress(
                done,
                &format!("{}, round {} of {}", c.label(), round + 1, plan.rounds),
            );
            let (report, end) = bench::run(world.clone(), &settings(plan, c, steps), steps)?;
            let reference = reference.get_or_insert_with(|| end.clone());
            runs[i].push(Run {
                steps_per_second: report.steps_per_second,
                wall: report.wall_seconds,
                cpu: report.physics_cpu_seconds,
                parallel: report.parallel_seconds,
                same_bits: end.spheres == reference.spheres,
            });
            done += 1;
        }
    }
    let rows = rows(&configs, &runs, plan.cores);
    // Amdahl's law is about processors: an oversubscribed pool adds queueing,
    // not serial work, so it is shown but not fitted.
    let fitted: Vec<&Row> = rows
        .iter()
        .filter(|r| r.config.threading == Threading::Pool && r.config.threads <= plan.cores)
        .collect();
    let points: Vec<(f64, f64)> = fitted
        .iter()
        .map(|r| (r.processors as f64, r.speedup))
        .collect();
    let measured = median(fitted.iter().filter_map(|r| r.serial_measured).collect());
    Ok(Sweep {
        plan: *plan,
        n: world.spheres.len(),
        packing: crate::physics::relax::packing(&world.spheres, world.size),
        steps,
        load_average: load_start
            .into_iter()
            .chain(bench::load_average())
            .collect(),
        rows,
        fitted: fit::fit(&points),
        measured,
        nothing_to_share,
    })
}

/// The rows of `runs` (by configuration, one per round), against `off`'s.
fn rows(configs: &[Config], runs: &[Vec<Run>], cores: usize) -> Vec<Row> {
    let off = |f: &dyn Fn(&Run) -> f64| median(runs[0].iter().map(f).collect()).unwrap_or(0.0);
    let (off_rate, off_cpu) = (off(&|r| r.steps_per_second), off(&|r| r.cpu));
    configs
        .iter()
        .zip(runs)
        .map(|(&config, runs)| {
            let of = |f: &dyn Fn(&Run) -> f64| median(runs.iter().map(f).collect()).unwrap_or(0.0);
            let rate = of(&|r| r.steps_per_second);
            let processors = config.processors(cores);
            let speedup = if off_rate > 0.0 { rate / off_rate } else { 0.0 };
            let serial = median(
                runs.iter()
                    .filter_map(|r| serial_fraction(r.wall, r.parallel?))
                    .collect(),
            );
            let lo = runs
                .iter()
                .map(|r| r.steps_per_second)
                .fold(f64::INFINITY, f64::min);
            let hi = runs.iter().map(|r| r.steps_per_second).fold(0.0, f64::max);
            let cpu = of(&|r| r.cpu);
            Row {
                config,
                processors,
                steps_per_second: rate,
                steps_per_second_range: (lo, hi),
                speedup,
                efficiency: speedup / processors as f64,
                physics_cpu_seconds: cpu,
                cpu_over_off: cpu - off_cpu,
                serial_measured: serial.filter(|_| processors > 1),
                karp_flatt: (config.threading == Threading::Pool)
                    .then(|| fit::karp_flatt(speedup, processors as f64))
                    .flatten()
                    .filter(|f| (0.0..=1.0).contains(f)),
                same_bits: runs.iter().all(|r| r.same_bits),
            }
        })
        .collect()
}

/// The serial share of one pool run: its time outside sections of more
/// than one lane over its own physics time. Over `off`'s time instead it
/// would count the pool's overhead as serial work and exceed 1 on a pool
/// slower than `off`; over its own it is in [0, 1] by construction.
fn serial_fraction(wall: f64, parallel: f64) -> Option<f64> {
    (wall > 0.0).then(|| ((wall - parallel) / wall).clamp(0.0, 1.0))
}

/// A few steps of a pool of at least 2 threads: if no section ran on more
/// than one lane, nothing in this scene can spread and the sweep says why.
fn probe_sharing(world: &World, plan: &Plan) -> anyhow::Result<Option<String>> {
    let pool = Config {
        threading: Threading::Pool,
        threads: plan.top.max(2),
    };
    let probe = 4;
    let (report, _) = bench::run(world.clone(), &settings(plan, pool, probe), probe)?;
    if report.parallel_seconds.is_some_and(|p| p > 0.0) {
        return Ok(None);
    }
    let n = world.spheres.len();
    let why = if plan.cores < 2 {
        "this machine has one core".to_string()
    } else {
        format!(
            "no section of a {} step on {n} sphere{} got a second lane (too few spheres for the lane rule, or a model that runs on one thread)",
            plan.model,
            if n == 1 { "" } else { "s" }
        )
    };
    Ok(Some(format!(
        "Nothing to share: {why}, so no mode below can beat off; they show only what their hand-offs cost."
    )))
}

/// Steps that make an `off` run take about `plan.seconds`, from a short
/// run of `off` (which also warms the caches and the allocator).
fn probe_steps(world: &World, plan: &Plan) -> anyhow::Result<u64> {
    let probe = 4;
    let off = Config {
        threading: Threading::Off,
        threads: 1,
    };
    let (report, _) = bench::run(world.clone(), &settings(plan, off, probe), probe)?;
    let per_step = report.wall_seconds / probe as f64;
    let steps = if per_step > 0.0 {
        (plan.seconds / per_step).ceil()
    } else {
        1e6
    };
    // Float to int: clamped first, so it cannot wrap.
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    Ok(steps.clamp(2.0, 1e6) as u64)
}

fn settings(plan: &Plan, c: Config, steps: u64) -> Settings {
    Settings {
        model: plan.model,
        dt: plan.dt,
        // As `bench` does: frames of a hundredth of the run.
        tick: u32::try_from(steps.div_ceil(100))
            .unwrap_or(u32::MAX)
            .max(1),
        threading: c.threading,
        threads: c.threads,
    }
}

fn median(mut v: Vec<f64>) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let m = v.len() / 2;
    Some(if v.len() % 2 == 1 {
        v[m]
    } else {
        f64::midpoint(v[m - 1], v[m])
    })
}

/// Measure, and with `out` write `scaling.csv` and `scaling.svg` there;
/// returns the table for the caller to print.
///
/// # Errors
/// A directory that cannot be made or written, or threads the system
/// refuses: bad input.
pub fn run(world: &World, plan: &Plan, out: Option<&Path>) -> anyhow::Result<String> {
    if world.spheres.is_empty() {
        // An empty scene's steps are all hand-off: its "speed-ups" would be
        // of nothing (9 M steps/s for `off`), so it is refused, not timed.
        return Err(crate::error::BadInput(format!(
            "scaling needs spheres to time: --count must be 1 to {} (the scene has 0)",
            crate::scene::MAX_COUNT
        ))
        .into());
    }
    if let Some(dir) = out {
        // Before the minute of measuring, not after: a bad path is bad input.
        std::fs::create_dir_all(dir).map_err(|e| {
            crate::error::BadInput(format!("cannot create directory {}: {e}", dir.display()))
        })?;
    }
    let runs = 1 + configs(plan.top).len() * plan.rounds;
    let bar = crate::progress::Progress::new(runs);
    let sweep = measure(world, plan, &mut |done, next| bar.set(done, next));
    bar.finish();
    let sweep = sweep?;
    if let Some(dir) = out {
        report::write(&sweep, dir)?;
    }
    Ok(markdown(&sweep))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sweep_doubles_to_the_cores_then_oversubscribes() {
        let pools = |top| {
            configs(top)
                .iter()
                .filter(|c| c.threading == Threading::Pool)
                .map(|c| c.threads)
                .collect::<Vec<_>>()
        };
        assert_eq!(pools(2), [1, 2, 4]);
        assert_eq!(pools(1), [1, 2]);
        assert_eq!(pools(48), [1, 2, 4, 8, 16, 32, 48, 96]);
        assert_eq!(pools(200), [1, 2, 4, 8, 16, 32, 64, 128, 200, 256]);
        assert_eq!(pools(256), [1, 2, 4, 8, 16, 32, 64, 128, 256]);
        assert_eq!(configs(2)[0].threading, Threading::Off);
        assert_eq!(configs(2)[2].processors(1), 1);
        assert_eq!(configs(2).last().map(|c| c.processors(2)), Some(2));
    }

    fn run(wall: f64, cpu: f64, parallel: Option<f64>) -> Run {
        Run {
            steps_per_second: 100.0 / wall,
            wall,
            cpu,
            parallel,
            same_bits: true,
        }
    }

    #[test]
    fn a_pool_slower_than_off_has_a_serial_fraction_within_0_and_1() {
        let configs = configs(2);
        // off 1 s; a pool of 2 at 1.5 s, 0.2 s of it in parallel sections:
        // 1.3 s serial, which over off's 1 s would read as 1.3.
        let runs: Vec<Vec<Run>> = configs
            .iter()
            .map(|c| match (c.threading, c.threads) {
                (Threading::Pool, 2) => vec![run(1.5, 2.1, Some(0.2))],
                (Threading::Pool, t) => vec![run(1.0, 1.0, Some(if t > 1 { 0.9 } else { 0.0 }))],
                _ => vec![run(1.0, 1.0, None)],
            })
            .collect();
        let rows = rows(&configs, &runs, 2);
        let pool2 = rows
            .iter()
            .find(|r| r.config.threading == Threading::Pool && r.config.threads == 2)
            .unwrap();
        let f = pool2.serial_measured.unwrap();
        assert!((f - 1.3 / 1.5).abs() < 1e-12, "{f}");
        assert!((pool2.speedup - 1.0 / 1.5).abs() < 1e-12);
        assert_eq!(pool2.karp_flatt, None, "no speed-up, no fraction");
        assert!((pool2.cpu_over_off - 1.1).abs() < 1e-12);
        // A pool at off's own speed on 2 processors: Karp–Flatt exactly 1.
        let pool4 = rows.last().unwrap();
        assert_eq!(pool4.karp_flatt, Some(1.0));
        assert!((pool4.serial_measured.unwrap() - 0.1).abs() < 1e-12);
        // One processor: no measured fraction, whatever the clock says.
        assert_eq!(rows[3].serial_measured, None);
        for r in &rows {
            for f in [r.serial_measured, r.karp_flatt].into_iter().flatten() {
                assert!((0.0..=1.0).contains(&f), "{r:?}");
            }
        }
        assert_eq!(serial_fraction(0.0, 0.0), None);
        assert_eq!(serial_fraction(1.0, 1.2), Some(0.0), "clock skew clamps");
    }

    #[test]
    fn the_median_of_odd_and_even_counts() {
        assert_eq!(median(vec![3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(vec![4.0, 1.0]), Some(2.5));
        assert_eq!(median(Vec::new()), None);
    }
}
