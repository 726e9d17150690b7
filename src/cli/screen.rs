//! The terminal app as the command line opens it: shared by `main` and the
//! examples that must start it the same way (`examples/panic_probe.rs`).
use super::Cli;
use crate::engine::Rebuild;
use crate::error::BadInput;
use crate::tui::{AfterFirstFrame, RunExtras};
use crate::{memory, scene, tui};
use std::io::IsTerminal;

impl Cli {
    /// Open the screen with these flags and run until the user quits.
    /// Flags, then the terminal, then the scene: nothing is built for a
    /// screen that cannot open.
    pub fn run_screen(&self, after_first_frame: Option<AfterFirstFrame>) -> anyhow::Result<()> {
        let settings = self.run.settings()?;
        let opts = self.options();
        if !(std::io::stdin().is_terminal() && std::io::stdout().is_terminal()) {
            return Err(BadInput(
                "the screen needs a terminal, but stdin or stdout is not one; \
                 for a headless run use `ballpit bench --steps 600`"
                    .into(),
            )
            .into());
        }
        let spec = self.scene.spec();
        let world = scene::build_world_for(&spec, Some(settings.model))?;
        // The app can switch to any model: plan for the hungriest.
        memory::check(world.spheres.len(), None, memory::available()).map_err(BadInput)?;
        // A preset is made again for Reset rather than kept; a file's
        // spheres are kept (the file may change meanwhile).
        let from_file = spec.scene.as_deref().is_some_and(|s| {
            std::path::Path::new(s)
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("csv") || e.eq_ignore_ascii_case("toml"))
        });
        let rebuild = (!from_file).then(|| {
            let model = settings.model;
            Box::new(move || Ok(scene::build_world_for(&spec, Some(model))?)) as Rebuild
        });
        let extras = RunExtras {
            rebuild,
            after_first_frame,
        };
        tui::run_with(world, settings, opts, extras)
    }
}
