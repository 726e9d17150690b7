//! One frame's worth of work, moved whole to whichever thread runs it: the
//! world, the model, the executor, and the back snapshot to fill.
use super::Settings;
use super::snapshot::{Overlap, OverlapScratch, Snapshot};
use crate::physics::{Exec, Model, World};
use std::sync::Arc;
use std::time::Instant;

/// An executor that can travel with the frame to the physics thread.
pub(crate) type SharedExec = Arc<dyn Exec + Send + Sync>;

pub(crate) struct Frame {
    pub world: World,
    pub model: Box<dyn Model>,
    pub exec: SharedExec,
    pub settings: Settings,
    pub energy_reset: f64,
    pub number: u64,
    pub notice: Option<String>,
    /// The back buffer: filled here, swapped to the front when done.
    pub snap: Snapshot,
    /// Whether the snapshot carries the spheres (a headless run needs none).
    pub views: bool,
    scratch: OverlapScratch,
}

impl Frame {
    pub fn new(
        world: World,
        model: Box<dyn Model>,
        exec: SharedExec,
        settings: Settings,
        views: bool,
    ) -> Frame {
        let energy_reset = world.kinetic_energy();
        let snap = Snapshot::new(&world, settings, energy_reset, views);
        Frame {
            world,
            model,
            exec,
            settings,
            energy_reset,
            number: 0,
            notice: None,
            snap,
            views,
            scratch: OverlapScratch::default(),
        }
    }

    /// Step the world `tick` times and fill the back snapshot, on a thread
    /// of the frame's executor.
    pub fn run(&mut self) {
        let exec = self.exec.clone();
        exec.host(&mut || self.run_here());
    }

    /// The timer covers the steps and the overlap readout's detection:
    /// `swept` makes it as the next step's detection and reuses it, the
    /// others search for overlaps; either way it is work the frame costs
    /// (DESIGN.md: `wall_seconds` covers any detection for the readouts).
    /// Copying the spheres out for the screen is not timed.
    fn run_here(&mut self) {
        let steps = u64::from(self.settings.tick);
        let t0 = Instant::now();
        self.model
            .advance(&mut self.world, self.settings.dt, steps, &*self.exec);
        let overlap = self
            .model
            .max_overlap_rel(&self.world, self.settings.dt, &*self.exec)
            .map_or_else(
                || self.scratch.measure(&self.world, &*self.exec),
                Overlap::complete,
            );
        let physics_seconds = t0.elapsed().as_secs_f64();
        self.number += 1;
        let snap = &mut self.snap;
        snap.fill_world(
            &self.world,
            self.model.last_parts(),
            overlap,
            &*self.exec,
            self.views,
        );
        snap.frame = self.number;
        snap.energy_reset = self.energy_reset;
        snap.physics_seconds = physics_seconds;
        snap.steps = steps;
        snap.settings = self.settings;
        snap.choice = self.model.choice().cloned();
        snap.notice.clone_from(&self.notice);
    }
}
