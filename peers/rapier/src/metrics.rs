//! The accuracy and cost figures of `ballpit bench`, computed the same way from the f64 state.

use crate::scene::Sphere;
use std::collections::HashMap;

pub fn kinetic_energy(spheres: &[Sphere]) -> f64 {
    spheres
        .iter()
        .map(|s| 0.5 * s.mass * s.vel.iter().map(|v| v * v).sum::<f64>())
        .sum()
}

/// Spheres whose centre lies outside `[r, L-r]` by more than `1e-9 L` on some axis.
pub fn escaped(spheres: &[Sphere], box_len: f64) -> usize {
    let tol = 1e-9 * box_len;
    spheres
        .iter()
        .filter(|s| {
            s.pos
                .iter()
                .any(|&c| c < s.radius - tol || c > box_len - s.radius + tol)
        })
        .count()
}

/// How far the worst centre lies outside `[r, L-r]`, divided by its radius (0 when none does).
pub fn max_escape_rel(spheres: &[Sphere], box_len: f64) -> f64 {
    spheres
        .iter()
        .flat_map(|s| {
            s.pos
                .iter()
                .map(move |&c| (s.radius - c).max(c - (box_len - s.radius)) / s.radius)
        })
        .fold(0.0, f64::max)
}

/// Deepest pair overlap divided by the smaller radius (0 when nothing overlaps).
/// A uniform grid with cells one largest diameter wide keeps this O(N).
pub fn max_overlap_rel(spheres: &[Sphere]) -> f64 {
    let rmax = spheres.iter().map(|s| s.radius).fold(0.0, f64::max);
    if rmax <= 0.0 {
        return 0.0;
    }
    let cell = 2.0 * rmax;
    let key = |p: [f64; 3]| p.map(|c| (c / cell).floor() as i64);
    let mut grid: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
    for (i, s) in spheres.iter().enumerate() {
        grid.entry(key(s.pos)).or_default().push(i);
    }
    let mut worst = 0.0f64;
    for (i, a) in spheres.iter().enumerate() {
        let k = key(a.pos);
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let Some(cell) = grid.get(&[k[0] + dx, k[1] + dy, k[2] + dz]) else {
                        continue;
                    };
                    for &j in cell.iter().filter(|&&j| j > i) {
                        let b = &spheres[j];
                        let d2: f64 = (0..3).map(|c| (a.pos[c] - b.pos[c]).powi(2)).sum();
                        let depth = a.radius + b.radius - d2.sqrt();
                        if depth > 0.0 {
                            worst = worst.max(depth / a.radius.min(b.radius));
                        }
                    }
                }
            }
        }
    }
    worst
}

/// `{name, cpu_seconds}` for every thread of this process, from `/proc/self/task/*/stat`.
pub fn thread_cpu() -> Vec<(String, f64)> {
    // USER_HZ is fixed at 100 in the Linux user ABI.
    const TICKS_PER_SECOND: f64 = 100.0;
    let mut out = Vec::new();
    let Ok(dir) = std::fs::read_dir("/proc/self/task") else {
        return out;
    };
    for entry in dir.flatten() {
        let Ok(stat) = std::fs::read_to_string(entry.path().join("stat")) else {
            continue;
        };
        // The name sits in parentheses and may itself hold spaces or ')'.
        let (Some(open), Some(close)) = (stat.find('('), stat.rfind(')')) else {
            continue;
        };
        let name = stat[open + 1..close].to_string();
        let rest: Vec<&str> = stat[close + 1..].split_whitespace().collect();
        // After the name: state is field 3, so utime (14) and stime (15) are rest[11], rest[12].
        let ticks = |i: usize| {
            rest.get(i)
                .and_then(|v| v.parse::<f64>().ok())
                .unwrap_or(0.0)
        };
        out.push((name, (ticks(11) + ticks(12)) / TICKS_PER_SECOND));
    }
    out.sort_by(|a, b| a.0.cmp(&b.0));
    out
}

/// Peak resident set (VmHWM) in bytes.
pub fn peak_rss_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ball(x: f64, r: f64) -> Sphere {
        Sphere {
            pos: [x, 0.5, 0.5],
            vel: [1.0, 2.0, 0.0],
            radius: r,
            mass: 2.0,
        }
    }

    #[test]
    fn energy_escape_and_overlap_are_measured() {
        let s = vec![ball(0.3, 0.1), ball(0.45, 0.1), ball(0.95, 0.1)];
        assert!((kinetic_energy(&s) - 15.0).abs() < 1e-12);
        // 0.95 + 0.1 > 1: the third one sticks out of the cube.
        assert_eq!(escaped(&s, 1.0), 1);
        assert!((max_escape_rel(&s, 1.0) - 0.5).abs() < 1e-12);
        assert_eq!(max_escape_rel(&s[..2], 1.0), 0.0);
        // The first two overlap by 0.05 = half a radius.
        assert!((max_overlap_rel(&s) - 0.5).abs() < 1e-12);
        assert_eq!(max_overlap_rel(&s[1..]), 0.0);
    }

    #[test]
    fn proc_readouts_name_this_thread() {
        let cpu = thread_cpu();
        assert!(!cpu.is_empty());
        assert!(cpu.iter().all(|(_, s)| *s >= 0.0));
        assert!(peak_rss_bytes().unwrap() > 0);
    }
}
