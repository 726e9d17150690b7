//! TOML scene files: a preset with overrides, and/or explicit spheres.
//!
//! ```toml
//! preset = "gas"          # optional, default "gas"
//! count = 500             # optional overrides, as the flags
//! radius = 0.02
//! speed = 0.5
//! seed = 7
//! box = 1.0
//! [[sphere]]              # optional: explicit spheres replace generated ones
//! pos = [0.5, 0.5, 0.5]
//! vel = [0.1, 0.0, 0.0]
//! radius = 0.05
//! mass = 1.0              # optional, default: volume (density 1)
//! ```
use super::bounded::Bound;
use crate::bad;
use crate::error::BadInput;
use serde::Deserialize;
use std::fmt::Write as _;
use std::path::Path;

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    pub preset: Option<String>,
    pub count: Option<usize>,
    pub radius: Option<f64>,
    pub speed: Option<f64>,
    pub seed: Option<u64>,
    #[serde(rename = "box")]
    pub size: Option<f64>,
    #[serde(default)]
    pub sphere: Vec<SphereEntry>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SphereEntry {
    #[serde(deserialize_with = "three")]
    pub pos: [f64; 3],
    #[serde(default, deserialize_with = "three")]
    pub vel: [f64; 3],
    pub radius: f64,
    pub mass: Option<f64>,
}

/// Exactly three numbers: serde's fixed arrays let TOML pass a longer list.
fn three<'de, D: serde::Deserializer<'de>>(d: D) -> Result<[f64; 3], D::Error> {
    let v: Vec<f64> = Vec::deserialize(d)?;
    <[f64; 3]>::try_from(v.as_slice()).map_err(|_| {
        serde::de::Error::custom(format!("expected 3 numbers [x, y, z], found {}", v.len()))
    })
}

/// What a TOML scene may hold, decided before reading: `MAX_SPHERES`
/// entries of at most 1 KB (an entry with four keys of long numbers is
/// about 150 bytes), and the preset keys.
pub const BOUND: Bound = Bound {
    kind: "TOML",
    max_bytes: MAX_SPHERES as u64 * 1024 + 64 * 1024,
    max_line: 4096,
    max_lines: MAX_SPHERES * 64 + 1024,
    why: "100000 [[sphere]] entries, 1 KB an entry",
};

pub fn read(path: &Path) -> Result<SceneFile, BadInput> {
    let text = super::bounded::read_text(path, &BOUND)?;
    parse(&text, &path.display().to_string())
}

/// Most `[[sphere]]` entries a TOML scene may hold: parsing TOML takes
/// about 3 KB a sphere, a CSV under a tenth of that.
pub const MAX_SPHERES: usize = 100_000;

pub fn parse(text: &str, name: &str) -> Result<SceneFile, BadInput> {
    // An empty file would silently be the default scene.
    if text
        .lines()
        .all(|l| l.trim().is_empty() || l.trim().starts_with('#'))
    {
        return bad!(
            "{name}: the file is empty: give `preset = \"gas\"`, overrides such as `count = 500`, or [[sphere]] entries"
        );
    }
    let entries = text.matches("[[sphere]]").count();
    if entries > MAX_SPHERES {
        return bad!(
            "{name}: {entries} [[sphere]] entries; a TOML scene holds at most {MAX_SPHERES} (parsing takes about 3 KB a sphere): give that many spheres as a CSV"
        );
    }
    toml::from_str(text).or_else(|e: toml::de::Error| {
        let line = e.span().map(|s| super::line_of(text, s.start));
        let msg = short_numbers(e.message());
        match line {
            Some(l) => bad!("{name} line {l}: {msg}"),
            None => bad!("{name}: {msg}"),
        }
    })
}

/// `msg` with every number of more than 20 digits (toml prints `1e308` in
/// full) written as `1e308`.
fn short_numbers(msg: &str) -> String {
    let mut out = String::new();
    let mut run = String::new();
    for c in msg.chars().chain(['\0']) {
        if c.is_ascii_digit() || (c == '.' && !run.is_empty()) {
            run.push(c);
            continue;
        }
        match run.parse::<f64>() {
            Ok(v) if run.len() > 20 => {
                let _ = write!(out, "{v:e}");
            }
            _ => out.push_str(&run),
        }
        run.clear();
        if c != '\0' {
            out.push(c);
        }
    }
    out
}
