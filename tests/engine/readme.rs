//! The README against the repository and the real command line: every
//! relative link and every repository path it names exists, every command
//! in its `sh` blocks parses with the real CLI and its flags and scene
//! validate, runs as written from a temporary directory with `ballpit` on
//! the PATH as its install step puts it there, and changes no tracked file;
//! and its TOML example is a scene ballpit reads.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use crate::common::cli::scratch;
use ballpit::cli::{Cli, Command, SceneArgs};
use ballpit::scene::{self, presets};
use std::path::{Path, PathBuf};

const README: &str = include_str!("../../README.md");

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The bodies of the fenced blocks whose info string is `lang`.
fn blocks(text: &str, lang: &str) -> Vec<String> {
    enum State {
        Outside,
        Keep(String),
        Skip,
    }
    let mut out = Vec::new();
    let mut state = State::Outside;
    for line in text.lines() {
        if let Some(info) = line.strip_prefix("```") {
            state = match state {
                State::Outside if info.trim() == lang => State::Keep(String::new()),
                State::Outside => State::Skip,
                State::Keep(body) => {
                    out.push(body);
                    State::Outside
                }
                State::Skip => State::Outside,
            };
        } else if let State::Keep(body) = &mut state {
            body.push_str(line);
            body.push('\n');
        }
    }
    out
}

#[test]
fn blocks_finds_the_fenced_bodies() {
    let text = "a\n```sh\nx 1\n```\n```text\ny\n```\n```sh\nz\n```\n";
    assert_eq!(blocks(text, "sh"), vec!["x 1\n", "z\n"]);
    assert_eq!(blocks(text, "text"), vec!["y\n"]);
}

#[test]
fn every_link_and_path_the_readme_names_exists() {
    let mut checked = 0;
    // Markdown links: ](target)
    for piece in README.split("](").skip(1) {
        let target = piece.split(')').next().unwrap_or("");
        let target = target.split('#').next().unwrap_or("");
        if target.is_empty() || target.contains("://") {
            continue;
        }
        assert!(
            root().join(target).exists(),
            "README links {target}, which is not there"
        );
        checked += 1;
    }
    // Repository paths in backticks: `docs/...`, `scripts/...`, ...
    let dirs = [
        "docs/",
        "src/",
        "tests/",
        "scripts/",
        "examples/",
        "benches/",
        "peers/",
    ];
    for (i, piece) in README.split('`').enumerate() {
        if i % 2 == 1 && dirs.iter().any(|d| piece.starts_with(d)) {
            assert!(
                root().join(piece).exists(),
                "README names {piece}, which is not there"
            );
            checked += 1;
        }
    }
    assert!(
        checked >= 8,
        "only {checked} links found: is the parser still right?"
    );
}

/// GitHub's anchor for a heading: lower case, punctuation dropped, spaces
/// to hyphens.
fn slug(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || *c == ' ' || *c == '-' || *c == '_')
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

#[test]
fn slug_is_githubs() {
    assert_eq!(
        slug("Terminal: `cargo bench --bench frame`"),
        "terminal-cargo-bench---bench-frame"
    );
    assert_eq!(slug("20× Rapier"), "20-rapier");
    assert_eq!(slug("Parts (`parts.rs`)"), "parts-partsrs");
}

/// The anchors a markdown file offers: its headings' slugs and the ids of
/// its `<a id="..."></a>` marks (which docs/figures.md puts on table rows).
fn anchors(body: &str) -> Vec<String> {
    let headings = body
        .lines()
        .filter_map(|l| l.strip_prefix('#'))
        .map(|h| slug(h.trim_start_matches('#')));
    let ids = body
        .split("<a id=\"")
        .skip(1)
        .filter_map(|p| p.split('"').next())
        .map(str::to_string);
    headings.chain(ids).collect()
}

#[test]
fn anchors_are_headings_and_row_marks() {
    let body = "# Top\n\n## A `b` c\n| <a id=\"row-1\"></a>x | y |\n";
    assert_eq!(anchors(body), ["top", "a-b-c", "row-1"]);
}

/// README.md and every markdown file under docs/, subfolders included.
fn doc_files() -> Vec<PathBuf> {
    let mut files = vec![root().join("README.md")];
    let mut dirs = vec![root().join("docs")];
    while let Some(dir) = dirs.pop() {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                dirs.push(p);
            } else if p.extension().is_some_and(|x| x == "md") {
                files.push(p);
            }
        }
    }
    files
}

#[test]
fn every_link_between_the_docs_lands() {
    let files = doc_files();
    assert!(
        files
            .iter()
            .any(|f| f.ends_with("docs/history/2026-11-22.md")),
        "the walk reaches docs/history/"
    );
    let mut checked = 0;
    for file in &files {
        let text = std::fs::read_to_string(file).unwrap();
        for piece in text.split("](").skip(1) {
            let link = piece.split(')').next().unwrap_or("");
            if link.contains("://") || link.is_empty() {
                continue;
            }
            let (path, anchor) = link.split_once('#').unwrap_or((link, ""));
            let target = if path.is_empty() {
                file.clone()
            } else {
                file.parent().unwrap().join(path)
            };
            assert!(target.exists(), "{}: {link} is not there", file.display());
            if !anchor.is_empty() {
                let body = std::fs::read_to_string(&target).unwrap();
                let found = anchors(&body).iter().any(|a| a == anchor);
                assert!(found, "{}: no anchor #{anchor} in {path}", file.display());
            }
            checked += 1;
        }
    }
    assert!(
        checked >= 20,
        "only {checked} links: is the parser still right?"
    );
}

/// The arguments (program name first) a README line runs ballpit with, or
/// `None` for the one other command it shows (`cargo test`).
fn ballpit_args(line: &str) -> Option<Vec<String>> {
    let words: Vec<String> = line.split_whitespace().map(String::from).collect();
    let w: Vec<&str> = words.iter().map(String::as_str).collect();
    match w.as_slice() {
        ["ballpit", ..] => Some(words),
        ["cargo", "run", "--release"] => Some(vec!["ballpit".into()]),
        ["cargo", "run", "--release", "--", rest @ ..] => Some(
            std::iter::once("ballpit".to_string())
                .chain(rest.iter().map(std::string::ToString::to_string))
                .collect(),
        ),
        ["cargo", "test", "--release"] | ["cargo", "install", "--path", "."] => None,
        _ => panic!("README shows a command this test does not know: `{line}`"),
    }
}

/// Build the scene the flags describe, unless it is a file an earlier
/// command dumps (then that dump must come first).
#[allow(clippy::case_sensitive_file_extension_comparisons)] // as the app reads them
fn check_scene(scene_args: &SceneArgs, dumped: &[PathBuf], line: &str) {
    match scene_args.scene.as_deref() {
        Some(f) if f.ends_with(".csv") || f.ends_with(".toml") => {
            assert!(
                dumped.contains(&PathBuf::from(f)),
                "`{line}` reads {f}, which no command above it writes"
            );
        }
        _ => {
            if let Err(e) = scene::build_world(&scene_args.spec()) {
                panic!("`{line}`: {e}");
            }
        }
    }
}

#[test]
fn every_command_the_readme_shows_parses_and_validates() {
    let mut parsed = 0;
    let mut dumped: Vec<PathBuf> = Vec::new();
    for block in blocks(README, "sh") {
        for line in block.lines() {
            let line = line.split(" #").next().unwrap_or("").trim();
            if line.is_empty() {
                continue;
            }
            let Some(args) = ballpit_args(line) else {
                continue;
            };
            let cli = match Cli::try_parse_checked(&args) {
                Ok(c) => c,
                Err(e) => panic!("`{line}` does not parse:\n{e}"),
            };
            match &cli.command {
                None => {
                    cli.run
                        .settings()
                        .unwrap_or_else(|e| panic!("`{line}`: {e}"));
                    check_scene(&cli.scene, &dumped, line);
                }
                Some(Command::Bench(b)) => {
                    b.run.settings().unwrap_or_else(|e| panic!("`{line}`: {e}"));
                    check_scene(&b.scene, &dumped, line);
                    dumped.extend(b.dump.iter().cloned());
                }
                Some(Command::Tradeoff(t)) => check_scene(&t.scene, &dumped, line),
                Some(Command::Scaling(s)) => {
                    if let Err(e) = scene::build_world(&s.spec()) {
                        panic!("`{line}`: {e}");
                    }
                }
                Some(Command::Completions { .. } | Command::Man) => {}
            }
            parsed += 1;
        }
    }
    assert!(
        parsed >= 5,
        "only {parsed} commands found: is the parser still right?"
    );
}

#[test]
fn the_readme_toml_example_is_a_scene() {
    let examples = blocks(README, "toml");
    assert!(!examples.is_empty(), "the README shows no TOML scene");
    let dir = scratch("readme");
    std::fs::create_dir_all(&dir).unwrap();
    for (i, text) in examples.iter().enumerate() {
        let path = dir.join(format!("scene{i}.toml"));
        std::fs::write(&path, text).unwrap();
        let spec = scene::SceneSpec {
            scene: Some(path.to_string_lossy().into_owned()),
            ..Default::default()
        };
        let world = scene::build_world(&spec).unwrap_or_else(|e| panic!("{text}\n{e}"));
        assert!(!world.spheres.is_empty());
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn every_preset_is_named_in_the_readme() {
    for p in presets::PRESETS {
        assert!(README.contains(&format!("`{}`", p.name)), "{}", p.name);
    }
}

/// `line` run by `sh` in `dir` with `bin` first on the PATH, in a 100x30
/// pty: it must draw the app (its `threading` readout), then quit on `q`
/// with status 0.
fn run_app(line: &str, dir: &Path, bin: &Path) {
    use portable_pty::{CommandBuilder, PtySize, native_pty_system};
    use std::io::{Read, Write};
    use std::sync::{Arc, Mutex};
    let pty = native_pty_system()
        .openpty(PtySize {
            rows: 30,
            cols: 100,
            pixel_width: 0,
            pixel_height: 0,
        })
        .unwrap();
    let mut cmd = CommandBuilder::new("sh");
    cmd.args(["-c", line]);
    cmd.cwd(dir);
    cmd.env("PATH", path_with(bin));
    cmd.env("TERM", "xterm-256color");
    let mut child = pty.slave.spawn_command(cmd).unwrap();
    drop(pty.slave);
    let mut reader = pty.master.try_clone_reader().unwrap();
    let mut writer = pty.master.take_writer().unwrap();
    let screen = Arc::new(Mutex::new(vt100::Parser::new(nz(30), nz(100), 0)));
    let s = screen.clone();
    let read = std::thread::spawn(move || {
        let mut buf = vec![0u8; 65536];
        while let Ok(n) = reader.read(&mut buf) {
            if n == 0 {
                break;
            }
            s.lock().unwrap().process(&buf[..n]);
        }
    });
    let wait = |what: &str, ok: &dyn Fn() -> bool| {
        let end = std::time::Instant::now() + std::time::Duration::from_secs(20);
        while !ok() {
            assert!(
                std::time::Instant::now() < end,
                "`{line}`: no {what}; screen:\n{}",
                screen.lock().unwrap().screen().contents()
            );
            std::thread::sleep(std::time::Duration::from_millis(50));
        }
    };
    wait("app drawn", &|| {
        screen
            .lock()
            .unwrap()
            .screen()
            .contents()
            .contains("threading")
    });
    writer.write_all(b"q").unwrap();
    writer.flush().unwrap();
    let end = std::time::Instant::now() + std::time::Duration::from_secs(20);
    let st = loop {
        if let Some(st) = child.try_wait().unwrap() {
            break st;
        }
        assert!(
            std::time::Instant::now() < end,
            "`{line}`: q did not end it"
        );
        std::thread::sleep(std::time::Duration::from_millis(50));
    };
    assert!(st.success(), "`{line}` ended with {st:?}");
    drop(writer);
    drop(pty.master);
    let _ = read.join();
}

fn path_with(bin: &Path) -> String {
    format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    )
}

/// `git status --porcelain` of the repository: what differs from HEAD.
fn tracked_changes() -> String {
    let out = std::process::Command::new("git")
        .args(["status", "--porcelain", "--untracked-files=no"])
        .current_dir(root())
        .output()
        .expect("git runs: the test checks tracked files with it");
    assert!(out.status.success(), "not a git checkout");
    String::from_utf8(out.stdout).unwrap()
}

#[test]
fn every_readme_command_runs_as_written_and_changes_no_tracked_file() {
    let before = tracked_changes();
    let dir = scratch("readme-run");
    let bin = dir.join("bin");
    let work = dir.join("work");
    std::fs::create_dir_all(&work).unwrap();
    let mut installed = false;
    let mut ran = 0;
    for block in blocks(README, "sh") {
        for line in block.lines() {
            let line = line.split(" #").next().unwrap_or("").trim();
            if line.is_empty() || line == "cargo test --release" {
                continue;
            }
            if line == "cargo run --release" {
                // This very build's binary, run as the app on its default scene.
                let here = dir.join("run");
                std::fs::create_dir_all(&here).unwrap();
                std::fs::copy(env!("CARGO_BIN_EXE_ballpit"), here.join("ballpit")).unwrap();
                run_app("ballpit", &work, &here);
                ran += 1;
                continue;
            }
            if line == "cargo install --path ." {
                // What it leaves: this very build's binary, on the PATH.
                std::fs::create_dir_all(&bin).unwrap();
                std::fs::copy(env!("CARGO_BIN_EXE_ballpit"), bin.join("ballpit")).unwrap();
                installed = true;
                continue;
            }
            assert!(
                line.starts_with("ballpit"),
                "README runs `{line}`, which this test does not know"
            );
            assert!(installed, "`{line}` comes before the install step");
            let app = Cli::try_parse_checked(line.split_whitespace())
                .unwrap_or_else(|e| panic!("`{line}`: {e}"))
                .command
                .is_none();
            if app {
                run_app(line, &work, &bin);
            } else {
                let out = std::process::Command::new("sh")
                    .args(["-c", line])
                    .current_dir(&work)
                    .env("PATH", path_with(&bin))
                    .output()
                    .unwrap();
                let err = String::from_utf8_lossy(&out.stderr);
                assert!(out.status.success(), "`{line}`: {err}");
                assert!(!out.stdout.is_empty(), "`{line}` printed nothing");
                assert!(!err.contains("warning"), "`{line}`: {err}");
            }
            ran += 1;
        }
    }
    assert!(
        ran >= 6,
        "only {ran} commands run: is the parser still right?"
    );
    // What the commands say they write, written where they ran.
    for f in [
        "end.csv",
        "tradeoff-out/tradeoff.csv",
        "tradeoff-out/tradeoff.svg",
        "scaling-out/scaling.csv",
        "scaling-out/scaling.svg",
    ] {
        assert!(
            work.join(f).exists(),
            "{f} not written in the work directory"
        );
    }
    assert_eq!(
        tracked_changes(),
        before,
        "README commands changed tracked files"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

fn nz(n: u16) -> std::num::NonZeroU16 {
    std::num::NonZeroU16::new(n).unwrap()
}
