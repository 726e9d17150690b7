//! Scenes: the presets, TOML scene files and sphere CSVs, turned into a
//! checked [`World`].
pub mod csv_io;
pub mod place;
pub mod presets;
pub mod toml_file;

use crate::bad;
use crate::error::BadInput;
use crate::physics::sphere::volume;
use crate::physics::{Sphere, World};
use glam::DVec3;
use std::path::Path;

/// Most spheres a scene may ask for (memory stays well under a few GB).
pub const MAX_COUNT: usize = 10_000_000;

/// What the scene flags ask for; `None` means "the preset's value".
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SceneSpec {
    /// A preset name, a `.toml` scene file or a `.csv` sphere file.
    pub scene: Option<String>,
    pub count: Option<usize>,
    pub radius: Option<f64>,
    pub speed: Option<f64>,
    pub seed: Option<u64>,
    pub size: Option<f64>,
}

pub const DEFAULT_SEED: u64 = 1;

/// Build the world a spec describes, or say what is wrong with it.
pub fn build_world(spec: &SceneSpec) -> Result<World, BadInput> {
    if let Some(size) = spec.size {
        positive("--box", size)?;
    }
    let scene = spec.scene.as_deref().unwrap_or("gas");
    if scene.ends_with(".csv") {
        if spec.count.is_some() || spec.radius.is_some() || spec.speed.is_some() {
            return bad!("--count, --radius and --speed do not apply to a CSV scene ({scene})");
        }
        return csv_io::read(Path::new(scene), spec.size.unwrap_or(1.0));
    }
    let (file, spec) = if scene.ends_with(".toml") {
        let f = toml_file::read(Path::new(scene))?;
        let merged = SceneSpec {
            scene: f.preset.clone(),
            count: spec.count.or(f.count),
            radius: spec.radius.or(f.radius),
            speed: spec.speed.or(f.speed),
            seed: spec.seed.or(f.seed),
            size: spec.size.or(f.size),
        };
        (Some((scene.to_string(), f)), merged)
    } else {
        (None, spec.clone())
    };
    if let Some((name, f)) = file.as_ref().filter(|(_, f)| !f.sphere.is_empty()) {
        let size = spec.size.unwrap_or(1.0);
        positive(&format!("{name}: box"), size)?;
        let spheres = f
            .sphere
            .iter()
            .map(|e| {
                let mut s =
                    Sphere::new(DVec3::from_array(e.pos), DVec3::from_array(e.vel), e.radius);
                if let Some(m) = e.mass {
                    s.mass = m;
                }
                s
            })
            .collect();
        let world = World::new(size, spheres);
        place::check(&world, &|i| format!("{name}: sphere {}", i + 1))?;
        return Ok(world);
    }
    let name = spec.scene.as_deref().unwrap_or("gas");
    let Some(preset) = presets::find(name) else {
        return bad!(
            "unknown scene '{name}' (expected a preset — {} — or a .toml/.csv file)",
            presets::names()
        );
    };
    let size = spec.size.unwrap_or(1.0);
    positive("--box", size)?;
    let count = spec.count.unwrap_or(preset.count);
    if count > MAX_COUNT {
        return bad!("--count {count} is more than the {MAX_COUNT} spheres ballpit supports");
    }
    let radius = match (spec.radius, preset.packing) {
        (Some(r), _) => r,
        (None, Some(phi)) if count > 0 => {
            (phi * size.powi(3) / (count as f64 * volume(1.0))).cbrt()
        }
        (None, _) => preset.radius * size,
    };
    positive("--radius", radius)?;
    if 2.0 * radius >= size {
        return bad!(
            "--radius {radius} is too big for a box of {size} (it must be under {})",
            size / 2.0
        );
    }
    let speed = spec.speed.unwrap_or(preset.speed * size);
    if !speed.is_finite() || speed < 0.0 {
        return bad!("--speed must be a finite number >= 0, got {speed}");
    }
    let mut rng = place::rng(spec.seed.unwrap_or(DEFAULT_SEED));
    let world = place::generate(preset, count, radius, speed, size, &mut rng)?;
    if !(world.spheres.iter().all(place::speed_ok) && world.kinetic_energy().is_finite()) {
        return bad!(
            "--speed {speed:e} is too large: the spheres' energies or relative speeds squared would not be finite numbers"
        );
    }
    place::check(&world, &|i| format!("generated sphere {i}"))?;
    Ok(world)
}

fn positive(what: &str, x: f64) -> Result<(), BadInput> {
    if x.is_finite() && x > 0.0 {
        Ok(())
    } else {
        bad!("{what} must be a finite number > 0, got {x}")
    }
}
