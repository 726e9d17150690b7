//! `ballpit tradeoff`: every model over a ladder of `dt`, measured against
//! an independent reference on the same scene: the brute-force event-driven
//! run of `physics::reference` (every pair tested at every event; none of
//! the models' code). All models run on one thread here, so the costs
//! compare algorithms, not thread counts.
//!
//! Measures, per model and `dt`, over [`RUN_SECONDS`] of simulated time:
//! cost (wall seconds per simulated second, sphere-steps per second), worst
//! relative energy error, deepest overlap (per smaller radius, worst over
//! the steps), spheres escaped (worst over the steps), and sphere–sphere
//! collisions missed relative to the reference over the same time. Then the
//! position error against the reference at a short horizon: a quarter of
//! the mean free time (from the reference run), rounded up to whole steps.
//! Before that time a typical sphere has not collided yet, so the
//! difference comes from how the model handles the few contacts that do
//! happen, not from chaos: each collision multiplies a small position
//! difference by about the mean free path over the diameter, so after a few
//! collisions per sphere any two runs differ by the box.
use crate::physics::{ModelKind, Serial, World, reference};
use anyhow::Context;
use plotters::prelude::*;
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

/// The `dt` ladder: 1/15 s down to 1/1920 s, halving.
pub const LADDER: [f64; 8] = [
    1.0 / 15.0,
    1.0 / 30.0,
    1.0 / 60.0,
    1.0 / 120.0,
    1.0 / 240.0,
    1.0 / 480.0,
    1.0 / 960.0,
    1.0 / 1920.0,
];
/// Simulated seconds each (model, dt) runs for the cost and error figures.
pub const RUN_SECONDS: f64 = 2.0;

#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    pub model: ModelKind,
    pub dt: f64,
    pub steps: u64,
    /// Wall seconds per simulated second.
    pub cost: f64,
    pub sphere_steps_per_second: f64,
    pub energy_err: f64,
    pub max_overlap_rel: f64,
    pub escaped: usize,
    pub collisions: u64,
    /// `1 - collisions / reference collisions` (negative: counted more).
    pub missed: f64,
    pub horizon: f64,
    /// RMS distance to the reference positions at `horizon`, in box lengths.
    pub pos_err: f64,
    pub capped_steps: u64,
    /// What `auto` ran at the end of the run (`None` for the other models).
    pub chosen: Option<ModelKind>,
}

/// The runs [`measure`] makes: the reference over [`RUN_SECONDS`] and to
/// each dt's horizon, then per model and dt a run and a run to the horizon.
pub const RUNS: usize = 1 + LADDER.len() + 2 * ModelKind::ALL.len() * LADDER.len();

/// Measure every model over the ladder on `world`.
pub fn measure(world: &World) -> Vec<Row> {
    measure_with(world, &mut |_, _| {})
}

/// [`measure`], calling `progress(done, next)` before each of its [`RUNS`]
/// runs with the number done so far and what runs next.
pub fn measure_with(world: &World, progress: &mut dyn FnMut(usize, &str)) -> Vec<Row> {
    let mut done = 0;
    let mut next = |what: &str| {
        progress(done, what);
        done += 1;
    };
    next("reference");
    let reference = {
        let mut w = world.clone();
        reference::run(&mut w, RUN_SECONDS);
        w.counters.sphere_collisions
    };
    let n = world.spheres.len();
    let free_time = if reference > 0 {
        n as f64 * RUN_SECONDS / (2.0 * reference as f64)
    } else {
        f64::INFINITY
    };
    let horizon = (free_time / 4.0).min(RUN_SECONDS / 8.0);
    // The reference at each dt's horizon (a whole number of its steps).
    let at_horizon: Vec<(u64, World)> = LADDER
        .iter()
        .map(|&dt| {
            next(&format!("reference to the horizon, dt {}", dt_label(dt)));
            let steps = (horizon / dt).ceil().max(1.0) as u64;
            let mut w = world.clone();
            reference::run(&mut w, steps as f64 * dt);
            (steps, w)
        })
        .collect();
    let mut rows = Vec::new();
    // `auto` at tolerance 0 beside the three it chooses among.
    for model in ModelKind::ALL {
        for (dt, (steps_h, truth)) in LADDER.into_iter().zip(&at_horizon) {
            next(&format!("{model}, dt {}", dt_label(dt)));
            let mut row = run_one(world, model, dt);
            row.missed = if reference > 0 {
                1.0 - row.collisions as f64 / reference as f64
            } else {
                0.0
            };
            next(&format!("{model} to the horizon, dt {}", dt_label(dt)));
            row.pos_err = position_error(world, model, dt, *steps_h, truth);
            row.horizon = *steps_h as f64 * dt;
            rows.push(row);
        }
    }
    rows
}

fn run_one(world: &World, kind: ModelKind, dt: f64) -> Row {
    let mut w = world.clone();
    let mut model = kind.build();
    let steps = (RUN_SECONDS / dt).round() as u64;
    let e0 = w.kinetic_energy();
    let (mut energy_err, mut overlap, mut escaped) = (0.0f64, w.max_overlap_rel(), w.escaped());
    let mut wall = 0.0;
    for _ in 0..steps {
        let t = Instant::now();
        model.advance(&mut w, dt, 1, &Serial);
        wall += t.elapsed().as_secs_f64();
        if e0 > 0.0 {
            energy_err = energy_err.max((w.kinetic_energy() - e0).abs() / e0);
        }
        overlap = overlap.max(w.max_overlap_rel());
        escaped = escaped.max(w.escaped());
    }
    Row {
        model: kind,
        dt,
        steps,
        cost: wall / (steps as f64 * dt),
        sphere_steps_per_second: if wall > 0.0 {
            (steps * w.spheres.len() as u64) as f64 / wall
        } else {
            0.0
        },
        energy_err,
        max_overlap_rel: overlap,
        escaped,
        collisions: w.counters.sphere_collisions,
        missed: 0.0,
        horizon: 0.0,
        pos_err: 0.0,
        capped_steps: w.counters.capped_steps,
        chosen: model.choice().map(|c| c.model),
    }
}

fn position_error(world: &World, kind: ModelKind, dt: f64, steps: u64, truth: &World) -> f64 {
    let mut a = world.clone();
    kind.build().advance(&mut a, dt, steps, &Serial);
    let b = truth;
    if a.spheres.is_empty() {
        return 0.0;
    }
    let sum: f64 = a
        .spheres
        .iter()
        .zip(&b.spheres)
        .map(|(x, y)| x.pos.distance_squared(y.pos))
        .sum();
    (sum / a.spheres.len() as f64).sqrt() / world.size
}

pub(crate) fn dt_label(dt: f64) -> String {
    format!("1/{}", (1.0 / dt).round())
}

/// What the errors are measured against, said above the table.
pub const REFERENCE_NOTE: &str = "Errors against the reference: a brute-force event-driven run \
(every pair tested at every event, src/physics/reference.rs), not any of the models.";

pub fn markdown(rows: &[Row]) -> String {
    let mut s = format!("{REFERENCE_NOTE}\n\n");
    s.push_str(
        "| model | dt | wall s / sim s | sphere-steps/s | energy err | deepest overlap (r) | escaped | collisions missed | pos err (L) at horizon |\n\
         |---|---|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for r in rows {
        let _ = writeln!(
            s,
            "| {} | {} | {:.2e} | {:.2e} | {:.1e} | {:.1e} | {} | {:+.1} % | {:.1e} at {:.3} s |",
            model_cell(r),
            dt_label(r.dt),
            r.cost,
            r.sphere_steps_per_second,
            r.energy_err,
            r.max_overlap_rel,
            r.escaped,
            100.0 * r.missed,
            r.pos_err,
            r.horizon,
        );
    }
    s
}

/// `auto → exact` for `auto`'s rows, the model's name for the others.
fn model_cell(r: &Row) -> String {
    match r.chosen {
        Some(c) => format!("{} → {c}", r.model),
        None => r.model.to_string(),
    }
}

/// The columns of `tradeoff.csv`, in order (`tradeoff --help` lists them).
pub const CSV_COLUMNS: [&str; 14] = [
    "model",
    "dt",
    "steps",
    "wall_s_per_sim_s",
    "sphere_steps_per_second",
    "energy_err_rel",
    "max_overlap_rel",
    "escaped",
    "sphere_collisions",
    "missed_rel",
    "horizon_s",
    "pos_err_rms",
    "capped_steps",
    "chosen",
];

/// The rows as CSV. Numbers are in `{:e}` form: one notation for columns
/// that span many orders of magnitude, each the shortest that reads back.
pub fn csv(rows: &[Row]) -> anyhow::Result<String> {
    let mut w = ::csv::Writer::from_writer(Vec::new());
    w.write_record(CSV_COLUMNS)?;
    let e = |x: f64| format!("{x:e}");
    for r in rows {
        // Sized by the header: a column added on one side only does not compile.
        let fields: [String; CSV_COLUMNS.len()] = [
            r.model.to_string(),
            e(r.dt),
            r.steps.to_string(),
            e(r.cost),
            e(r.sphere_steps_per_second),
            e(r.energy_err),
            e(r.max_overlap_rel),
            r.escaped.to_string(),
            r.collisions.to_string(),
            e(r.missed),
            e(r.horizon),
            e(r.pos_err),
            r.capped_steps.to_string(),
            r.chosen.map_or_else(String::new, |c| c.to_string()),
        ];
        w.write_record(&fields)?;
    }
    let bytes = w.into_inner().map_err(|e| anyhow::anyhow!("{e}"))?;
    Ok(String::from_utf8(bytes)?)
}

/// Position error against cost, log–log, a line per model (errors below
/// `1e-16` drawn at `1e-16`: rounding).
pub fn svg(rows: &[Row], path: &Path) -> anyhow::Result<()> {
    let floor = 1e-16;
    let xs = rows.iter().map(|r| r.cost.max(1e-9));
    let (xmin, xmax) = xs.fold((f64::INFINITY, 0.0f64), |(a, b), x| (a.min(x), b.max(x)));
    let ys = rows.iter().map(|r| r.pos_err.max(floor));
    let (ymin, ymax) = ys.fold((f64::INFINITY, 0.0f64), |(a, b), y| (a.min(y), b.max(y)));
    let root = SVGBackend::new(path, (800, 560)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            "ballpit tradeoff: position error vs cost",
            ("sans-serif", 22),
        )
        .margin(16)
        .x_label_area_size(48)
        .y_label_area_size(72)
        .build_cartesian_2d(
            (xmin / 2.0..xmax * 2.0).log_scale(),
            (ymin / 10.0..ymax * 10.0).log_scale(),
        )?;
    chart
        .configure_mesh()
        .x_desc("wall seconds per simulated second (one thread)")
        .y_desc("RMS position error at horizon (box lengths)")
        .x_label_formatter(&|x| format!("{x:.0e}"))
        .y_label_formatter(&|y| format!("{y:.0e}"))
        .draw()?;
    let colours = [RED, BLUE, GREEN, MAGENTA, CYAN];
    for (k, model) in ModelKind::ALL.iter().enumerate() {
        let colour = colours[k % colours.len()];
        let pts: Vec<(f64, f64)> = rows
            .iter()
            .filter(|r| r.model == *model)
            .map(|r| (r.cost.max(1e-9), r.pos_err.max(floor)))
            .collect();
        chart
            .draw_series(LineSeries::new(pts.clone(), colour.stroke_width(2)))?
            .label(model.name())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour));
        chart.draw_series(pts.iter().map(|&p| Circle::new(p, 3, colour.filled())))?;
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()?;
    root.present()?;
    Ok(())
}

/// Measure, and with `out` write `tradeoff.csv` and `tradeoff.svg` there;
/// returns the table for the caller to print.
pub fn run(world: &World, out: Option<&Path>) -> anyhow::Result<String> {
    if let Some(dir) = out {
        // Before the minutes of measuring, not after: a bad path is bad input.
        std::fs::create_dir_all(dir).map_err(|e| {
            crate::error::BadInput(format!("cannot create directory {}: {e}", dir.display()))
        })?;
    }
    let bar = crate::progress::Progress::new(RUNS);
    let rows = measure_with(world, &mut |done, next| bar.set(done, next));
    bar.finish();
    if let Some(dir) = out {
        let csv_path = dir.join("tradeoff.csv");
        std::fs::write(&csv_path, csv(&rows)?)
            .with_context(|| format!("cannot write {}", csv_path.display()))?;
        svg(&rows, &dir.join("tradeoff.svg"))?;
    }
    Ok(markdown(&rows))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::Sphere;
    use glam::DVec3;

    #[test]
    fn csv_has_the_header_and_every_number_in_e_form() {
        let row = Row {
            model: ModelKind::Swept,
            dt: 1.0 / 60.0,
            steps: 120,
            cost: 0.5,
            sphere_steps_per_second: 1.5e6,
            energy_err: 1e-15,
            max_overlap_rel: 0.0,
            escaped: 2,
            collisions: 42,
            missed: -0.25,
            horizon: 0.05,
            pos_err: 3e-3,
            capped_steps: 1,
            chosen: None,
        };
        let text = csv(&[row.clone(), row]).unwrap();
        let line = "swept,1.6666666666666666e-2,120,5e-1,1.5e6,1e-15,0e0,2,42,-2.5e-1,5e-2,3e-3,1,";
        assert_eq!(text, format!("{}\n{line}\n{line}\n", CSV_COLUMNS.join(",")));
    }

    #[test]
    fn progress_counts_every_run_once_in_order() {
        let spheres = (0..4)
            .map(|i| Sphere {
                pos: DVec3::new(0.2 + 0.2 * f64::from(i), 0.5, 0.5),
                vel: DVec3::new(0.3, -0.2 * f64::from(i), 0.1),
                radius: 0.05,
                mass: 1.0,
            })
            .collect();
        let world = World::new(1.0, spheres);
        let mut seen = Vec::new();
        let rows = measure_with(&world, &mut |done, next| {
            seen.push((done, next.to_string()));
        });
        assert_eq!(rows.len(), ModelKind::ALL.len() * LADDER.len());
        assert_eq!(seen.len(), RUNS);
        assert!(seen.iter().enumerate().all(|(i, (done, _))| *done == i));
        assert_eq!(seen[0].1, "reference");
        assert_eq!(seen[RUNS - 1].1, "auto to the horizon, dt 1/1920");
    }
}
