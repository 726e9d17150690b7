//! Scenes: the presets, TOML scene files and sphere CSVs, turned into a
//! checked [`World`].
mod bounded;
pub mod csv_io;
pub mod lattice;
mod place;
pub mod presets;
pub mod toml_file;

use crate::bad;
use crate::error::BadInput;
use crate::physics::sphere::volume;
use crate::physics::{ModelKind, Sphere, World};
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

/// Lengths (the box, a radius) ballpit accepts: volumes, energies and the
/// fourth powers in a time of impact stay normal `f64` numbers in between.
pub const LENGTH_RANGE: (f64, f64) = (1e-40, 1e40);
/// Smallest radius, in box lengths: below it a contact is finer than the
/// rounding of a position in the box.
pub const MIN_RADIUS_REL: f64 = 1e-12;

/// Who gave a scene value, for messages that blame what the user actually
/// gave: `--radius` (the flag), `scene.toml: radius` (a key of the file), or
/// `the preset's radius`.
fn label(flag: &str, given_as_flag: bool, file_with_key: Option<&str>) -> String {
    let key = flag.trim_start_matches("--");
    match (given_as_flag, file_with_key) {
        (true, _) => flag.to_string(),
        (false, Some(file)) => format!("{file}: {key}"),
        (false, None) => format!("the preset's {key}"),
    }
}

/// The bytes of a scene file as text, or a message saying where they are
/// not UTF-8.
pub(crate) fn utf8(bytes: Vec<u8>, name: &str) -> Result<String, BadInput> {
    String::from_utf8(bytes).or_else(|e| {
        let at = e.utf8_error().valid_up_to();
        let line = memchr::memchr_iter(b'\n', &e.as_bytes()[..at]).count() + 1;
        bad!("{name} line {line}: not UTF-8 text")
    })
}

/// Whether a scene on stdin is a sphere CSV: its first line is the header.
fn looks_like_csv(text: &str) -> bool {
    text.lines()
        .find(|l| !l.trim().is_empty())
        .is_some_and(|l| l.trim_start().starts_with('x') && l.contains(','))
}

/// The 1-based line holding byte `at` of `text`.
pub(crate) fn line_of(text: &str, at: usize) -> usize {
    memchr::memchr_iter(b'\n', &text.as_bytes()[..at.min(text.len())]).count() + 1
}

/// `name` ends in `.ext`, in any case (`END.CSV` is a CSV, as the screen's
/// check in `cli/screen.rs` reads it).
fn has_extension(name: &str, ext: &str) -> bool {
    Path::new(name)
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case(ext))
}

/// Build the world a spec describes, or say what is wrong with it.
pub fn build_world(spec: &SceneSpec) -> Result<World, BadInput> {
    build_world_for(spec, None)
}

/// [`build_world`] for a run that starts with `model`: `discrete` takes a
/// scene file with overlapping spheres (as its own `--dump` may hold). The
/// checks read in the order the messages promise: the box, the source
/// (stdin, CSV, TOML, preset), then the preset's values.
pub fn build_world_for(spec: &SceneSpec, model: Option<ModelKind>) -> Result<World, BadInput> {
    let overlaps = if model == Some(ModelKind::Discrete) {
        place::Overlaps::Allow
    } else {
        place::Overlaps::Refuse
    };
    if let Some(size) = spec.size {
        length("--box", size)?;
    }
    let scene = spec.scene.as_deref().unwrap_or("gas");
    let stdin = read_stdin(scene)?;
    let scene = if stdin.is_some() { "stdin" } else { scene };
    if has_extension(scene, "csv") || stdin.as_deref().is_some_and(looks_like_csv) {
        return csv_world(spec, scene, stdin, overlaps);
    }
    let file = if has_extension(scene, "toml") || stdin.is_some() {
        Some(read_toml(scene, stdin.as_deref())?)
    } else {
        None
    };
    let merged = file
        .as_ref()
        .map_or_else(|| spec.clone(), |f| merge(spec, f));
    let labels = Labels::new(spec, file.as_ref().map(|f| (scene, f)));
    let size = merged.size.unwrap_or(1.0);
    length(&labels.size, size)?;
    if let Some(f) = file.as_ref().filter(|f| !f.sphere.is_empty()) {
        return listed_world(f, size, scene, overlaps);
    }
    preset_world(&merged, &labels, size, model)
}

/// `-`: a CSV or TOML scene on standard input, read within the larger
/// (CSV) bound; a TOML one must then keep to its own.
fn read_stdin(scene: &str) -> Result<Option<String>, BadInput> {
    if scene == "-" {
        Ok(Some(bounded::read_text(
            Path::new("/dev/stdin"),
            &csv_io::BOUND,
        )?))
    } else {
        Ok(None)
    }
}

/// A sphere CSV, from `stdin` when given, else from the file `scene`.
fn csv_world(
    spec: &SceneSpec,
    scene: &str,
    stdin: Option<String>,
    overlaps: place::Overlaps,
) -> Result<World, BadInput> {
    if spec.count.is_some() || spec.radius.is_some() || spec.speed.is_some() {
        return bad!("--count, --radius and --speed do not apply to a CSV scene ({scene})");
    }
    let size = spec.size.unwrap_or(1.0);
    match stdin {
        Some(text) => csv_io::parse_with(text, size, scene, overlaps),
        None => csv_io::read(Path::new(scene), size, overlaps),
    }
}

/// A TOML scene, from `stdin` (within the TOML bound) when given, else
/// from the file `scene`.
fn read_toml(scene: &str, stdin: Option<&str>) -> Result<toml_file::SceneFile, BadInput> {
    match stdin {
        Some(text) if text.len() as u64 > toml_file::BOUND.max_bytes => {
            bad!(
                "stdin holds {} bytes of TOML; a TOML scene is at most {} bytes ({})",
                text.len(),
                toml_file::BOUND.max_bytes,
                toml_file::BOUND.why
            )
        }
        Some(text) => toml_file::parse(text, scene),
        None => toml_file::read(Path::new(scene)),
    }
}

/// The flags over the file's keys: a flag given wins.
fn merge(spec: &SceneSpec, f: &toml_file::SceneFile) -> SceneSpec {
    SceneSpec {
        scene: f.preset.clone(),
        count: spec.count.or(f.count),
        radius: spec.radius.or(f.radius),
        speed: spec.speed.or(f.speed),
        seed: spec.seed.or(f.seed),
        size: spec.size.or(f.size),
    }
}

/// Who gave each value, for the messages (see [`label`]).
struct Labels {
    size: String,
    count: String,
    radius: String,
    speed: String,
}

impl Labels {
    /// `file`: the scene file's name and keys, when there is one.
    fn new(spec: &SceneSpec, file: Option<(&str, &toml_file::SceneFile)>) -> Labels {
        // The file's name when the file set the key.
        let from = |set: fn(&toml_file::SceneFile) -> bool| {
            file.filter(|(_, f)| set(f)).map(|(name, _)| name)
        };
        Labels {
            size: label("--box", spec.size.is_some(), from(|f| f.size.is_some())),
            count: label("--count", spec.count.is_some(), from(|f| f.count.is_some())),
            radius: label(
                "--radius",
                spec.radius.is_some(),
                from(|f| f.radius.is_some()),
            ),
            speed: label("--speed", spec.speed.is_some(), from(|f| f.speed.is_some())),
        }
    }
}

/// The spheres a TOML file lists, checked.
fn listed_world(
    f: &toml_file::SceneFile,
    size: f64,
    name: &str,
    overlaps: place::Overlaps,
) -> Result<World, BadInput> {
    let spheres = f
        .sphere
        .iter()
        .map(|e| {
            let mut s = Sphere::new(DVec3::from_array(e.pos), DVec3::from_array(e.vel), e.radius);
            if let Some(m) = e.mass {
                s.mass = m;
            }
            s
        })
        .collect();
    let world = World::new(size, spheres);
    place::check_with(&world, overlaps, name, &|i| format!("sphere {}", i + 1))?;
    Ok(world)
}

/// The world of the preset `merged` names, its values checked first and
/// the spheres it makes after.
fn preset_world(
    merged: &SceneSpec,
    labels: &Labels,
    size: f64,
    model: Option<ModelKind>,
) -> Result<World, BadInput> {
    let name = merged.scene.as_deref().unwrap_or("gas");
    let Some(preset) = presets::find(name) else {
        return bad!(
            "unknown scene '{name}' (expected a preset — {} — or a .toml/.csv file)",
            presets::names()
        );
    };
    let count = merged.count.unwrap_or(preset.count);
    if count > MAX_COUNT {
        return bad!(
            "{} {count} is more than the {MAX_COUNT} spheres ballpit supports ({})",
            labels.count,
            crate::memory::need_text(count, model)
        );
    }
    let radius = preset_radius(merged.radius, preset, count, size, &labels.radius)?;
    let speed = merged.speed.unwrap_or(preset.speed * size);
    if !speed.is_finite() || speed < 0.0 {
        return bad!("{} must be a finite number >= 0, got {speed}", labels.speed);
    }
    let mut rng = place::rng(merged.seed.unwrap_or(DEFAULT_SEED));
    let world = place::generate(preset, count, radius, speed, size, &mut rng)?;
    check_energies(&world, count, &labels.speed, speed, radius)?;
    place::check(&world, "generated scene", &|i| format!("sphere {i}"))?;
    Ok(world)
}

/// The radius given, or the one the preset's packing (or its own radius)
/// makes for `count` spheres, checked against the box.
fn preset_radius(
    given: Option<f64>,
    preset: &presets::Preset,
    count: usize,
    size: f64,
    radius_label: &str,
) -> Result<f64, BadInput> {
    let radius = match (given, preset.packing) {
        (Some(r), _) => r,
        (None, Some(phi)) if count > 0 => {
            (phi * size.powi(3) / (count as f64 * volume(1.0))).cbrt()
        }
        (None, _) => preset.radius * size,
    };
    length(radius_label, radius)?;
    if 2.0 * radius >= size {
        return bad!(
            "{radius_label} {radius} is too big for a box of {size} (it must be under {})",
            size / 2.0
        );
    }
    if radius < MIN_RADIUS_REL * size {
        return bad!(
            "{radius_label} {radius} is too small for a box of {size} (at least {:e}: a finer contact is lost in the rounding of positions)",
            MIN_RADIUS_REL * size
        );
    }
    Ok(radius)
}

/// The energies of a generated world of `count` spheres are finite, and
/// not all 0 when the spheres move.
fn check_energies(
    world: &World,
    count: usize,
    speed_label: &str,
    speed: f64,
    radius: f64,
) -> Result<(), BadInput> {
    if !(world.spheres.iter().all(place::speed_ok) && world.kinetic_energy().is_finite()) {
        return bad!(
            "{speed_label} {speed:e} is too large: the spheres' energies or relative speeds squared would not be finite numbers"
        );
    }
    if speed > 0.0 && count > 0 && !world.kinetic_energy().is_normal() {
        return bad!(
            "{speed_label} {speed:e} is too small for spheres of radius {radius:e}: their kinetic energies underflow to 0, so energy figures would mean nothing"
        );
    }
    Ok(())
}

/// A box or radius: finite, positive, and within [`LENGTH_RANGE`].
fn length(what: &str, x: f64) -> Result<(), BadInput> {
    positive(what, x)?;
    let (lo, hi) = LENGTH_RANGE;
    if (lo..=hi).contains(&x) {
        Ok(())
    } else {
        bad!(
            "{what} {x:e} is outside {lo:e}..{hi:e}: volumes, energies and times of impact would overflow or underflow"
        )
    }
}

fn positive(what: &str, x: f64) -> Result<(), BadInput> {
    if x.is_finite() && x > 0.0 {
        Ok(())
    } else {
        bad!("{what} must be a finite number > 0, got {x}")
    }
}
