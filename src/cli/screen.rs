//! The terminal app as the command line opens it: shared by `main` and the
//! examples that must start it the same way (`examples/panic_probe.rs`).
use super::Cli;
use crate::error::BadInput;
use crate::tui::AfterFirstFrame;
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
                "ballpit's screen needs a terminal, but stdin or stdout is not one; \
                 for a headless run use `ballpit bench`"
                    .into(),
            )
            .into());
        }
        let world = scene::build_world_for(&self.scene.spec(), Some(settings.model))?;
        // The app can switch to any model: plan for the hungriest.
        memory::check(world.spheres.len(), None, memory::available()).map_err(BadInput)?;
        tui::run_with(world, settings, opts, after_first_frame)
    }
}
