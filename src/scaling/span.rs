//! `scaling --lanes`: what a pool of many more lanes than this machine has
//! cores would give, from the work and span of the scene's own steps
//! ([`SpanExec`]: every lane of every section run one after another on this
//! thread and timed with its CPU clock). A prediction, never a measurement
//! of a many-core machine: hand-offs cost nothing on paper and the lanes
//! share no memory bandwidth.
use super::Plan;
use crate::engine::{SpanExec, WorkSpan};
use crate::physics::World;

/// Most lanes `--lanes` takes: past a thousand the sections' blocks run out
/// long before the lanes, and the schedule is only bookkeeping.
pub const MAX_LANES: usize = 1024;

/// The lanes `scaling` predicts for without `--lanes`.
pub const DEFAULT_LANES: [usize; 3] = [16, 64, 128];

/// One lane count's work and span over the sweep's steps.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpanRow {
    pub lanes: usize,
    pub measured: WorkSpan,
    /// The run ended in the same bits as `off`.
    pub same_bits: bool,
}

impl SpanRow {
    /// Work over the infinite-lane span: no number of lanes beats it.
    #[must_use]
    pub fn parallelism(&self) -> f64 {
        self.measured.parallelism()
    }

    /// Work over the span on these lanes (blocks dealt as the pool deals
    /// them): the speed-up predicted from work and span on this machine.
    #[must_use]
    pub fn predicted_speedup(&self) -> f64 {
        self.measured.speedup()
    }

    /// Brent's bound, the speed-up any greedy schedule of `lanes` lanes is
    /// sure of: work / (work / lanes + span∞).
    #[must_use]
    pub fn brent(&self) -> f64 {
        let m = &self.measured;
        let t = m.work / self.lanes as f64 + m.span_inf;
        if t > 0.0 { m.work / t } else { 1.0 }
    }
}

/// Step `world` `steps` steps of `plan`'s model in frames of `tick` on a
/// [`SpanExec`] of `lanes` lanes; its work and span, and the world it ends
/// in. Frames are cut as `bench` cuts them, so the bits are comparable.
#[must_use]
pub fn step(world: &World, plan: &Plan, steps: u64, tick: u64, lanes: usize) -> (WorkSpan, World) {
    let exec = SpanExec::new(lanes);
    let mut w = world.clone();
    let mut model = plan.model.build();
    let measured = exec.measure(&mut || {
        let mut done = 0;
        while done < steps {
            let frame = tick.max(1).min(steps - done);
            model.advance(&mut w, plan.dt, frame, &exec);
            done += frame;
        }
    });
    (measured, w)
}

/// Every lane count of `plan.lanes`, each checked against `reference`.
#[must_use]
pub fn rows(
    world: &World,
    plan: &Plan,
    steps: u64,
    tick: u64,
    reference: &World,
    progress: &mut dyn FnMut(&str),
) -> Vec<SpanRow> {
    plan.lanes
        .iter()
        .map(|&lanes| {
            progress(&format!("work and span on {lanes} lanes"));
            let (measured, end) = step(world, plan, steps, tick, lanes);
            SpanRow {
                lanes,
                measured,
                same_bits: end.spheres == reference.spheres,
            }
        })
        .collect()
}

/// `--lanes`: lane counts, sorted, each once.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Lanes(pub Vec<usize>);

/// `--lanes`: a comma-separated list of lane counts, 1 to [`MAX_LANES`].
///
/// # Errors
/// The first value that is not a whole number in range, named.
pub fn parse_lanes(s: &str) -> Result<Lanes, String> {
    let range = || format!("lanes are whole numbers from 1 to {MAX_LANES}, e.g. 16,64,128");
    let mut lanes = Vec::new();
    for part in s.split(',') {
        let part = part.trim();
        match part.parse::<usize>() {
            Ok(n) if (1..=MAX_LANES).contains(&n) => lanes.push(n),
            _ => return Err(format!("`{part}` is not a lane count: {}", range())),
        }
    }
    lanes.sort_unstable();
    lanes.dedup();
    Ok(Lanes(lanes))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lanes_parse_as_a_sorted_list_in_range() {
        let ok = |v: &[usize]| Ok(Lanes(v.to_vec()));
        assert_eq!(parse_lanes("16,64,128"), ok(&DEFAULT_LANES));
        assert_eq!(parse_lanes("64, 16,64"), ok(&[16, 64]));
        assert_eq!(parse_lanes("1"), ok(&[1]));
        assert_eq!(parse_lanes("1024"), ok(&[MAX_LANES]));
        for bad in ["0", "100000", "x", "", "16,,64", "-2", "1.5"] {
            let e = parse_lanes(bad).unwrap_err();
            assert!(e.contains("from 1 to 1024"), "{bad}: {e}");
        }
        assert!(parse_lanes("16,0").unwrap_err().starts_with("`0`"));
    }

    #[test]
    fn brents_bound_lies_between_one_lane_and_the_parallelism() {
        let row = SpanRow {
            lanes: 64,
            measured: WorkSpan {
                work: 10.0,
                span: 0.3,
                span_inf: 0.25,
            },
            same_bits: true,
        };
        // 10 / (10/64 + 0.25) = 24.6; parallelism 40; the schedule 33.3,
        // which a greedy schedule's bound must not exceed.
        assert!((row.brent() - 10.0 / (10.0 / 64.0 + 0.25)).abs() < 1e-12);
        assert!((row.parallelism() - 40.0).abs() < 1e-12);
        assert!((row.predicted_speedup() - 10.0 / 0.3).abs() < 1e-12);
        assert!(row.brent() <= row.predicted_speedup());
        assert!(row.predicted_speedup() <= row.parallelism() && row.parallelism() <= 64.0);
    }
}
