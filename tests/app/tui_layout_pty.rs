//! The screen's layout in the real binary, in a real pseudo-terminal at
//! 80x24 (the size most terminals open at), its screen parsed with vt100:
//! every thread is on screen in every threading mode, and `c` shows the
//! chart. Waits poll the screen with a deadline; nothing sleeps blind.
use crate::common::pty;

/// The app at `cols`×`rows`.
fn start(args: &[&str], cols: u16, rows: u16) -> pty::App {
    pty::start_with(args, None, (rows, cols), "xterm-256color")
}

/// Grid cells of the thread panel (idle dot or a bar).
fn cells(screen: &str) -> usize {
    let mut n = 0;
    let mut in_grid = false;
    for l in screen.lines() {
        if l.contains("pool x") {
            in_grid = true;
            continue;
        }
        if in_grid {
            if l.contains("total") || l.contains("idle") {
                break;
            }
            // The panel's part of the line: after the canvas.
            let panel = l.rsplit_once('│').map_or(l, |p| p.0);
            let panel = panel.rsplit('│').next().unwrap_or(panel);
            n += panel.chars().filter(|c| "·▁▂▃▄▅▆▇█".contains(*c)).count();
        }
    }
    n
}

#[test]
fn every_thread_and_the_total_at_80x24_in_pool_split_and_64_threads() {
    let names = |s: &str, want: &[&str]| want.iter().all(|n| s.contains(n));
    let base = ["main", "physics", "process", "other procs"];

    let app = start(&["--threading", "pool", "--threads", "2"], 80, 24);
    app.wait_for("pool-0 and pool-1", 10.0, |s| {
        names(s, &base) && names(s, &["pool-0", "pool-1"])
    });
    app.quit();

    let app = start(&["--threading", "split"], 80, 24);
    app.wait_for("split-pair and split-wall", 10.0, |s| {
        names(s, &base) && names(s, &["split-pair", "split-wall"])
    });
    app.quit();

    let app = start(&["--threading", "pool", "--threads", "64"], 80, 24);
    app.wait_for("a cell for each of 64 pool threads", 10.0, |s| {
        names(s, &base) && s.contains("pool x64:") && cells(s) == 64
    });
    // The help overlay fits too: its first and last keys and its border.
    let mut app = app;
    app.send("?");
    app.wait_for("the help overlay", 3.0, |s| {
        s.contains("this help") && s.contains("frame rate") && s.contains("closes this help")
    });
    app.quit();
}

#[test]
fn c_swaps_the_canvas_for_the_chart_and_back() {
    let mut app = start(&["--threading", "worker"], 80, 24);
    app.wait_for("the readouts", 10.0, |s| s.contains("threading"));
    app.send("c");
    app.wait_for("the chart with its legend", 3.0, |s| {
        s.contains("CPU per thread, last 60 s") && s.contains("━ main") && s.contains("━ physics")
    });
    app.send("c");
    app.wait_for("the canvas again", 3.0, |s| !s.contains("CPU per thread"));
    app.quit();
}
