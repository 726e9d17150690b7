#![forbid(unsafe_code)]
use ballpit::cli::{Cli, Command};
use ballpit::error::BadInput;
use ballpit::{bench, scene};
use clap::Parser;
use std::io::Write;
use std::process::ExitCode;

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            if let Some(bad) = e.downcast_ref::<BadInput>() {
                // stderr may be gone with the terminal: never panic for it.
                let _ = writeln!(std::io::stderr(), "ballpit: {bad}");
                ExitCode::from(2)
            } else {
                let _ = writeln!(std::io::stderr(), "ballpit: {e:#}");
                ExitCode::FAILURE
            }
        }
    }
}

fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Some(Command::Bench(args)) => {
            let mut settings = args.run.settings()?;
            settings.tick = args
                .run
                .tick
                .unwrap_or_else(|| args.steps.div_ceil(100).clamp(1, u64::from(u32::MAX)) as u32);
            let world = scene::build_world(&args.scene.spec())?;
            fits(world.spheres.len(), Some(settings.model))?;
            let dump = args
                .dump
                .as_deref()
                .map(scene::csv_io::create)
                .transpose()?;
            let (report, world) = bench::run(world, &settings, args.steps)?;
            if let Some(file) = dump {
                file.write(&world)?;
            }
            println!("{}", serde_json::to_string(&report)?);
            Ok(())
        }
        Some(Command::Tradeoff(args)) => {
            let world = scene::build_world(&args.scene.spec())?;
            ballpit::tradeoff::run(world, args.out.as_deref())
        }
        None => {
            let settings = cli.run.settings()?;
            let world = scene::build_world(&cli.scene.spec())?;
            // The app can switch to any model: plan for the hungriest.
            fits(world.spheres.len(), None)?;
            let color = match cli.color.as_deref() {
                None => ballpit::tui::ColorChoice::Auto,
                Some(c) => c.parse().map_err(BadInput)?,
            };
            let opts = ballpit::tui::Options {
                fps: cli.fps,
                color,
            };
            ballpit::tui::run(world, settings, opts)
        }
    }
}

/// Refuse a world the machine has no memory for, before the model builds
/// its structures.
fn fits(count: usize, model: Option<ballpit::physics::ModelKind>) -> Result<(), BadInput> {
    use ballpit::memory;
    memory::check(count, model, memory::available()).map_err(BadInput)
}
