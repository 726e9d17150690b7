use ballpit::cli::{Cli, Command};
use ballpit::error::BadInput;
use ballpit::{bench, scene};
use clap::CommandFactory;
use std::io::Write;
use std::process::ExitCode;

fn main() -> ExitCode {
    // clap prints its own message and exits with 2 on a usage error (0 for --help).
    let cli = Cli::try_parse_checked(std::env::args_os()).unwrap_or_else(|e| e.exit());
    ballpit::error::exit_code(run(cli))
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
            settings.tick = args.run.bench_tick(args.steps)?;
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
            let table = ballpit::tradeoff::run(&world, args.out.as_deref())?;
            Ok(emit(table.as_bytes())?)
        }
        Some(Command::Scaling(args)) => {
            ballpit::cli::check_dt(args.dt)?;
            let plan = args.plan();
            let world = scene::build_world_for(&args.spec(), Some(plan.model))?;
            fits(world.spheres.len(), Some(plan.model))?;
            let table = ballpit::scaling::run(&world, &plan, args.out.as_deref())?;
            Ok(emit(table.as_bytes())?)
        }
        Some(Command::Completions { shell }) => {
            let mut script = Vec::new();
            clap_complete::generate(shell, &mut Cli::command(), "ballpit", &mut script);
            Ok(emit(&script)?)
        }
        Some(Command::Man) => Ok(emit(&Cli::man_page()?)?),
        None => cli.run_screen(None),
    }
}

/// Refuse a world the machine has no memory for, before the model builds
/// its structures.
fn fits(count: usize, model: Option<ballpit::physics::ModelKind>) -> Result<(), BadInput> {
    use ballpit::memory;
    memory::check(count, model, memory::available()).map_err(BadInput)
}
