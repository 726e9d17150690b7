//! Help text built from the code's own tables: the bench JSON fields and the
//! presets.
use crate::engine::MAX_THREADS;
use crate::scene::presets::PRESETS;
use crate::tradeoff::CSV_COLUMNS;
use std::fmt::Write as _;

/// The fields of `bench`'s JSON line, in the order it prints them, with what
/// each holds; `bench --help` shows them and a test holds them to the output.
pub const BENCH_FIELDS: &[(&str, &str)] = &[
    ("n", "spheres"),
    ("steps", "steps run"),
    ("dt", "step length, s"),
    ("model", "collision model"),
    (
        "model_chosen",
        "what --model auto ran at the end (null for the others)",
    ),
    (
        "model_reason",
        "why auto chose it, or that the tolerance could not be met",
    ),
    ("threading", "threading mode"),
    ("threads", "pool threads (--threads)"),
    (
        "physics_threads",
        "the threads the physics ran on, driver first",
    ),
    (
        "wall_seconds",
        "wall time of the physics: the steps and the detection behind the overlap readout",
    ),
    (
        "physics_cpu_seconds",
        "CPU time of the physics_threads while stepping",
    ),
    (
        "load_average",
        "[start, end] 1-minute load average of the host (/proc/loadavg)",
    ),
    ("steps_per_second", "steps / wall_seconds"),
    ("sphere_steps_per_second", "n x steps / wall_seconds"),
    ("energy_start", "kinetic energy at the start"),
    ("energy_end", "kinetic energy at the end"),
    (
        "energy_drift_rel",
        "|energy_end - energy_start| / energy_start",
    ),
    (
        "max_energy_err_rel",
        "worst relative energy error over the frames",
    ),
    (
        "escaped",
        "centres outside [r, L-r] by more than 1e-9 L, at the end",
    ),
    (
        "max_overlap_rel",
        "deepest pair overlap / smaller radius, at the end",
    ),
    ("sphere_collisions", "sphere-sphere collisions"),
    ("wall_collisions", "sphere-wall collisions"),
    (
        "wall_pressure",
        "momentum given to the walls / (simulated time x wall area)",
    ),
    (
        "collisions_per_sim_second",
        "sphere_collisions per simulated second",
    ),
    ("temperature", "mean kinetic energy per sphere, 2/3 x E/n"),
    (
        "capped_steps",
        "steps that hit the model's event cap or work budget and were finished coarsely",
    ),
    (
        "budget_steps",
        "of capped_steps, those that ran out of a work budget per step (swept's, or discrete's pairs)",
    ),
    (
        "thread_cpu",
        "[{name, cpu_seconds}] for every thread of the process",
    ),
    ("peak_rss_bytes", "peak resident memory of the process"),
    (
        "warnings",
        "the promises the run could not keep, and why (empty when none)",
    ),
];

pub(super) fn bench_after_help() -> String {
    let mut s = String::from("Prints one JSON line with these fields:\n");
    let w = BENCH_FIELDS.iter().map(|f| f.0.len()).max().unwrap_or(0);
    for (name, what) in BENCH_FIELDS {
        let _ = writeln!(s, "  {name:<w$}  {what}");
    }
    s.push_str("\nExample: ballpit bench --scene dense --model exact --threading pool --steps 600");
    s
}

pub(super) fn tradeoff_after_help() -> String {
    format!(
        "With --out DIR it also writes DIR/tradeoff.csv (columns: {}) and DIR/tradeoff.svg \
         (position error against cost, one line per model).",
        CSV_COLUMNS.join(", ")
    )
}

pub(super) fn scene_long_help() -> String {
    let mut s = String::from(
        "A preset, a .toml scene or a .csv of spheres (header x,y,z,vx,vy,vz,radius,mass) \
         [default: gas]. --count, --radius, --speed, --seed and --box override a preset.\n\
         Presets:",
    );
    let w = PRESETS.iter().map(|p| p.name.len()).max().unwrap_or(0);
    for p in &PRESETS {
        let _ = write!(s, "\n  {:<w$}  {}", p.name, p.about);
    }
    s
}

pub(super) fn threads_help() -> String {
    format!("Pool threads (1 to {MAX_THREADS}) [default: available cores]")
}
