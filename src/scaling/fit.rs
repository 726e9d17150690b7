//! Amdahl's law read both ways: the Karp–Flatt serial fraction of one
//! measured speed-up, and the one fraction that fits them all, with the
//! speed-ups it predicts on machines that were not measured.

/// Amdahl's speed-up on `p` processors of a run whose serial fraction is `f`.
#[must_use]
pub fn amdahl(f: f64, p: f64) -> f64 {
    1.0 / (f + (1.0 - f) / p)
}

/// The Karp–Flatt serial fraction of speed-up `speedup` on `p > 1`
/// processors: the `f` for which Amdahl's law gives exactly that speed-up
/// (`None` on one processor, where every `f` does).
#[must_use]
pub fn karp_flatt(speedup: f64, p: f64) -> Option<f64> {
    (p > 1.0 && speedup > 0.0).then(|| (1.0 / speedup - 1.0 / p) / (1.0 - 1.0 / p))
}

/// The serial fraction, clamped to `[0, 1]`, that fits `(p, speed-up)`
/// points best in `1 / speed-up`, which Amdahl's law makes linear in it:
/// `1/S - 1/p = f (1 - 1/p)`. Points on one processor say nothing and are
/// left out; `None` when none is left.
#[must_use]
pub fn fit(points: &[(f64, f64)]) -> Option<f64> {
    let (mut num, mut den) = (0.0, 0.0);
    for &(p, s) in points.iter().filter(|(p, s)| *p > 1.0 && *s > 0.0) {
        let a = 1.0 - 1.0 / p;
        num += a * (1.0 / s - 1.0 / p);
        den += a * a;
    }
    (den > 0.0).then(|| (num / den).clamp(0.0, 1.0))
}

/// The core counts a prediction is given for.
pub const PREDICT_AT: [usize; 3] = [16, 64, 128];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn karp_flatt_inverts_amdahl() {
        for f in [0.0, 0.01, 0.2, 1.0] {
            for p in [2.0, 3.0, 64.0] {
                let e = karp_flatt(amdahl(f, p), p).unwrap();
                assert!((e - f).abs() < 1e-12, "f {f} p {p}: {e}");
            }
        }
        assert_eq!(karp_flatt(1.0, 1.0), None);
        // Superlinear speed-up reads as a negative fraction, not a clamp.
        assert!(karp_flatt(2.5, 2.0).unwrap() < 0.0);
    }

    #[test]
    fn the_fit_recovers_the_fraction_of_amdahl_data() {
        let f = 0.03;
        let pts: Vec<(f64, f64)> = [1.0, 2.0, 4.0, 8.0]
            .iter()
            .map(|&p| (p, amdahl(f, p)))
            .collect();
        assert!((fit(&pts).unwrap() - f).abs() < 1e-12);
        // No speed-up at all is a serial run; more than linear clamps at 0.
        assert_eq!(fit(&[(2.0, 1.0), (4.0, 1.0)]), Some(1.0));
        assert_eq!(fit(&[(2.0, 2.5)]), Some(0.0));
        assert_eq!(fit(&[(1.0, 1.0)]), None);
        assert!((amdahl(0.03, 64.0) - 22.14).abs() < 0.01);
    }
}
