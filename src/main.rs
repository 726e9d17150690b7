#![forbid(unsafe_code)]
use ballpit::cli::{Cli, Command};
use ballpit::error::BadInput;
use ballpit::{bench, scene};
use clap::CommandFactory;
use std::io::{IsTerminal, Write};
use std::process::ExitCode;

fn main() -> ExitCode {
    // clap prints its own message and exits with 2 on a usage error (0 for --help).
    let cli = Cli::try_parse_checked(std::env::args_os()).unwrap_or_else(|e| e.exit());
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

/// Write `bytes` to stdout; a full disk or a closed pipe is reported, not a panic.
fn emit(bytes: &[u8]) -> Result<(), BadInput> {
    let mut out = std::io::stdout().lock();
    out.write_all(bytes)
        .and_then(|()| out.flush())
        .map_err(|e| BadInput(format!("cannot write to stdout: {e}")))
}

fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Some(Command::Bench(args)) => {
            let mut settings = args.run.settings()?;
            settings.tick = args
                .run
                .tick
                .unwrap_or_else(|| args.steps.div_ceil(100).clamp(1, u64::from(u32::MAX)) as u32);
            let world = scene::build_world_for(&args.scene.spec(), Some(settings.model))?;
            fits(world.spheres.len(), Some(settings.model))?;
            let dump = args
                .dump
                .as_deref()
                .map(scene::csv_io::create)
                .transpose()?;
            let (report, world) = bench::run(world, &settings, args.steps)?;
            if let Some(file) = dump {
                file.write(&world)?;
                if world.max_overlap_rel() > 0.0 {
                    // Not an error: discrete makes overlaps. Say how it reads back.
                    let _ = writeln!(
                        std::io::stderr(),
                        "ballpit: note: the dump holds overlapping spheres; it loads back with --model discrete"
                    );
                }
            }
            let line = serde_json::to_string(&report)? + "\n";
            Ok(emit(line.as_bytes())?)
        }
        Some(Command::Tradeoff(args)) => {
            let world = scene::build_world(&args.scene.spec())?;
            let table = ballpit::tradeoff::run(world, args.out.as_deref())?;
            Ok(emit(table.as_bytes())?)
        }
        Some(Command::Completions { shell }) => {
            let mut script = Vec::new();
            clap_complete::generate(shell, &mut Cli::command(), "ballpit", &mut script);
            Ok(emit(&script)?)
        }
        Some(Command::Man) => {
            let mut page = Vec::new();
            clap_mangen::Man::new(Cli::command()).render(&mut page)?;
            Ok(emit(&page)?)
        }
        None => {
            // Flags, then the terminal, then the scene: nothing is built for
            // a screen that cannot open.
            let settings = cli.run.settings()?;
            let opts = cli.options();
            if !(std::io::stdin().is_terminal() && std::io::stdout().is_terminal()) {
                return Err(BadInput(
                    "ballpit's screen needs a terminal, but stdin or stdout is not one; \
                     for a headless run use `ballpit bench`"
                        .into(),
                )
                .into());
            }
            let spec = cli.scene.spec();
            let world = scene::build_world_for(&spec, Some(settings.model))?;
            // The app can switch to any model: plan for the hungriest.
            fits(world.spheres.len(), None)?;
            // A preset is made again for Reset rather than kept; a file's
            // spheres are kept (the file may change meanwhile).
            let from_file = spec.scene.as_deref().is_some_and(|s| {
                std::path::Path::new(s).extension().is_some_and(|e| {
                    e.eq_ignore_ascii_case("csv") || e.eq_ignore_ascii_case("toml")
                })
            });
            let rebuild = (!from_file).then(|| {
                let model = settings.model;
                Box::new(move || Ok(scene::build_world_for(&spec, Some(model))?))
                    as ballpit::engine::Rebuild
            });
            ballpit::tui::run_with_start(world, settings, opts, rebuild)
        }
    }
}

/// Refuse a world the machine has no memory for, before the model builds
/// its structures.
fn fits(count: usize, model: Option<ballpit::physics::ModelKind>) -> Result<(), BadInput> {
    use ballpit::memory;
    memory::check(count, model, memory::available()).map_err(BadInput)
}
