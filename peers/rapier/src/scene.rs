//! The sphere CSV shared with `ballpit` (header `x,y,z,vx,vy,vz,radius,mass`).

use std::fmt::Write as _;

/// One sphere as read from (or written to) the CSV, in f64 like ballpit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    pub pos: [f64; 3],
    pub vel: [f64; 3],
    pub radius: f64,
    pub mass: f64,
}

const HEADER: [&str; 8] = ["x", "y", "z", "vx", "vy", "vz", "radius", "mass"];

/// Parses the CSV and checks what rapier cannot be trusted to reject: non-finite numbers,
/// non-positive radius or mass, centres outside the cube.
pub fn parse(text: &str, box_len: f64) -> Result<Vec<Sphere>, String> {
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let (_, header) = lines.next().ok_or("empty CSV: expected a header line")?;
    let cols: Vec<&str> = header.split(',').map(str::trim).collect();
    if cols != HEADER {
        return Err(format!(
            "line 1: header must be `{}`, found `{header}`",
            HEADER.join(",")
        ));
    }
    let mut out = Vec::new();
    for (i, line) in lines {
        let n = i + 1;
        let vals: Vec<f64> = line
            .split(',')
            .map(|f| {
                f.trim()
                    .parse::<f64>()
                    .map_err(|_| format!("line {n}: `{}` is not a number", f.trim()))
            })
            .collect::<Result<_, _>>()?;
        if vals.len() != 8 {
            return Err(format!("line {n}: expected 8 fields, found {}", vals.len()));
        }
        if let Some(v) = vals.iter().find(|v| !v.is_finite()) {
            return Err(format!("line {n}: non-finite value {v}"));
        }
        let s = Sphere {
            pos: [vals[0], vals[1], vals[2]],
            vel: [vals[3], vals[4], vals[5]],
            radius: vals[6],
            mass: vals[7],
        };
        if s.radius <= 0.0 || s.mass <= 0.0 {
            return Err(format!("line {n}: radius and mass must be positive"));
        }
        if s.pos.iter().any(|&c| c < 0.0 || c > box_len) {
            return Err(format!(
                "line {n}: centre outside the cube [0, {box_len}]^3"
            ));
        }
        out.push(s);
    }
    if out.is_empty() {
        return Err("the CSV holds no sphere".into());
    }
    Ok(out)
}

/// Writes the CSV; f64 `Display` is the shortest text that reads back to the same value.
pub fn to_csv(spheres: &[Sphere]) -> String {
    let mut s = HEADER.join(",");
    s.push('\n');
    for p in spheres {
        let [x, y, z] = p.pos;
        let [vx, vy, vz] = p.vel;
        let _ = writeln!(s, "{x},{y},{z},{vx},{vy},{vz},{},{}", p.radius, p.mass);
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_round_trips_exactly() {
        let a = Sphere {
            pos: [0.1, 0.2 + 1e-17, 1.0 / 3.0],
            vel: [-0.7, 0.0, 1e-300],
            radius: 0.01,
            mass: 4.1887902047863905e-6,
        };
        let text = to_csv(&[a, a]);
        assert_eq!(parse(&text, 1.0).unwrap(), vec![a, a]);
    }

    #[test]
    fn rejects_bad_rows() {
        let h = "x,y,z,vx,vy,vz,radius,mass\n";
        assert!(parse(&format!("{h}0.5,0.5,0.5,0,0,0,0,1\n"), 1.0).is_err());
        assert!(parse(&format!("{h}0.5,0.5,1.5,0,0,0,0.1,1\n"), 1.0).is_err());
        assert!(parse(&format!("{h}0.5,0.5,NaN,0,0,0,0.1,1\n"), 1.0).is_err());
        assert!(parse(&format!("{h}0.5,0.5\n"), 1.0).is_err());
        assert!(parse("a,b\n", 1.0).is_err());
    }
}
