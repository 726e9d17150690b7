//! The terminal app started as `main` starts it, plus a thread named
//! `probe-panic` that panics once the first frame is out: `tests/app/tui_pty.rs`
//! checks that the terminal is restored, the message printed after it, and
//! the exit code a failure. Kept out of the shipped binary.
//!
//! `cargo run --release --example panic_probe` (in a terminal; same flags
//! as `ballpit`).
use ballpit::cli::Cli;
use std::process::ExitCode;

fn main() -> ExitCode {
    let cli = Cli::try_parse_checked(std::env::args_os()).unwrap_or_else(|e| e.exit());
    let panic_soon = Box::new(|| {
        let spawned = std::thread::Builder::new()
            .name("probe-panic".into())
            .spawn(|| panic!("test panic in a worker thread"));
        // Without the thread there is nothing to probe: say so and stop.
        if let Err(e) = spawned {
            panic!("cannot start the probe thread: {e}");
        }
    });
    ballpit::error::exit_code(cli.run_screen(Some(panic_soon)))
}
