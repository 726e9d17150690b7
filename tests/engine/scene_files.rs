//! Issue 27, item 4: scene files are read with a bound decided before
//! reading. Devices that never end, FIFOs that never close and a 2 GB
//! sparse file, as CSV and as TOML, end in one message and exit 2, in
//! bounded time and memory. The peak resident size is sampled from
//! `/proc/PID/status` while the process runs: an unbounded read (8 GB in
//! 20 s before) shows there long before the deadline.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use crate::common::cli::scratch;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::thread;
use std::time::{Duration, Instant};

const BIN: &str = env!("CARGO_BIN_EXE_ballpit");

/// The issue asks for 2 s; a loaded 2-core runner gets 10 (measured: a few
/// ms, and the 1 s idle limit for a FIFO).
const DEADLINE: Duration = Duration::from_secs(10);
/// Peak resident size allowed, KB.
const MAX_RSS_KB: u64 = 200 * 1024;

fn dir(test: &str) -> PathBuf {
    let d = scratch(test);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The child's peak resident size, once it runs ballpit: between fork and
/// exec it is a copy of the test process, whose high-water mark (the other
/// tests' worlds) it carries until the exec.
fn vm_hwm_kb(pid: u32) -> Option<u64> {
    let comm = std::fs::read_to_string(format!("/proc/{pid}/comm")).ok()?;
    if comm.trim_end() != "ballpit" {
        return None;
    }
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// Run `ballpit bench --steps 1 --scene path`: its exit code, stderr and
/// the largest peak resident size seen.
fn bench(path: &Path) -> (Option<i32>, String, u64) {
    let mut child = Command::new(BIN)
        .args(["bench", "--steps", "1", "--scene"])
        .arg(path)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let pid = child.id();
    let start = Instant::now();
    let mut peak = 0;
    let status = loop {
        peak = peak.max(vm_hwm_kb(pid).unwrap_or(0));
        if let Some(st) = child.try_wait().unwrap() {
            break st;
        }
        if start.elapsed() > DEADLINE || peak > MAX_RSS_KB {
            let _ = child.kill();
            let _ = child.wait();
            panic!(
                "{}: still running after {:?} with {peak} KB resident",
                path.display(),
                start.elapsed()
            );
        }
        thread::sleep(Duration::from_millis(5));
    };
    let mut err = String::new();
    std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut err).unwrap();
    (status.code(), err, peak)
}

fn refused(path: &Path, what: &str) {
    let (code, err, peak) = bench(path);
    assert_eq!(code, Some(2), "{what}: {err}");
    assert_eq!(err.lines().count(), 1, "{what}: one message: {err}");
    assert!(err.starts_with("ballpit: "), "{what}: {err}");
    assert!(peak < MAX_RSS_KB, "{what}: {peak} KB resident");
}

#[test]
fn endless_devices_and_a_sparse_file_are_refused_at_once() {
    let d = dir("endless");
    for ext in ["csv", "toml"] {
        for dev in ["zero", "urandom"] {
            let link = d.join(format!("{dev}.{ext}"));
            std::os::unix::fs::symlink(format!("/dev/{dev}"), &link).unwrap();
            refused(&link, &format!("/dev/{dev} as {ext}"));
        }
        let sparse = d.join(format!("sparse.{ext}"));
        let f = std::fs::File::create(&sparse).unwrap();
        f.set_len(2 << 30).unwrap();
        drop(f);
        refused(&sparse, &format!("a 2 GB sparse file as {ext}"));
    }
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn a_fifo_that_never_closes_is_refused() {
    let d = dir("fifo_open");
    for ext in ["csv", "toml"] {
        let fifo = d.join(format!("fifo.{ext}"));
        mkfifo(&fifo);
        // A writer that holds the FIFO open and sends a line, then nothing.
        let mut writer = sh_writing(
            &fifo,
            "exec 3>\"$1\"; echo x,y,z,vx,vy,vz,radius,mass >&3; sleep 30",
        )
        .spawn()
        .unwrap();
        refused(&fifo, &format!("a FIFO that never closes, as {ext}"));
        let _ = writer.kill();
        let _ = writer.wait();
    }
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn a_fifo_that_ends_is_read() {
    let d = dir("fifo_ends");
    let fifo = d.join("ends.csv");
    mkfifo(&fifo);
    let mut writer = sh_writing(
        &fifo,
        "printf 'x,y,z,vx,vy,vz,radius,mass\\n0.5,0.5,0.5,0,0,0,0.1,1\\n' > \"$1\"",
    )
    .spawn()
    .unwrap();
    let (code, err, _) = bench(&fifo);
    assert_eq!(code, Some(0), "{err}");
    let _ = writer.wait();
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn an_endless_stream_of_valid_rows_stops_at_the_largest_scene() {
    let d = dir("rows");
    let fifo = d.join("rows.csv");
    mkfifo(&fifo);
    let mut writer = sh_writing(&fifo, "exec yes 0,0,0,0,0,0,0,0 > \"$1\"")
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let (code, err, peak) = bench(&fifo);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("lines a CSV scene may have"), "{err}");
    // 10 M short rows are what the largest scene may need (about 160 MB).
    assert!(peak < MAX_RSS_KB, "{peak} KB");
    let _ = writer.kill();
    let _ = writer.wait();
    let _ = std::fs::remove_dir_all(&d);
}

/// `bench --scene -` with `stdin`: its exit code and stderr.
fn bench_stdin(stdin: Stdio) -> (Option<i32>, String) {
    let out = Command::new(BIN)
        .args(["bench", "--steps", "1", "--scene", "-"])
        .stdin(stdin)
        .output()
        .unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn a_scene_on_stdin_is_read_within_the_same_bound() {
    let d = dir("stdin");
    let csv = d.join("one.csv");
    std::fs::write(
        &csv,
        "x,y,z,vx,vy,vz,radius,mass\n0.5,0.5,0.5,0,0,0,0.1,1\n",
    )
    .unwrap();
    let toml = d.join("one.toml");
    std::fs::write(&toml, "preset = \"billiards\"\n").unwrap();
    for f in [&csv, &toml] {
        let (code, err) = bench_stdin(std::fs::File::open(f).unwrap().into());
        assert_eq!(code, Some(0), "{}: {err}", f.display());
    }
    let (code, err) = bench_stdin(std::fs::File::open("/dev/zero").unwrap().into());
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("is not text"), "{err}");
    let _ = std::fs::remove_dir_all(&d);
}

/// A named pipe at `path`.
fn mkfifo(path: &std::path::Path) {
    let made = Command::new("mkfifo").arg(path).status().unwrap();
    assert!(made.success(), "mkfifo {}", path.display());
}

/// `sh -c script` with `fifo` as `$1`: the FIFO's writer, to spawn.
fn sh_writing(fifo: &Path, script: &str) -> Command {
    let mut sh = Command::new("sh");
    sh.arg("-c").arg(script).arg("sh").arg(fifo);
    sh
}
