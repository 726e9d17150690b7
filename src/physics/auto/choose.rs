//! `auto`'s choice: a pure function of a summary of the scene, `dt` and the
//! tolerance, so every machine and every threading mode chooses alike. The
//! costs are predicted from event and step counts, calibrated once against
//! `ballpit tradeoff` (docs/models.md, "auto"), never timed.
use crate::physics::kind::{Choice, ModelKind, Tolerance};
use crate::physics::swept;
use crate::physics::world::World;
use std::f64::consts::PI;

/// Predicted cost of one `exact` contact or wall event, of a cell
/// crossing (it rescans only the cells it enters), of a sphere in a step,
/// of a sphere's sync at the end of an `advance`, and of a sphere in the
/// overlap readout the engine asks for each frame, in seconds: fitted to
/// `ballpit bench` and `ballpit tradeoff` on the gas and projectiles
/// presets (docs/models.md, "auto").
const EXACT_EVENT: f64 = 4.4e-7;
const EXACT_CROSSING: f64 = 2.0e-7;
const EXACT_SPHERE_STEP: f64 = 1.8e-9;
const EXACT_SPHERE_SYNC: f64 = 1.1e-8;
const EXACT_SPHERE_READOUT: f64 = 7.1e-8;
/// `exact`'s events touch spheres, cells and queue entries at random, so
/// once its state outgrows the cache an event costs more: by
/// `1 + EXACT_MISS × (1 − EXACT_CACHED / N)` from `EXACT_CACHED` spheres
/// up (its state is ~300–500 B a sphere against this host's 32 MB L3;
/// fitted to steps of gas-like scenes of 1 000 to 100 000 spheres, which
/// measured 0.7–1.2× the cached price up to 32 000 and 3–5× from 41 000,
/// docs/models.md, "auto"). Its per-sphere passes stream, and stay.
const EXACT_CACHED: f64 = 30_000.0;
const EXACT_MISS: f64 = 5.5;
/// `swept`: one sphere in one part of a step, and one contact or wall hit
/// (its overlap readout is the next step's detection, reused).
const SWEPT_SPHERE_STEP: f64 = 3.5e-8;
const SWEPT_EVENT: f64 = 1.5e-6;
/// `discrete`: one sphere in one step (move, grid, overlaps).
const DISCRETE_SPHERE_STEP: f64 = 3.4e-8;
/// `swept` is taken over `exact` only when predicted this much cheaper:
/// near the boundary the model exact to rounding keeps the promise.
const SWEPT_MARGIN: f64 = 1.2;
/// `discrete` sinks a pair by up to its closing speed × dt; it is let in
/// only when twice that bound (speeds spread by collisions) stays within
/// the tolerance.
const DISCRETE_MARGIN: f64 = 2.0;
/// How far the predicted events of a step may fall short of what `exact`
/// meets: a scene predicted within this factor of its cap may hit it, and a
/// capped step ends in free flight, breaking the tolerance (a random scene
/// of 94 265 spheres at speed 16.6, dt 1/15, did at 0.9 of the cap).
pub const EXACT_CAP_MARGIN: f64 = 2.0;

/// What the choice reads from the scene: one pass over the spheres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Summary {
    pub count: usize,
    pub size: f64,
    pub r_min: f64,
    pub r_max: f64,
    pub r_mean: f64,
    /// The mean of r²: with `r_mean`, a pair's mean contact cross-section
    /// when radii spread.
    pub r2_mean: f64,
    pub packing: f64,
    pub v_rms: f64,
    pub v_max: f64,
}

impl Summary {
    pub fn of(world: &World) -> Summary {
        let n = world.spheres.len();
        let (mut r_min, mut r_max, mut r_sum, mut r2_sum, mut vol, mut vv, mut v_max) =
            (f64::INFINITY, 0.0_f64, 0.0, 0.0, 0.0, 0.0, 0.0_f64);
        for s in &world.spheres {
            r_min = r_min.min(s.radius);
            r_max = r_max.max(s.radius);
            r_sum += s.radius;
            r2_sum += s.radius * s.radius;
            vol += s.radius.powi(3);
            let v2 = s.vel.length_squared();
            vv += v2;
            v_max = v_max.max(v2);
        }
        let nf = n.max(1) as f64;
        Summary {
            count: n,
            size: world.size,
            r_min: if n == 0 { 0.0 } else { r_min },
            r_max,
            r_mean: r_sum / nf,
            r2_mean: r2_sum / nf,
            packing: 4.0 / 3.0 * PI * vol / world.size.powi(3),
            v_rms: (vv / nf).sqrt(),
            v_max: v_max.sqrt(),
        }
    }
}

/// Predicted events per simulated second: contacts (Enskog's rate with
/// the Carnahan–Starling contact value), wall hits and `exact`'s cell
/// crossings (cells a little over a diameter, at most 4 a sphere).
#[derive(Clone, Copy, Debug)]
pub struct Rates {
    pub contacts: f64,
    pub walls: f64,
    pub crossings: f64,
    /// How much dearer an `exact` event is than at its cells' design
    /// occupancy (1): cells sized by the largest sphere hold many small
    /// ones when radii spread, and every event scans its neighbours.
    pub crowding: f64,
}

pub fn rates(s: &Summary) -> Rates {
    let n = s.count as f64;
    if s.count < 2 || s.size <= 0.0 {
        return Rates {
            contacts: 0.0,
            walls: 0.0,
            crossings: 0.0,
            crowding: 1.0,
        };
    }
    let phi = s.packing.min(0.6);
    let g = (1.0 - 0.5 * phi) / (1.0 - phi).powi(3);
    let density = n / s.size.powi(3);
    // σ² the mean of (r_i + r_j)² over pairs, 2 (<r²> + <r>²): (2 <r>)²
    // undercounts contacts by 1.5× when radii spread 50× (log-uniform).
    let sigma2 = 2.0 * (s.r2_mean + s.r_mean * s.r_mean);
    // Enskog: z = 4 n σ² √(π kT/m) g, with kT/m = v_rms² / 3.
    let per_sphere = 4.0 * density * sigma2 * (PI / 3.0).sqrt() * s.v_rms * g;
    // Mean |v_x| of a Maxwell gas: v_rms √(2 / 3π); three axes.
    let axis = 3.0 * s.v_rms * (2.0 / (3.0 * PI)).sqrt();
    let per_side = (s.size / (2.0 * s.r_max.max(1e-300)))
        .floor()
        .clamp(1.0, (4.0 * n).cbrt().ceil().min(512.0));
    // Dense scenes run on neighbour lists: no cell crossings.
    let crossings = if s.packing > 0.3 {
        0.0
    } else {
        n * axis * per_side / s.size
    };
    // Spheres in a cell and its 26 neighbours, against the 27/4 of cells
    // as fine as (4 n)^(1/3) a side; half an event's cost there is its
    // neighbour scan (docs/models.md, "auto"). Neighbour lists: no cells.
    let near = 27.0 * n / per_side.powi(3);
    let crowding = if s.packing > 0.3 {
        1.0
    } else {
        (0.5 * (1.0 + near / 6.75)).max(1.0)
    };
    Rates {
        contacts: 0.5 * n * per_sphere,
        walls: n * axis / s.size,
        crossings,
        crowding,
    }
}

/// How much dearer an `exact` event is for a scene of `n` spheres than
/// for one whose state stays in cache (see [`EXACT_CACHED`]).
fn exact_memory(n: usize) -> f64 {
    1.0 + EXACT_MISS * (1.0 - EXACT_CACHED / (n.max(1) as f64)).max(0.0)
}

/// Predicted seconds of physics per simulated second, per model.
#[derive(Clone, Copy, Debug)]
pub struct Costs {
    pub discrete: f64,
    pub swept: f64,
    pub exact: f64,
}

/// `frame`: steps per `advance` (the tick), each call ending in a sync,
/// and in an overlap readout if `readouts`.
pub fn costs(s: &Summary, dt: f64, swept_parts: u32, frame: u64, readouts: bool) -> Costs {
    let r = rates(s);
    let steps = s.count as f64 / dt;
    let frames = steps / frame.max(1) as f64;
    let per_frame = EXACT_SPHERE_SYNC + if readouts { EXACT_SPHERE_READOUT } else { 0.0 };
    Costs {
        discrete: DISCRETE_SPHERE_STEP * steps,
        swept: SWEPT_SPHERE_STEP * steps * f64::from(swept_parts.max(1))
            + SWEPT_EVENT * (r.contacts + r.walls),
        exact: (EXACT_EVENT * (r.contacts + r.walls) + EXACT_CROSSING * r.crossings)
            * r.crowding
            * exact_memory(s.count)
            + EXACT_SPHERE_STEP * steps
            + per_frame * frames,
    }
}

/// The deepest overlap `discrete` may leave, as a fraction of the smaller
/// radius: two spheres closing at up to twice the top speed for one step.
pub fn discrete_overlap(s: &Summary, dt: f64) -> f64 {
    if s.r_min > 0.0 {
        2.0 * s.v_max * dt / s.r_min
    } else {
        f64::INFINITY
    }
}

/// `swept`'s pair checks in a step of `parts` parts: each sphere against
/// those its path ball of a part meets (reach two mean radii and the rms
/// path of a part), at most all the others. Its parts keep this small but
/// where they run out ([`crate::physics::swept::parts`] stops at 256).
fn swept_work(s: &Summary, dt: f64, parts: u32) -> f64 {
    let n = s.count as f64;
    let k = f64::from(parts.max(1));
    let reach = 2.0 * s.r_mean + s.v_rms * dt / k;
    let met = (n / s.size.powi(3) * 4.0 / 3.0 * PI * reach.powi(3)).min((n - 1.0).max(0.0));
    k * n * met
}

fn ratio(a: f64, b: f64) -> String {
    let x = a / b.max(1e-300);
    if x >= 10.0 {
        format!("{x:.0}×")
    } else {
        format!("{x:.1}×")
    }
}

/// How `choose` is asked: `dt`, steps per frame, the tolerance, `swept`'s
/// parts for this scene, and the strictness floor (1: no `discrete`, 2:
/// `exact` only, once the cheaper ones broke the tolerance).
#[derive(Clone, Copy, Debug)]
pub struct Ask {
    pub dt: f64,
    pub frame: u64,
    pub tol: Tolerance,
    pub parts: u32,
    pub floor: u8,
    /// The caller reads the deepest overlap after every `advance` (the
    /// engine does; `tradeoff` does not).
    pub readouts: bool,
}

/// The choice when `exact`'s predicted events a step (`per_step`) come near
/// its cap or pass it: `swept` where it may run (`swept_ok`: it fits its own
/// caps and the floor lets it in), else `exact`, saying the tolerance
/// cannot be met past the cap. `None` well under the cap.
fn at_exacts_cap(per_step: f64, exact_cap: f64, swept_ok: bool, tol_text: &str) -> Option<Choice> {
    let swept = |reason: String| Choice {
        model: ModelKind::Swept,
        reason,
        unmet: false,
    };
    if per_step <= exact_cap {
        let near = per_step * EXACT_CAP_MARGIN > exact_cap;
        return (near && swept_ok).then(|| {
            swept(format!(
                "exact may hit its event cap (~{per_step:.0} events a step, cap {exact_cap:.0}); {tol_text}"
            ))
        });
    }
    // `exact` would end its steps at the cap, in free flight; `swept`
    // takes every contact within its own cap and budget.
    Some(if swept_ok {
        swept(format!(
            "exact would pass its event cap (~{per_step:.0} events a step > {exact_cap:.0}); {tol_text}"
        ))
    } else {
        Choice {
            model: ModelKind::Exact,
            reason: format!(
                "tolerance cannot be met: ~{per_step:.0} events a step > exact's cap {exact_cap:.0}; {tol_text}"
            ),
            unmet: true,
        }
    })
}

/// The cheapest model predicted to keep the tolerance.
pub fn choose(s: &Summary, ask: Ask) -> Choice {
    let Ask {
        dt,
        frame,
        tol,
        parts: swept_parts,
        floor,
        readouts,
    } = ask;
    let t = tol.fraction();
    let c = costs(s, dt, swept_parts, frame, readouts);
    let r = rates(s);
    let per_step = (r.contacts + r.walls + r.crossings) * dt;
    let exact_cap = crate::physics::exact::event_cap(s.count) as f64;
    // `swept`'s caps, of a cluster and of a step, taken for a part's contacts.
    let swept_cap = swept::event_cap(s.count) as f64;
    let swept_budget = swept::budget(s.count) as f64;
    let tol_text = format!("tol {tol}");
    let swept_fits = r.contacts.max(0.0) * dt / f64::from(swept_parts.max(1)) < swept_cap
        && swept_work(s, dt, swept_parts) < swept_budget;
    if let Some(c) = at_exacts_cap(per_step, exact_cap, floor <= 1 && swept_fits, &tol_text) {
        return c;
    }
    let depth = discrete_overlap(s, dt);
    if floor == 0 && t > 0.0 && DISCRETE_MARGIN * depth <= t && c.discrete < c.swept.min(c.exact) {
        return Choice {
            model: ModelKind::Discrete,
            reason: format!(
                "sinks ≤{depth:.2} r < tol, {} cheaper than {}; {tol_text}",
                ratio(c.swept.min(c.exact), c.discrete),
                if c.exact <= c.swept { "exact" } else { "swept" }
            ),
            unmet: false,
        };
    }
    if floor <= 1 && swept_fits && c.swept * SWEPT_MARGIN < c.exact {
        let frames = (EXACT_SPHERE_SYNC + EXACT_SPHERE_READOUT) * s.count as f64
            / (dt * frame.max(1) as f64);
        let why = if frames > 0.5 * c.exact {
            format!("{frame} step a frame")
        } else if r.crossings > r.contacts + r.walls {
            "fast".to_string()
        } else {
            "coarse dt".to_string()
        };
        return Choice {
            model: ModelKind::Swept,
            reason: format!(
                "{why}: {} cheaper than exact; {tol_text}",
                ratio(c.exact, c.swept)
            ),
            unmet: false,
        };
    }
    let why = if floor >= 2 && c.swept * SWEPT_MARGIN < c.exact {
        "the cheaper models broke the tolerance".to_string()
    } else if s.packing > 0.3 {
        format!("dense: {} cheaper than swept", ratio(c.swept, c.exact))
    } else if c.exact <= c.swept {
        format!("{} cheaper than swept", ratio(c.swept, c.exact))
    } else {
        "near the boundary: the stricter model".to_string()
    };
    Choice {
        model: ModelKind::Exact,
        reason: format!("{why}; {tol_text}"),
        unmet: false,
    }
}
