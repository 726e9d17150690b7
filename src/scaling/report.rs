//! The sweep as a markdown table, a CSV and an SVG plot.
use super::{Row, Sweep, fit};
use crate::engine::Threading;
use anyhow::Context;
use plotters::prelude::*;
use std::fmt::Write as _;
use std::path::Path;

fn opt(x: Option<f64>, digits: usize) -> String {
    x.map_or_else(|| "—".to_string(), |v| format!("{v:.digits$}"))
}

/// The Karp–Flatt cell: the fraction, or why a pool on more than one
/// processor has none (a speed-up below 1, or above linear).
fn karp_flatt_cell(r: &Row) -> String {
    match r.karp_flatt {
        None if r.config.threading == Threading::Pool && r.processors > 1 => if r.speedup < 1.0 {
            "no speed-up"
        } else {
            "above linear"
        }
        .to_string(),
        kf => opt(kf, 3),
    }
}

/// `x` to three places, an empty sum's `-0` (or a rounding to it) as 0.
fn three_places(x: f64) -> String {
    let s = format!("{x:.3}");
    if s.trim_start_matches('-')
        .bytes()
        .all(|b| b == b'0' || b == b'.')
    {
        "0".to_string()
    } else {
        s
    }
}

/// The table, with the scene above it and the fit and its predictions below.
#[must_use]
pub fn markdown(s: &Sweep) -> String {
    let p = &s.plan;
    let load = match s.load_average.as_slice() {
        [a, b] => format!(", load {a:.2} → {b:.2}"),
        _ => String::new(),
    };
    let mut out = format!(
        "Scaling of {} on {} spheres (packing {}), dt {}, {} steps a run, {} rounds in alternation, {} cores{load}.\n\n",
        p.model,
        s.n,
        three_places(s.packing),
        crate::tradeoff::dt_label(p.dt),
        s.steps,
        p.rounds,
        p.cores,
    );
    if let Some(why) = &s.nothing_to_share {
        out.push_str(why);
        out.push_str("\n\n");
    }
    out.push_str(
        "| mode | threads | processors | steps/s | slowest–fastest | speed-up over off | efficiency | physics CPU s | CPU s over off | serial fraction, measured | Karp–Flatt |\n\
         |---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for r in &s.rows {
        let _ = writeln!(
            out,
            "| {} | {} | {} | {:.1} | {:.1}–{:.1} | {:.2}× | {:.0} % | {:.2} | {:+.2} | {} | {} |",
            r.config.threading,
            r.config.threads,
            r.processors,
            r.steps_per_second,
            r.steps_per_second_range.0,
            r.steps_per_second_range.1,
            r.speedup,
            100.0 * r.efficiency,
            r.physics_cpu_seconds,
            r.cpu_over_off,
            opt(r.serial_measured, 3),
            karp_flatt_cell(r),
        );
    }
    out.push('\n');
    notes(s, &mut out);
    out
}

/// Below the table: a busy host, runs that ended in other bits, the fit
/// and what it predicts.
fn notes(s: &Sweep, out: &mut String) {
    let p = &s.plan;
    if let Some(&start) = s.load_average.first()
        && start >= 0.5 * p.cores as f64
    {
        let _ = writeln!(
            out,
            "WARNING: the host was busy before the sweep began (load {start:.2} on {} cores): other work took cores the runs needed, so these figures measure the host as much as the threading; run again on an idle host.",
            p.cores
        );
    }
    let differ: Vec<String> = s
        .rows
        .iter()
        .filter(|r| !r.same_bits)
        .map(|r| r.config.label())
        .collect();
    if differ.is_empty() {
        out.push_str("Every run ended in the same bits as off.\n");
    } else {
        let _ = writeln!(
            out,
            "WARNING: {} ended in other bits than off (the physics promises the same in every mode).",
            differ.join(", ")
        );
    }
    match s.fitted {
        Some(f) => {
            let _ = writeln!(
                out,
                "Amdahl fit of the pool's speed-ups up to the cores: serial fraction {f:.3} (the pool's own clock, its time outside parallel sections: {}).",
                opt(s.measured, 3)
            );
            let pred: Vec<String> = s
                .predictions()
                .iter()
                .map(|(c, x)| format!("{c} cores {x:.1}×"))
                .collect();
            let _ = writeln!(
                out,
                "Predicted by that fit, not measured (this machine has {} cores): {}.",
                p.cores,
                pred.join(", ")
            );
        }
        None => out.push_str(
            "No pool ran on more than one processor, so there is no serial fraction to fit.\n",
        ),
    }
}

/// The CSV's columns; `mode` is `predicted` on the rows of the fit's
/// predictions (only `threads`, `processors` and `speedup` filled in).
pub const CSV_COLUMNS: [&str; 14] = [
    "mode",
    "threads",
    "processors",
    "steps",
    "steps_per_second",
    "steps_per_second_min",
    "steps_per_second_max",
    "speedup",
    "efficiency",
    "physics_cpu_seconds",
    "cpu_seconds_over_off",
    "serial_measured",
    "karp_flatt",
    "same_bits",
];

/// The rows as CSV, numbers in `{:e}` form as `tradeoff.csv` has them.
///
/// # Errors
/// Only if the CSV writer fails in memory.
pub fn csv(s: &Sweep) -> anyhow::Result<String> {
    let mut w = ::csv::Writer::from_writer(Vec::new());
    w.write_record(CSV_COLUMNS)?;
    let e = |x: f64| format!("{x:e}");
    let oe = |x: Option<f64>| x.map_or_else(String::new, e);
    for r in &s.rows {
        // Sized by the header: a column added on one side only does not compile.
        let fields: [String; CSV_COLUMNS.len()] = [
            r.config.threading.to_string(),
            r.config.threads.to_string(),
            r.processors.to_string(),
            s.steps.to_string(),
            e(r.steps_per_second),
            e(r.steps_per_second_range.0),
            e(r.steps_per_second_range.1),
            e(r.speedup),
            e(r.efficiency),
            e(r.physics_cpu_seconds),
            e(r.cpu_over_off),
            oe(r.serial_measured),
            oe(r.karp_flatt),
            r.same_bits.to_string(),
        ];
        w.write_record(&fields)?;
    }
    for (cores, speedup) in s.predictions() {
        let mut fields: [String; CSV_COLUMNS.len()] = Default::default();
        fields[0] = "predicted".into();
        fields[1] = cores.to_string();
        fields[2] = cores.to_string();
        fields[7] = e(speedup);
        w.write_record(&fields)?;
    }
    let bytes = w.into_inner().map_err(|e| anyhow::anyhow!("{e}"))?;
    Ok(String::from_utf8(bytes)?)
}

/// Speed-up over `off` against threads, log–log: the pool measured, the
/// other modes as points, the ideal line, and the fit's prediction dashed
/// out to 128 cores.
///
/// # Errors
/// When the file cannot be written.
pub fn svg(s: &Sweep, path: &Path) -> anyhow::Result<()> {
    let (top, ymin, ymax) = extent(s);
    let root = SVGBackend::new(path, (800, 560)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            format!("ballpit scaling: {} on {} spheres", s.plan.model, s.n),
            ("sans-serif", 22),
        )
        .margin(16)
        .x_label_area_size(48)
        .y_label_area_size(64)
        .build_cartesian_2d(
            (1.0..top * 1.2).log_scale(),
            (ymin / 1.2..ymax * 1.5).log_scale(),
        )?;
    chart
        .configure_mesh()
        .x_desc(format!("threads (this machine: {} cores)", s.plan.cores))
        .y_desc("speed-up over off")
        .draw()?;
    // Up to the top of the plot: a point beyond it would be clamped to the
    // edge, bending the line.
    let ideal: Vec<(f64, f64)> = [1.0, top.min(ymax * 1.5)].iter().map(|&x| (x, x)).collect();
    chart
        .draw_series(LineSeries::new(ideal, BLACK.mix(0.3)))?
        .label("ideal (speed-up = threads)")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.mix(0.3)));
    let pool: Vec<(f64, f64)> = rows_of(s, Threading::Pool)
        .map(|r| (r.config.threads as f64, r.speedup))
        .collect();
    chart
        .draw_series(LineSeries::new(pool.clone(), BLUE.stroke_width(2)))?
        .label("pool, measured")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLUE));
    chart.draw_series(pool.iter().map(|&p| Circle::new(p, 4, BLUE.filled())))?;
    for (mode, colour) in [
        (Threading::Worker, GREEN),
        (Threading::Split, MAGENTA),
        (Threading::Off, BLACK),
    ] {
        let pts: Vec<(f64, f64)> = rows_of(s, mode)
            .map(|r| (r.config.threads as f64, r.speedup))
            .collect();
        chart
            .draw_series(
                pts.iter()
                    .map(|&p| Cross::new(p, 6, colour.stroke_width(2))),
            )?
            .label(format!("{mode}, measured"))
            .legend(move |(x, y)| Cross::new((x + 10, y), 5, colour));
    }
    if let Some(f) = s.fitted {
        let curve: Vec<(f64, f64)> = (0..=70)
            .map(|i| {
                let p = top.powf(f64::from(i) / 70.0);
                (p, fit::amdahl(f, p))
            })
            .collect();
        chart
            .draw_series(DashedLineSeries::new(curve, 6, 4, RED.stroke_width(2)))?
            .label(format!("Amdahl fit, serial fraction {f:.3}: predicted"))
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerRight)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()?;
    root.present()?;
    Ok(())
}

/// The plot's reach: the most threads (measured or predicted at), and the
/// least and most speed-up.
fn extent(s: &Sweep) -> (f64, f64, f64) {
    let top = s
        .rows
        .iter()
        .map(|r| r.config.threads)
        .chain(fit::PREDICT_AT)
        .max()
        .unwrap_or(2) as f64;
    let ymax = s
        .rows
        .iter()
        .map(|r| r.speedup)
        .chain(s.predictions().iter().map(|p| p.1))
        .fold(2.0f64, f64::max);
    let ymin = s
        .rows
        .iter()
        .map(|r| r.speedup)
        .fold(0.5f64, f64::min)
        .max(1e-3);
    (top, ymin, ymax)
}

fn rows_of(s: &Sweep, mode: Threading) -> impl Iterator<Item = &Row> {
    s.rows.iter().filter(move |r| r.config.threading == mode)
}

/// `scaling.csv` and `scaling.svg` into `dir`.
pub(super) fn write(s: &Sweep, dir: &Path) -> anyhow::Result<()> {
    let csv_path = dir.join("scaling.csv");
    std::fs::write(&csv_path, csv(s)?)
        .with_context(|| format!("cannot write {}", csv_path.display()))?;
    svg(s, &dir.join("scaling.svg"))
}
