//! The scene as it started, for Reset: kept whole, or rebuilt from its
//! description (a preset is a seed and a few numbers, so the app need not
//! hold a second copy of a million spheres). A rebuilt start is checked
//! against a fingerprint of the first, so Reset gives back the same bits or
//! says it cannot.
use crate::physics::World;
use std::hash::{DefaultHasher, Hasher};

/// Makes the start again; it must give the same world each time.
pub type Rebuild = Box<dyn Fn() -> anyhow::Result<World> + Send>;

pub(crate) enum Start {
    Kept(World),
    Rebuilt {
        rebuild: Rebuild,
        print: u64,
    },
    /// Headless: no Reset.
    Dropped,
}

impl Start {
    pub fn rebuilt(first: &World, rebuild: Rebuild) -> Start {
        Start::Rebuilt {
            rebuild,
            print: fingerprint(first),
        }
    }

    /// The start again, or why not (the notice for the screen).
    pub fn world(&self) -> Result<World, String> {
        match self {
            Start::Kept(w) => Ok(w.clone()),
            Start::Rebuilt { rebuild, print } => {
                let w = rebuild().map_err(|e| format!("reset: {e:#}"))?;
                if fingerprint(&w) == *print {
                    Ok(w)
                } else {
                    Err("reset: the scene rebuilt differently; nothing changed".into())
                }
            }
            Start::Dropped => Err("reset: a headless engine keeps no start".into()),
        }
    }
}

/// Every number of the world, hashed.
fn fingerprint(w: &World) -> u64 {
    let mut h = DefaultHasher::new();
    let c = w.counters;
    for x in [w.size, w.time, c.wall_momentum] {
        h.write_u64(x.to_bits());
    }
    for n in [c.sphere_collisions, c.wall_collisions, c.capped_steps] {
        h.write_u64(n);
    }
    h.write_usize(w.spheres.len());
    for s in &w.spheres {
        for x in s.pos.to_array().into_iter().chain(s.vel.to_array()) {
            h.write_u64(x.to_bits());
        }
        h.write_u64(s.radius.to_bits());
        h.write_u64(s.mass.to_bits());
    }
    h.finish()
}
