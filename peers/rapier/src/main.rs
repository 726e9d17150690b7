//! Peer runner: the ballpit sphere CSV stepped by rapier3d, reporting `ballpit bench`'s JSON line.

mod args;
mod metrics;
mod scene;
mod world;

use serde_json::json;
use std::process::ExitCode;
use std::time::{Duration, Instant};

fn main() -> ExitCode {
    match run() {
        Ok(line) => {
            println!("{line}");
            ExitCode::SUCCESS
        }
        Err(msg) => {
            eprintln!("peer-rapier: {msg}\n{}", args::USAGE);
            ExitCode::from(2)
        }
    }
}

fn run() -> Result<String, String> {
    let a = args::parse(std::env::args().skip(1))?;
    let text = std::fs::read_to_string(&a.scene)
        .map_err(|e| format!("cannot read {}: {e}", a.scene.display()))?;
    let spheres =
        scene::parse(&text, a.box_len).map_err(|e| format!("{}: {e}", a.scene.display()))?;
    let n = spheres.len();
    let mean_diameter = 2.0 * spheres.iter().map(|s| s.radius).sum::<f64>() / n as f64;
    let length_unit = a.length_unit.unwrap_or(mean_diameter);

    let mut w = world::World::new(&spheres, a.box_len, a.dt, a.ccd, length_unit, a.threads)?;
    let mass_err = w.mass_err_rel();
    // Rapier stores f32: anything beyond f32 rounding means the mass was not taken as given.
    if mass_err > 1e-6 {
        return Err(format!(
            "rapier's body mass differs from the CSV's by {mass_err:e} (relative)"
        ));
    }

    let e0 = metrics::kinetic_energy(&w.spheres());
    let mut max_err = 0.0f64;
    let mut stepping = Duration::ZERO;
    for _ in 0..a.steps {
        let t = Instant::now();
        w.step();
        stepping += t.elapsed();
        max_err = max_err.max((w.kinetic_energy() - e0).abs() / e0);
    }
    let wall = stepping.as_secs_f64();
    let end = w.spheres();
    let e1 = metrics::kinetic_energy(&end);
    if let Some(path) = &a.dump {
        std::fs::write(path, scene::to_csv(&end))
            .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    }
    let per_second = |x: f64| if wall > 0.0 { Some(x / wall) } else { None };
    let line = json!({
        "n": n,
        "steps": a.steps,
        "dt": a.dt,
        "model": if a.ccd { "rapier-ccd" } else { "rapier" },
        "threading": if a.threads > 1 { "parallel" } else { "single" },
        "threads": a.threads,
        "wall_seconds": wall,
        "steps_per_second": per_second(a.steps as f64),
        "sphere_steps_per_second": per_second((a.steps * n as u64) as f64),
        "energy_start": e0,
        "energy_end": e1,
        "energy_drift_rel": (e1 - e0).abs() / e0,
        "max_energy_err_rel": max_err,
        "escaped": metrics::escaped(&end, a.box_len),
        "max_escape_rel": metrics::max_escape_rel(&end, a.box_len),
        "max_overlap_rel": metrics::max_overlap_rel(&end),
        "sphere_collisions": null,
        "wall_collisions": null,
        "wall_pressure": null,
        "thread_cpu": metrics::thread_cpu()
            .into_iter()
            .map(|(name, s)| json!({"name": name, "cpu_seconds": s}))
            .collect::<Vec<_>>(),
        "peak_rss_bytes": metrics::peak_rss_bytes(),
        "length_unit": length_unit,
        "mass_err_rel": mass_err,
        "rapier_version": "0.36.1",
        "precision": "f32",
    });
    Ok(line.to_string())
}
