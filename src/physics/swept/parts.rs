//! Into how many equal parts a step is cut. Detection looks for pairs
//! whose path balls meet, and a ball grows with speed × dt: when the paths
//! are long against the gaps between spheres, the pairs grow with the cube
//! of the path (N² in the limit: 30 000 of the `projectiles` preset's
//! spheres made 77 million pairs, 1.5 GB and 90 s a step), and so do the
//! spheres drawn into each other's events, until the clusters merge into
//! one serial loop over everyone (a dense 100 000 took 6 s a step). Cut into
//! k parts, each part's balls shrink toward the spheres themselves, for k
//! passes over everyone. The events are the same whatever k is: each part
//! takes its contacts in time order from where the last one ended.
//!
//! k is the fewest parts that keep the pairs the motion adds (beyond those
//! of spheres already within touching distance) under [`ADDED_PAIRS`] a
//! sphere, estimated from a sample of the spheres: a function of the state
//! alone, so every thread count picks the same k.
use crate::physics::sphere::Sphere;
use std::f64::consts::PI;

/// One sphere in this many is sampled, at least [`SAMPLE_MIN`] and at most
/// [`SAMPLE_MAX`] of them: the estimate's noise is a few per cent from
/// 10 000 spheres up, for a cost under 0.5 % of a step.
const SAMPLE_EVERY: usize = 32;
const SAMPLE_MIN: usize = 64;
const SAMPLE_MAX: usize = 1024;
/// No more parts than this.
pub const MAX_PARTS: u32 = 256;
/// Pairs per sphere the motion may add in one part: fewer parts cost more
/// pairs and bigger clusters, more parts more passes over everyone; this
/// balances them (docs/benchmarks.md, "tuned constants").
pub const ADDED_PAIRS: f64 = 0.34;

/// Moments of a sphere's path-ball reach `r + s τ` (`s` its speed), as
/// sums over the sample of `r^a s^b`, for every τ at once.
#[derive(Default)]
struct Moments {
    n: f64,
    r: f64,
    s: f64,
    rr: f64,
    rs: f64,
    ss: f64,
    rrr: f64,
    rrs: f64,
    rss: f64,
    sss: f64,
}

impl Moments {
    fn of(spheres: &[Sphere]) -> Self {
        let n = spheres.len();
        let samples = (n / SAMPLE_EVERY).clamp(SAMPLE_MIN, SAMPLE_MAX);
        let stride = n.div_ceil(samples).max(1);
        let mut m = Moments::default();
        for sp in spheres.iter().step_by(stride) {
            let (r, s) = (sp.radius, sp.vel.length());
            m.n += 1.0;
            m.r += r;
            m.s += s;
            m.rr += r * r;
            m.rs += r * s;
            m.ss += s * s;
            m.rrr += r * r * r;
            m.rrs += r * r * s;
            m.rss += r * s * s;
            m.sss += s * s * s;
        }
        m
    }

    /// The mean of `(a_i + a_j)^3` over pairs of independent samples,
    /// `a = r + s τ`: the volume factor of two balls meeting.
    fn pair_cube(&self, tau: f64) -> f64 {
        let n = self.n;
        let m1 = (self.r + tau * self.s) / n;
        let m2 = (self.rr + 2.0 * tau * self.rs + tau * tau * self.ss) / n;
        let m3 = (self.rrr
            + 3.0 * tau * self.rrs
            + 3.0 * tau * tau * self.rss
            + tau * tau * tau * self.sss)
            / n;
        2.0 * m3 + 6.0 * m1 * m2
    }
}

/// The parts for a step of `dt` of `spheres` in a box of side `size`.
pub fn parts(spheres: &[Sphere], size: f64, dt: f64) -> u32 {
    let n = spheres.len();
    if n < 2 {
        return 1;
    }
    let m = Moments::of(spheres);
    let others = (n - 1) as f64;
    let per_volume = others / (size * size * size) * 4.0 / 3.0 * PI;
    let touching = m.pair_cube(0.0);
    // Neighbours crowd at contact as the packing grows: the shell the
    // motion adds holds the Carnahan–Starling contact value `g` times the
    // mean density (1.3 at packing 0.1, 3.7 at 0.4).
    let phi = (per_volume * m.rrr / m.n).min(0.64);
    let g = (1.0 - 0.5 * phi) / (1.0 - phi).powi(3);
    // Pairs per sphere whose balls meet in a part of `k`, counted at both
    // ends, less those of the spheres themselves.
    let added = |k: u32| {
        let tau = 0.5 * dt / f64::from(k);
        (g * per_volume * (m.pair_cube(tau) - touching)).min(others) * 0.5
    };
    if added(1) <= ADDED_PAIRS || !added(1).is_finite() {
        return 1;
    }
    // `added` falls as k grows: the fewest parts that bring it under.
    let (mut lo, mut hi) = (1, MAX_PARTS);
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        if added(mid) <= ADDED_PAIRS {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    hi
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    fn gas(n: usize, radius: f64, speed: f64) -> Vec<Sphere> {
        (0..n)
            .map(|i| {
                let a = i as f64;
                Sphere::new(
                    DVec3::splat(0.5),
                    DVec3::new(a.sin(), a.cos(), (2.0 * a).sin()).normalize() * speed,
                    radius,
                )
            })
            .collect()
    }

    #[test]
    fn slow_or_dilute_steps_stay_whole() {
        let dt = 1.0 / 60.0;
        // The bench's dilute gas, and 1 000 at packing 0.1: paths short
        // against the gaps.
        assert_eq!(parts(&gas(10_000, 0.0049, 0.5), 1.0, dt), 1);
        assert_eq!(parts(&gas(1_000, 0.0288, 0.5), 1.0, dt), 1);
        // One sphere crossing the box many times has no one to meet.
        assert_eq!(parts(&gas(1, 0.01, 1000.0), 1.0, dt), 1);
    }

    #[test]
    fn crowds_are_cut_more_the_denser_they_are() {
        let dt = 1.0 / 60.0;
        // 100 000 at the same speed: packing 0.005, 0.1 and 0.4.
        let k: Vec<u32> = [0.00228, 0.0062, 0.00985]
            .iter()
            .map(|&r| parts(&gas(100_000, r, 0.5), 1.0, dt))
            .collect();
        assert!(1 < k[0] && k[0] < k[1] && k[1] < k[2], "{k:?}");
    }

    #[test]
    fn fast_crowds_are_cut_more_as_they_grow() {
        let dt = 1.0 / 60.0;
        let k = |n| parts(&gas(n, 0.005, 20.0), 1.0, dt);
        let (k1, k2, k3) = (k(200), k(3000), k(30_000));
        assert!(k1 > 1, "{k1}");
        assert!(k1 < k2 && k2 < k3, "{k1} {k2} {k3}");
        assert!(k3 <= MAX_PARTS);
    }

    #[test]
    fn the_moments_give_the_mean_cube_of_two_reaches() {
        let s = gas(4, 0.01, 2.0);
        let m = Moments::of(&s);
        let tau = 0.3;
        let a: Vec<f64> = s.iter().map(|x| x.radius + x.vel.length() * tau).collect();
        let mut mean = 0.0;
        for x in &a {
            for y in &a {
                mean += (x + y).powi(3);
            }
        }
        mean /= 16.0;
        assert!((m.pair_cube(tau) - mean).abs() <= 1e-12 * mean);
    }
}
