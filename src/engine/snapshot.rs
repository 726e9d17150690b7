//! What the screen reads of a finished frame. Two of them exist: the front
//! one the renderer reads while the physics fills the back one.
use super::{Settings, Threading, physics_threads};
use crate::physics::auto::Choice;
use crate::physics::broad::Grid;
use crate::physics::discrete::pair_budget;
use crate::physics::exec::{Busy, for_each_block_of, for_each_chunk, work_ns};
use crate::physics::overlap::{self, Overlap};
use crate::physics::world::escapes;
use crate::physics::{Counters, Exec, ModelKind, World};
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};

/// Spheres per parallel block when copying them out.
const VIEW_BLOCK: usize = 8192;
/// Predicted nanoseconds a sphere's view and counters cost (docs/threading.md).
const NS_PER_VIEW: usize = 4;

/// What the screen needs of one sphere. Single precision: a screen is a few
/// thousand pixels across, f32 resolves a millionth of the box (20 bytes a
/// sphere instead of 40, and two snapshots hold them).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SphereView {
    pub pos: [f32; 3],
    pub radius: f32,
    pub speed: f32,
}

/// One finished frame, read by the renderer while the next one computes.
#[derive(Clone, Debug, PartialEq)]
pub struct Snapshot {
    pub frame: u64,
    pub time: f64,
    pub size: f64,
    /// Empty in a headless engine (`Engine::headless`): read `count`.
    pub spheres: Vec<SphereView>,
    /// Spheres in the world.
    pub count: usize,
    /// The largest radius, exactly (`None` for an empty box).
    pub max_radius: Option<f64>,
    /// The smallest radius (`None` for an empty box): a mixed scene's range.
    pub min_radius: Option<f64>,
    pub energy: f64,
    /// Energy right after the last reset (or scene start), for the drift.
    pub energy_reset: f64,
    pub max_overlap_rel: f64,
    /// The overlap readout stopped at its pair budget (a heap of
    /// overlapping spheres): `max_overlap_rel` is the deepest among the
    /// pairs it looked at, a lower bound.
    pub overlap_partial: bool,
    pub escaped: usize,
    pub counters: Counters,
    /// Parts the model cut its last step into (1: whole).
    pub parts: u32,
    /// What `auto` chose to run and why (`None` for the other models).
    pub choice: Option<Choice>,
    /// `auto` runs another model than in the frame before: `auto: swept →
    /// exact (reason)`, a notice for the screen (only in that frame).
    pub switch_notice: Option<String>,
    /// Wall-clock seconds the physics of this frame took: its steps and the
    /// detection behind `max_overlap_rel`.
    pub physics_seconds: f64,
    /// Steps run in this frame (none in a held one, `Engine::set_hold`).
    pub steps: u64,
    /// The settings this frame ran with (what really ran; a held frame
    /// keeps the tick it resumes with).
    pub settings: Settings,
    /// The threads this frame's physics ran on, driver first, as
    /// [`physics_threads`] names them for `settings` and the model that ran.
    pub physics_threads: Vec<String>,
    /// The model that ran keeps to one lane of those threads (`exact`'s
    /// event loop): in `pool` the frame is on one pool thread (rayon picks
    /// which), so the pool's size does nothing to it.
    pub one_lane: bool,
    /// What `physics_threads` was made for: remade only when it changes,
    /// not every frame (a pool names up to 256 threads).
    threads_for: Option<(Threading, usize, ModelKind)>,
    /// A limit the last count or radius command hit, e.g. "radius limit:
    /// spheres touch at r = 0.0310"; kept until the next such command.
    pub notice: Option<String>,
    /// How many pool lanes the widest section of this frame kept busy, of
    /// how many threads, and what held it there (`None` off the pool).
    pub pool_busy: Option<Busy>,
    /// The running scene's parallelism, work over span on unlimited lanes,
    /// measured every few seconds on one step under `pool` (docs/threading.md,
    /// "Parallelism on the threads panel"); `None` in the other modes, for
    /// a model on one lane, in a headless engine, and until first measured.
    pub parallelism: Option<f64>,
}

impl Snapshot {
    pub(crate) fn new(
        world: &World,
        settings: Settings,
        energy_reset: f64,
        views: bool,
    ) -> Snapshot {
        let mut s = Snapshot {
            frame: 0,
            time: 0.0,
            size: world.size,
            spheres: Vec::new(),
            count: 0,
            max_radius: None,
            min_radius: None,
            energy: 0.0,
            energy_reset,
            max_overlap_rel: 0.0,
            overlap_partial: false,
            escaped: 0,
            counters: Counters::default(),
            parts: 1,
            choice: None,
            switch_notice: None,
            physics_seconds: 0.0,
            steps: 0,
            settings,
            physics_threads: Vec::new(),
            one_lane: false,
            threads_for: None,
            notice: None,
            pool_busy: None,
            parallelism: None,
        };
        s.report_threads();
        let serial = crate::physics::Serial;
        let overlap = OverlapScratch::default().measure(world, &serial);
        s.fill_world(world, 1, overlap, &serial, views);
        s
    }

    /// Copy what the screen needs out of `world` (the sphere views only if
    /// `views`), reusing the buffers; the parts and the overlap come from
    /// the frame's timed work.
    pub(crate) fn fill_world(
        &mut self,
        world: &World,
        parts: u32,
        overlap: Overlap,
        exec: &dyn Exec,
        views: bool,
    ) {
        // Read before the copy below, whose sections count toward the next.
        self.pool_busy = exec.take_busy();
        self.time = world.time;
        self.size = world.size;
        // The copy and the scans run on the frame's executor: at 100 000
        // spheres they would otherwise be a serial tail on every frame of a
        // parallel mode.
        let sp = &world.spheres;
        let escaped = AtomicUsize::new(0);
        // Radii are positive, so their bits order like the numbers.
        let widest = AtomicU64::new(0);
        let narrowest = AtomicU64::new(u64::MAX);
        let tol = 1e-9 * world.size;
        let scan = |b: usize, out: Option<&mut [SphereView]>| {
            let block = &sp[b * VIEW_BLOCK..sp.len().min((b + 1) * VIEW_BLOCK)];
            let (mut n, mut r, mut least) = (0, 0.0f64, f64::INFINITY);
            for s in block {
                n += usize::from(escapes(s, world.size, tol));
                r = r.max(s.radius);
                least = least.min(s.radius);
            }
            if let Some(out) = out {
                for (v, s) in out.iter_mut().zip(block) {
                    *v = SphereView {
                        pos: s.pos.as_vec3().to_array(),
                        radius: s.radius as f32,
                        speed: s.vel.length() as f32,
                    };
                }
            }
            escaped.fetch_add(n, Ordering::Relaxed);
            widest.fetch_max(r.to_bits(), Ordering::Relaxed);
            narrowest.fetch_min(least.to_bits(), Ordering::Relaxed);
        };
        if views {
            self.spheres.resize(sp.len(), SphereView::default());
            for_each_chunk(exec, &mut self.spheres, VIEW_BLOCK, NS_PER_VIEW, &|b, c| {
                scan(b, Some(c));
            });
        } else {
            self.spheres = Vec::new();
            let work = work_ns(sp.len(), NS_PER_VIEW);
            for_each_block_of(exec, sp.len().div_ceil(VIEW_BLOCK), work, &|b| {
                scan(b, None);
            });
        }
        self.count = sp.len();
        self.max_radius = (!sp.is_empty()).then(|| f64::from_bits(widest.into_inner()));
        self.min_radius = (!sp.is_empty()).then(|| f64::from_bits(narrowest.into_inner()));
        self.energy = world.kinetic_energy();
        self.parts = parts;
        self.max_overlap_rel = overlap.deepest_rel;
        self.overlap_partial = overlap.partial;
        self.escaped = escaped.into_inner();
        self.counters = world.counters;
    }

    /// The model that ran: for `auto`, the one it chose.
    pub fn model_ran(&self) -> ModelKind {
        self.settings
            .model
            .running(self.choice.as_ref().map(|c| c.model))
    }

    /// Say where the physics ran, from `settings` and `choice` (set
    /// before): the engine's one answer to it, which the screen shows.
    pub(crate) fn report_threads(&mut self) {
        let s = self.settings;
        let ran = self.model_ran();
        let key = Some((s.threading, s.threads, ran));
        if self.threads_for == key {
            return;
        }
        self.threads_for = key;
        self.one_lane = ran.runs_on_one_lane();
        self.physics_threads = physics_threads(s.threading, s.threads, ran);
    }

    /// `|E - E_reset| / E_reset` (0 for a world at rest).
    pub fn energy_drift(&self) -> f64 {
        if self.energy_reset > 0.0 {
            (self.energy - self.energy_reset).abs() / self.energy_reset
        } else {
            0.0
        }
    }
}

/// A grid kept between frames for the overlap check, searched on the
/// frame's executor (`World::max_overlap_rel` would rebuild it serially).
#[derive(Default)]
pub(crate) struct OverlapScratch {
    grid: Grid,
}

impl OverlapScratch {
    /// The deepest overlap, looking at no more overlapping pairs than a
    /// `discrete` step may answer ([`pair_budget`]).
    pub(crate) fn measure(&mut self, world: &World, exec: &dyn Exec) -> Overlap {
        self.measure_within(world, exec, pair_budget(world.spheres.len()))
    }

    /// Same value as `World::max_overlap_rel` while at most `limit` pairs
    /// overlap; past `limit` the readout stops, so a heap of overlapping
    /// spheres (a file scene) costs a frame no more than a step may.
    pub(crate) fn measure_within(
        &mut self,
        world: &World,
        exec: &dyn Exec,
        limit: usize,
    ) -> Overlap {
        overlap::deepest(&mut self.grid, world, exec, Some(limit))
    }
}
