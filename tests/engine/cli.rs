//! The binary's command line: bench JSON, --dump, and bad input (exit 2).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use crate::common::cli::{ballpit, scratch};
use crate::common::json;

#[test]
fn bench_prints_one_json_line_with_every_field() {
    let v = json::bench(&["--steps", "30", "--count", "200"]);
    for field in [
        "n",
        "steps",
        "dt",
        "model",
        "threading",
        "threads",
        "wall_seconds",
        "physics_cpu_seconds",
        "first_frame",
        "load_average",
        "collisions_per_sim_second",
        "steps_per_second",
        "sphere_steps_per_second",
        "energy_start",
        "energy_end",
        "energy_drift_rel",
        "max_energy_err_rel",
        "escaped",
        "max_overlap_rel",
        "sphere_collisions",
        "wall_collisions",
        "wall_pressure",
        "thread_cpu",
        "peak_rss_bytes",
        "capped_steps",
    ] {
        assert!(v.get(field).is_some(), "missing {field}");
    }
    assert_eq!(v["n"], 200);
    assert_eq!(v["steps"], 30);
    assert_eq!(v["model"], "swept");
    assert_eq!(v["escaped"], 0);
    assert!(v["energy_drift_rel"].as_f64().unwrap() < 1e-12);
    assert!(v["peak_rss_bytes"].as_u64().unwrap() > 0);
    assert_eq!(v["load_average"].as_array().unwrap().len(), 2);
}

/// The first frame is reported apart (it also loads the model), so a
/// steady rate can leave it out: it is exactly a one-frame run.
#[test]
fn bench_reports_the_first_frame_apart() {
    let args = |steps| {
        let base = ["--model", "exact", "--count", "2000", "--radius", "0.02"];
        let run = ["--threading", "worker", "--tick", "1", "--steps", steps];
        json::bench(&[&base[..], &run[..]].concat())
    };
    let (one, many) = (args("1"), args("20"));
    let first = &many["first_frame"];
    assert_eq!(first["sphere_collisions"], one["sphere_collisions"]);
    assert!(one["sphere_collisions"].as_u64().unwrap() > 0);
    let (f, all) = (
        first["physics_cpu_seconds"].as_f64().unwrap(),
        many["physics_cpu_seconds"].as_f64().unwrap(),
    );
    assert!(f > 0.0 && f < all, "first frame {f} s of {all} s");
    assert!(many["sphere_collisions"].as_u64() > first["sphere_collisions"].as_u64());
}

#[test]
fn an_empty_box_reads_zero_not_minus_zero() {
    let v = json::bench(&["--steps", "3", "--count", "0"]);
    assert_eq!(v["n"], 0);
    for field in [
        "energy_start",
        "energy_end",
        "energy_drift_rel",
        "temperature",
    ] {
        let x = v[field].as_f64().unwrap();
        assert!(x == 0.0 && x.is_sign_positive(), "{field}: {x}");
    }
    assert_eq!(v["sphere_collisions"], 0);
    assert_eq!(v["wall_collisions"], 0);
}

#[test]
fn dump_reads_back_as_the_same_scene() {
    let dir = scratch("cli");
    std::fs::create_dir_all(&dir).unwrap();
    // Upper case reads as the same file type, as the screen's check has it.
    let a = dir.join("a.csv");
    let b = dir.join("B.CSV");
    json::bench(&[
        "--scene",
        "billiards",
        "--steps",
        "10",
        "--dump",
        a.to_str().unwrap(),
    ]);
    // Zero steps from the dump must write it back byte for byte.
    let v = json::bench(&[
        "--scene",
        a.to_str().unwrap(),
        "--steps",
        "0",
        "--dump",
        b.to_str().unwrap(),
    ]);
    assert_eq!(v["n"], 8);
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    let v = json::bench(&["--scene", b.to_str().unwrap(), "--steps", "0"]);
    assert_eq!(v["n"], 8);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
#[allow(clippy::too_many_lines)] // one table of bad inputs and what each must say
fn bad_input_exits_2_with_one_clear_message() {
    let dir = scratch("bad");
    std::fs::create_dir_all(&dir).unwrap();
    let overlap = dir.join("overlap.csv");
    std::fs::write(
        &overlap,
        "x,y,z,vx,vy,vz,radius,mass\n0.5,0.5,0.5,0,0,0,0.1,1\n0.55,0.5,0.5,0,0,0,0.1,1\n",
    )
    .unwrap();
    let fast = dir.join("fast.csv");
    std::fs::write(
        &fast,
        "x,y,z,vx,vy,vz,radius,mass\n0.5,0.5,0.5,1e200,0,0,0.1,1\n",
    )
    .unwrap();
    let broken = dir.join("broken.toml");
    std::fs::write(&broken, "count = [\n").unwrap();
    let cases: Vec<(Vec<String>, &str)> = vec![
        (vec!["--count=-3".into()], "--count"),
        (vec!["--count".into(), "ten".into()], "--count"),
        (vec!["--radius".into(), "0".into()], "--radius must be"),
        (vec!["--radius".into(), "NaN".into()], "--radius must be"),
        (vec!["--radius".into(), "0.6".into()], "too big"),
        (vec!["--speed".into(), "inf".into()], "--speed must be"),
        (vec!["--box=-1".into()], "--box must be"),
        (vec!["--dt".into(), "0".into()], "--dt must be"),
        // A negative number after a flag is a value, judged by the validators.
        (
            vec!["--dt".into(), "-1".into()],
            "--dt must be a finite number > 0, got -1",
        ),
        (vec!["--radius".into(), "-0.1".into()], "--radius must be"),
        (
            vec!["--speed".into(), "1e200".into()],
            "--speed 1e200 is too large",
        ),
        (
            vec!["--scene".into(), fast.to_str().unwrap().into()],
            "line 2: velocity [1e200, 0.0, 0.0] is too fast",
        ),
        (vec!["--tick=-1".into()], "--tick"),
        (
            vec!["--threads".into(), "0".into()],
            "for '--threads <K>': 0 is not in 1..=256",
        ),
        (
            vec!["--threads".into(), "257".into()],
            "for '--threads <K>': 257 is not in 1..=256",
        ),
        (
            vec!["--model".into(), "magic".into()],
            "invalid value 'magic' for '--model <MODEL>'\n  [possible values: discrete, swept, exact, auto]",
        ),
        (
            vec!["--threading".into(), "many".into()],
            "[possible values: off, worker, pool, split]",
        ),
        (
            vec!["--scene".into(), "moon".into()],
            "unknown scene 'moon'",
        ),
        (
            vec!["--scene".into(), "/nonexistent.csv".into()],
            "cannot read scene file",
        ),
        (
            vec!["--scene".into(), overlap.to_str().unwrap().into()],
            "overlap",
        ),
        (
            vec!["--scene".into(), broken.to_str().unwrap().into()],
            "line",
        ),
        (
            vec![
                "--count".into(),
                "100000".into(),
                "--radius".into(),
                "0.1".into(),
            ],
            "cannot fit",
        ),
    ];
    for (args, want) in cases {
        let out = ballpit()
            .arg("bench")
            .arg("--steps")
            .arg("1")
            .args(&args)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(want), "{args:?}: got `{err}`, want `{want}`");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert!(out.stdout.is_empty(), "{args:?}");
    }
    let out = ballpit().arg("bench").output().unwrap();
    assert_eq!(out.status.code(), Some(2), "missing --steps");
    // Output paths are checked before the run: these runs would not end
    // for hours (the timeout only stops a regression from hanging the suite).
    let nowhere = dir.join("missing").join("out");
    let nowhere = nowhere.to_str().unwrap();
    for (args, want) in [
        (
            vec![
                "bench",
                "--count",
                "2",
                "--steps",
                "1000000000000",
                "--dump",
                nowhere,
            ],
            "cannot write",
        ),
        (
            vec!["tradeoff", "--count", "2", "--out", "/proc/ballpit-out"],
            "cannot create directory /proc/ballpit-out",
        ),
    ] {
        let out = ballpit()
            .args(&args)
            .timeout(std::time::Duration::from_mins(2))
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(want), "{args:?}: got `{err}`, want `{want}`");
        assert!(out.stdout.is_empty(), "{args:?}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bench_runs_every_threading_mode_to_the_same_bits() {
    let dir = scratch("modes");
    std::fs::create_dir_all(&dir).unwrap();
    let mut dumps = Vec::new();
    for (mode, first) in [
        ("off", "main"),
        ("worker", "physics"),
        ("pool", "pool-0"),
        ("split", "physics"),
    ] {
        let path = dir.join(format!("{mode}.csv"));
        let v = json::bench(&[
            "--scene",
            "dense",
            "--count",
            "1500",
            "--steps",
            "40",
            "--tick",
            "7",
            "--threading",
            mode,
            "--threads",
            "2",
            "--dump",
            path.to_str().unwrap(),
        ]);
        assert_eq!(v["threading"], mode);
        assert_eq!(v["physics_threads"][0], first, "{mode}");
        if mode != "off" {
            // Threads that sleep between frames have their CPU time read
            // exactly (a running caller's only to the last scheduler tick).
            assert!(v["physics_cpu_seconds"].as_f64().unwrap() > 0.0, "{mode}");
        }
        assert!(v["sphere_collisions"].as_u64().unwrap() > 0);
        let names: Vec<&str> = v["thread_cpu"]
            .as_array()
            .unwrap()
            .iter()
            .map(|t| t["name"].as_str().unwrap())
            .collect();
        assert!(names.contains(&"physics"), "{mode}: {names:?}");
        dumps.push(std::fs::read(&path).unwrap());
    }
    assert!(
        dumps.windows(2).all(|w| w[0] == w[1]),
        "threading modes differ"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn flags_before_a_subcommand_are_refused_not_dropped() {
    for (args, flag, sub) in [
        (
            vec!["--model", "exact", "bench", "--steps", "2"],
            "--model",
            "bench",
        ),
        (vec!["--count", "10", "tradeoff"], "--count", "tradeoff"),
        (
            vec!["--fps", "10", "bench", "--steps", "1"],
            "--fps",
            "bench",
        ),
        (
            vec!["--color", "16", "completions", "bash"],
            "--color",
            "completions",
        ),
    ] {
        let out = ballpit().args(&args).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        // Flags the subcommand takes move after it; the app's own are dropped.
        let want = if ["--fps", "--color"].contains(&flag) {
            format!("{flag} is the terminal app's and does nothing for `{sub}`: drop it")
        } else {
            format!("{flag} must come after `{sub}`")
        };
        assert!(err.contains(&want), "{args:?}: got `{err}`");
        assert!(out.stdout.is_empty(), "{args:?}");
    }
    // After the subcommand the same flag is honoured.
    let v = json::bench(&["--model", "exact", "--steps", "2", "--count", "20"]);
    assert_eq!(v["model"], "exact");
    assert_eq!(v["n"], 20);
}

#[test]
fn clap_usage_errors_exit_2_and_help_exits_0() {
    for args in [
        vec!["--bogus"],
        vec!["bench", "--steps"],
        vec!["bench", "--steps", "1", "extra"],
        vec!["--fps", "0"],
        vec!["--fps", "2000"],
        vec!["--fps", "1e-30"],
        vec!["--dt", "1/x"],
        vec!["--color", "mauve"],
        vec!["completions", "tcsh"],
        vec!["nonsense"],
    ] {
        let out = ballpit().args(&args).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.starts_with("error: "), "{args:?}: {err}");
        assert!(out.stdout.is_empty(), "{args:?}");
    }
    let out = ballpit().args(["--fps", "0"]).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("must be above 0 and at most 1000"), "{err}");
    for args in [vec!["--help"], vec!["bench", "--help"], vec!["--version"]] {
        let out = ballpit().args(&args).output().unwrap();
        assert_eq!(out.status.code(), Some(0), "{args:?}");
        assert!(!out.stdout.is_empty(), "{args:?}");
    }
}

#[test]
fn dt_may_be_a_fraction() {
    let v = json::bench(&["--dt", "1/120", "--steps", "2", "--count", "20"]);
    assert_eq!(v["dt"].as_f64(), Some(1.0 / 120.0));
}

#[test]
fn help_lists_the_allowed_values_and_ranges() {
    let help = |args: &[&str]| {
        let out = ballpit().args(args).output().unwrap();
        assert!(out.status.success(), "{args:?}");
        String::from_utf8(out.stdout).unwrap()
    };
    let top = help(&["--help"]);
    for want in [
        "discrete",
        "swept",
        "exact",
        "off",
        "worker",
        "pool",
        "split",
        "256",
        "true",
        "0 < F <= 1000",
        "1 to 256",
        "0 to 10000000",
        "[default: 1/60]",
    ] {
        assert!(top.contains(want), "ballpit --help lacks `{want}`");
    }
    for p in ballpit::scene::presets::PRESETS {
        assert!(top.contains(p.name) && top.contains(p.about), "{}", p.name);
    }
    let bench = help(&["bench", "--help"]);
    for (field, what) in ballpit::cli::BENCH_FIELDS {
        assert!(bench.contains(field) && bench.contains(what), "{field}");
    }
    let tradeoff = help(&["tradeoff", "--help"]);
    for want in ["1/1920", "tradeoff.csv", "tradeoff.svg", "pos_err_rms"] {
        assert!(tradeoff.contains(want), "tradeoff --help lacks `{want}`");
    }
}

#[test]
fn bench_help_names_exactly_the_fields_the_json_has() {
    // Keep the printed order: a JSON object's keys in the line as written.
    let line = json::bench_line(&["--steps", "2", "--count", "20"]);
    let v: serde_json::Value = serde_json::from_str(&line).unwrap();
    // Where each top-level key is written: its first place at depth 1 (a
    // nested object may use the same name).
    let depth: Vec<i32> = line
        .bytes()
        .scan(0, |d, b| {
            *d += i32::from(b == b'{') - i32::from(b == b'}');
            Some(*d)
        })
        .collect();
    let at = |k: &str| {
        let pat = format!("\"{k}\":");
        line.match_indices(&pat)
            .find(|(i, _)| depth[*i] == 1)
            .unwrap()
            .0
    };
    let mut keys: Vec<(usize, &str)> = v
        .as_object()
        .unwrap()
        .keys()
        .map(|k| (at(k), k.as_str()))
        .collect();
    keys.sort_unstable();
    let printed: Vec<&str> = keys.into_iter().map(|(_, k)| k).collect();
    let documented: Vec<&str> = ballpit::cli::BENCH_FIELDS.iter().map(|f| f.0).collect();
    assert_eq!(printed, documented, "bench --help and the JSON disagree");
}

#[test]
fn completions_and_man_page_come_from_the_cli() {
    // elvish and powershell complete flags but not their values.
    for (shell, values) in [
        ("bash", true),
        ("zsh", true),
        ("fish", true),
        ("elvish", false),
        ("powershell", false),
    ] {
        let out = ballpit().args(["completions", shell]).output().unwrap();
        assert!(out.status.success(), "{shell}");
        let script = String::from_utf8(out.stdout).unwrap();
        let mut wants = vec!["ballpit", "threading", "tradeoff"];
        if values {
            wants.push("exact");
        }
        for want in wants {
            assert!(script.contains(want), "{shell}: no `{want}`");
        }
    }
    let out = ballpit().arg("man").output().unwrap();
    assert!(out.status.success());
    let page = String::from_utf8(out.stdout).unwrap();
    assert!(
        page.starts_with(".ie") && page.contains(".TH ballpit 1"),
        "{page}"
    );
    for want in ["\\-\\-model", "bench", "tradeoff", "completions"] {
        assert!(page.contains(want), "man page lacks `{want}`");
    }
}

#[test]
fn output_that_cannot_be_written_is_reported_not_a_panic() {
    let bin = assert_cmd::cargo::cargo_bin("ballpit");
    let full = std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .unwrap();
    let out = std::process::Command::new(&bin)
        .args(["bench", "--steps", "2", "--count", "20"])
        .stdout(full)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("cannot write to stdout"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    // `tradeoff` prints its table the same way.
    let full = std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .unwrap();
    let out = std::process::Command::new(&bin)
        .args(["tradeoff", "--count", "30"])
        .stdout(full)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("cannot write to stdout") && !err.contains("panicked"),
        "{err}"
    );
    // A reader that went away: the pipe is closed before anything is written.
    let mut child = std::process::Command::new(&bin)
        .args(["bench", "--steps", "30", "--count", "2000"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("cannot write to stdout"), "{err}");
}

#[test]
fn without_a_terminal_nothing_is_built_first() {
    // This scene would take minutes and gigabytes to place; the app must say
    // it needs a terminal before building it.
    let out = ballpit()
        .args(["--scene", "dense", "--count", "10", "--radius", "0.0001"])
        .write_stdin("")
        .timeout(std::time::Duration::from_secs(10))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("needs a terminal"), "{err}");
}
