//! The named scenes of issue 2. Each gives defaults that `--count`,
//! `--radius`, `--speed` override.

/// How a preset lays its spheres out and sets them moving.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Layout {
    /// Random non-overlapping positions, Maxwell–Boltzmann velocities.
    Gas,
    /// Random positions, every sphere at exactly `speed` in a random direction.
    Uniform,
    /// A jittered cubic lattice over the whole box, `⌈∛N⌉` sites a side
    /// (random placement jams near 0.38); it melts into the fluid at its
    /// packing within about half a diameter's flight.
    Lattice,
    /// A touching row along x through the centre; the first sphere strikes it.
    Cradle,
    /// Radii log-uniform over 100× around `radius` (mass = volume).
    Mixed,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Preset {
    pub name: &'static str,
    pub count: usize,
    /// Typical radius in box lengths (for `dense`, recomputed from the
    /// packing fraction when `--count` or `--box` changes and `--radius` is not given).
    pub radius: f64,
    pub speed: f64,
    pub layout: Layout,
    /// Target packing fraction, when the preset is defined by one.
    pub packing: Option<f64>,
    pub about: &'static str,
}

pub const PRESETS: [Preset; 6] = [
    Preset {
        name: "gas",
        count: 1000,
        radius: 0.02,
        speed: 0.5,
        layout: Layout::Gas,
        packing: None,
        about: "1000 spheres, dilute (packing 0.034), Maxwell–Boltzmann speeds",
    },
    Preset {
        name: "billiards",
        count: 8,
        radius: 0.1,
        speed: 0.6,
        layout: Layout::Uniform,
        packing: None,
        about: "a few large spheres",
    },
    Preset {
        name: "dense",
        count: 2000,
        radius: 0.0363,
        speed: 0.5,
        layout: Layout::Lattice,
        packing: Some(0.4),
        about: "packing fraction 0.4 from a jittered lattice",
    },
    Preset {
        name: "projectiles",
        count: 200,
        radius: 0.005,
        speed: 20.0,
        layout: Layout::Uniform,
        packing: None,
        about: "small and very fast: 20 box lengths per second",
    },
    Preset {
        name: "cradle",
        count: 5,
        radius: 0.06,
        speed: 0.5,
        layout: Layout::Cradle,
        packing: None,
        about: "Newton's cradle: a touching row, one end moving",
    },
    Preset {
        name: "mixed",
        count: 300,
        radius: 0.01,
        speed: 0.5,
        layout: Layout::Mixed,
        packing: None,
        about: "radii log-uniform over 100x (0.001..0.1), masses over 10^6x",
    },
];

pub fn find(name: &str) -> Option<&'static Preset> {
    PRESETS.iter().find(|p| p.name == name)
}

pub fn names() -> String {
    PRESETS
        .iter()
        .map(|p| p.name)
        .collect::<Vec<_>>()
        .join(", ")
}
