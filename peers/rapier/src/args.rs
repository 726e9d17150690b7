//! Command line of the peer runner; bad input gets one message and exit code 2.

use std::path::PathBuf;

pub const USAGE: &str = "usage: peer-rapier SCENE.csv [--box L] [--dt DT] --steps K [--ccd] \
[--threads K] [--length-unit U] [--dump FILE.csv]";

#[derive(Debug)]
pub struct Args {
    pub scene: PathBuf,
    pub box_len: f64,
    pub dt: f64,
    pub steps: u64,
    pub ccd: bool,
    pub threads: usize,
    /// Rapier's `length_unit` (its tolerances are tuned for 1 m objects); `None` = mean diameter.
    pub length_unit: Option<f64>,
    pub dump: Option<PathBuf>,
}

fn positive(flag: &str, v: &str) -> Result<f64, String> {
    match v.parse::<f64>() {
        Ok(x) if x.is_finite() && x > 0.0 => Ok(x),
        _ => Err(format!("{flag}: expected a positive number, found `{v}`")),
    }
}

pub fn parse(mut it: impl Iterator<Item = String>) -> Result<Args, String> {
    let mut scene = None;
    let mut a = Args {
        scene: PathBuf::new(),
        box_len: 1.0,
        dt: 1.0 / 60.0,
        steps: 0,
        ccd: false,
        threads: 1,
        length_unit: None,
        dump: None,
    };
    let mut steps_seen = false;
    while let Some(flag) = it.next() {
        if flag == "--ccd" {
            a.ccd = true;
            continue;
        }
        if !flag.starts_with("--") {
            if scene.replace(PathBuf::from(&flag)).is_some() {
                return Err(format!("more than one scene given (`{flag}`)"));
            }
            continue;
        }
        let v = it.next().ok_or(format!("{flag}: missing value"))?;
        match flag.as_str() {
            "--scene" => scene = Some(PathBuf::from(v)),
            "--box" => a.box_len = positive(&flag, &v)?,
            "--dt" => a.dt = positive(&flag, &v)?,
            "--length-unit" => a.length_unit = Some(positive(&flag, &v)?),
            "--steps" => {
                a.steps = v
                    .parse()
                    .map_err(|_| format!("--steps: expected a whole number, found `{v}`"))?;
                steps_seen = true;
            }
            "--threads" => {
                a.threads = match v.parse() {
                    Ok(k) if k > 0 => k,
                    _ => {
                        return Err(format!(
                            "--threads: expected a positive whole number, found `{v}`"
                        ));
                    }
                }
            }
            "--dump" => a.dump = Some(PathBuf::from(v)),
            _ => return Err(format!("unknown flag `{flag}`")),
        }
    }
    a.scene = scene.ok_or("no scene CSV given")?;
    if !steps_seen {
        return Err("--steps is required".into());
    }
    Ok(a)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(s: &str) -> Result<Args, String> {
        parse(s.split_whitespace().map(String::from))
    }

    #[test]
    fn flags_parse_and_bad_ones_are_named() {
        let a = p("s.csv --box 2 --dt 0.01 --steps 5 --ccd --threads 2").unwrap();
        assert_eq!(
            (a.box_len, a.dt, a.steps, a.ccd, a.threads),
            (2.0, 0.01, 5, true, 2)
        );
        assert!(p("s.csv").unwrap_err().contains("--steps"));
        assert!(p("s.csv --steps 1 --dt -1").unwrap_err().contains("--dt"));
        assert!(
            p("s.csv --steps 1 --threads 0")
                .unwrap_err()
                .contains("--threads")
        );
        assert!(
            p("s.csv --steps 1 --frob 1")
                .unwrap_err()
                .contains("--frob")
        );
        assert!(p("--steps 1").unwrap_err().contains("scene"));
    }
}
