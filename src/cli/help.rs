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
        "first_frame",
        "{physics_cpu_seconds, sphere_collisions} of the first frame, which also loads the model: leave it out for a steady rate",
    ),
    (
        "parallel_seconds",
        "pool only: the part of wall_seconds in sections on more than one lane (null otherwise)",
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

/// `tradeoff --help`'s long description, its models named from the list it
/// runs ([`ModelKind::ALL`](crate::physics::ModelKind::ALL)), so a model
/// added there is named here.
pub(super) fn tradeoff_long_about() -> String {
    let names: Vec<&str> = crate::physics::ModelKind::ALL
        .iter()
        .map(|m| m.name())
        .collect();
    let list = match names.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} and {last}", rest.join(", ")),
        _ => names.join(""),
    };
    format!(
        "Measure speed against accuracy for every model over a ladder of dt.\n\n\
         Runs {list} (auto at tolerance 0, naming the model it chose) on one thread for \
         dt = 1/15 s down to 1/1920 s (halving), each for 2 simulated seconds, and measures \
         each run against a reference run of the same scene: cost (wall seconds per \
         simulated second), worst energy error, deepest overlap, escapes, collisions \
         missed, and the position error at a short horizon. Prints a markdown table; the \
         table names its reference."
    )
}

pub(super) fn tradeoff_after_help() -> String {
    format!(
        "With --out DIR it also writes DIR/tradeoff.csv (columns: {}) and DIR/tradeoff.svg \
         (position error against cost, one line per model).",
        CSV_COLUMNS.join(", ")
    )
}

pub(super) fn scaling_after_help() -> String {
    format!(
        "Without --scene: {} spheres of the gas at packing {} (--count N keeps the packing \
         unless --radius is given). With --out DIR it also writes DIR/scaling.csv (columns: {}) \
         and DIR/scaling.svg (speed-up against threads, with the fit's prediction).\n\n\
         Example: ballpit scaling --out /tmp/scaling",
        super::SCALING_COUNT,
        super::SCALING_PACKING,
        crate::scaling::CSV_COLUMNS.join(", ")
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

/// The man page: clap's sections for `ballpit` and, in place of the list
/// of `ballpit-bench(1)`-style pages that are not generated, a section per
/// subcommand with its options, then the keys from the app's own table.
pub fn man_page(cmd: &clap::Command) -> std::io::Result<Vec<u8>> {
    let mut cmd = cmd.clone().disable_help_subcommand(true);
    cmd.build();
    let man = clap_mangen::Man::new(cmd.clone());
    let mut page = Vec::new();
    man.render_title(&mut page)?;
    man.render_name_section(&mut page)?;
    man.render_synopsis_section(&mut page)?;
    man.render_description_section(&mut page)?;
    man.render_options_section(&mut page)?;
    for sub in cmd.get_subcommands() {
        let name = format!("ballpit {}", sub.get_name());
        let _ = writeln!(
            page_text(&mut page),
            ".SH \"{}\"\n{}",
            roff_escape(&name.to_uppercase()),
            roff_escape(
                &sub.get_long_about()
                    .or(sub.get_about())
                    .map(ToString::to_string)
                    .unwrap_or_default()
            )
        );
        let mut opts = Vec::new();
        clap_mangen::Man::new(sub.clone()).render_options_section(&mut opts)?;
        // One OPTIONS section per page: the subcommand's are a subsection.
        let opts = String::from_utf8_lossy(&opts).replacen(
            ".SH OPTIONS",
            &format!(".SS \"{name} options\""),
            1,
        );
        page.extend_from_slice(opts.as_bytes());
    }
    page.extend_from_slice(keys_section().as_bytes());
    man.render_extra_section(&mut page)?;
    page.extend_from_slice(
        b".SH \"EXIT STATUS\"\n0 on success; 2 for bad input (a flag, a scene file), with one message on stderr; 1 for other errors.\n",
    );
    man.render_version_section(&mut page)?;
    Ok(page)
}

/// `page` as a `fmt::Write` sink for `writeln!`.
fn page_text(page: &mut Vec<u8>) -> impl std::fmt::Write + '_ {
    struct Sink<'a>(&'a mut Vec<u8>);
    impl std::fmt::Write for Sink<'_> {
        fn write_str(&mut self, s: &str) -> std::fmt::Result {
            self.0.extend_from_slice(s.as_bytes());
            Ok(())
        }
    }
    Sink(page)
}

/// The KEYS section: every binding of the app's key table.
pub fn keys_section() -> String {
    let mut s = String::from(".SH KEYS\nIn the terminal app (press ? there for the same list):\n");
    for b in crate::tui::keys::TABLE {
        let _ = write!(
            s,
            ".TP\n\\fB{}\\fR\n{}\n",
            roff_escape(&b.keys()),
            roff_escape(b.help)
        );
    }
    s
}

/// Text safe in roff: backslashes and hyphens escaped, no line starting a
/// request.
fn roff_escape(text: &str) -> String {
    text.lines()
        .map(|l| {
            let l = l.replace('\\', "\\e").replace('-', "\\-");
            if l.starts_with('.') || l.starts_with('\'') {
                format!("\\&{l}")
            } else {
                l
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
}
