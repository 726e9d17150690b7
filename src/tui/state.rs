//! What the user has asked for, and what each key does to it. Commands for
//! the engine come out of `apply`; nothing here touches a terminal.
use super::input::keys::Action;
use super::look::{Camera, DrawStyle, LIGHT_STEPS};
use crate::engine::{Command, MAX_THREADS, Settings, Snapshot, Threading};
use crate::physics::ModelKind;
use crate::physics::auto::Tolerance;

/// The most steps a frame runs, for `--tick` and the keys alike.
pub const MAX_TICK: u32 = 1_000_000;
/// The most spheres the `N` key doubles to (a scene from the command line
/// may hold more, up to `scene::MAX_COUNT`).
pub const MAX_KEY_COUNT: usize = 1 << 21;
pub const MIN_RADIUS: f64 = 1e-4;
/// A count from which placing the spheres takes long enough to say so.
pub const BIG_EDIT: usize = 100_000;
pub const RADIUS_STEP: f64 = 1.25;
pub const CAMERA_STEP: f64 = std::f64::consts::PI / 18.0;
pub const MAX_PITCH: f64 = 1.5;
pub const FPS_STEPS: [f64; 7] = [5.0, 10.0, 15.0, 20.0, 30.0, 60.0, 120.0];

#[derive(Clone, Debug, PartialEq)]
#[allow(clippy::struct_excessive_bools)] // independent toggles, one a key
pub struct AppState {
    pub threading: Threading,
    /// Where `t` goes back to; `d` cycles it while threading is off.
    pub last_threaded: Threading,
    pub threads: usize,
    pub tick: u32,
    /// Flat out (`--tick max`, key x): each frame runs as many steps as its
    /// time allows; `tick` is kept to go back to.
    pub flat_out: bool,
    /// Counts the changes of scene (count, radius, model, reset), so
    /// figures measured on one scene are not compared with another's.
    pub scene: u64,
    pub paused: bool,
    pub model: ModelKind,
    /// `auto`'s tolerance (the `<` / `>` keys), kept while another model
    /// runs so that `m` comes back to it.
    pub tolerance: Tolerance,
    pub count: usize,
    pub radius: f64,
    pub camera: Camera,
    pub style: DrawStyle,
    pub light: u8,
    pub help: bool,
    /// The chart of per-thread CPU is shown in place of the canvas.
    pub chart: bool,
    /// The thread panel is sorted by CPU (busiest first), not by role.
    pub threads_by_cpu: bool,
    pub fps: f64,
    pub quit: bool,
    /// A limit a key ran into, shown until the next key.
    pub notice: Option<String>,
    /// The notice says work is under way (placing spheres): the frame that
    /// does it ends it.
    pub under_way: bool,
}

impl AppState {
    pub fn new(settings: &Settings, count: usize, radius: f64, fps: f64) -> AppState {
        AppState {
            threading: settings.threading,
            last_threaded: if settings.threading == Threading::Off {
                Threading::Worker
            } else {
                settings.threading
            },
            threads: settings.threads.max(1),
            tick: settings.tick,
            flat_out: false,
            scene: 0,
            paused: false,
            model: settings.model,
            tolerance: settings.model.tolerance().unwrap_or_default(),
            count,
            radius,
            camera: Camera::default(),
            style: DrawStyle::PointsSpeed,
            light: 0,
            help: false,
            chart: false,
            threads_by_cpu: false,
            fps,
            quit: false,
            notice: None,
            under_way: false,
        }
    }

    /// Whether frames should step the physics.
    pub fn running(&self) -> bool {
        !self.paused && (self.flat_out || self.tick > 0)
    }

    /// The tick the engine runs with: flat out needs a tick above 0 (the
    /// frame's time budget, not the tick, says how many steps).
    pub fn engine_tick(&self) -> u32 {
        if self.flat_out {
            self.tick.max(1)
        } else {
            self.tick
        }
    }

    /// Do one key; returns what the engine must be told. `ran` is the
    /// latest snapshot: what ran, for the notices that say what a key will
    /// (not) change.
    pub fn apply(&mut self, action: Action, ran: &Snapshot) -> Vec<Command> {
        self.notice = None;
        self.under_way = false;
        let out = match action {
            Action::ToggleThreading
            | Action::CycleThreadedMode
            | Action::FewerThreads
            | Action::MoreThreads => self.apply_threads(action, ran),
            Action::FlatOut | Action::TickDown | Action::TickUp | Action::Pause => {
                self.apply_pace(action)
            }
            Action::HalveCount
            | Action::DoubleCount
            | Action::Smaller
            | Action::Bigger
            | Action::CycleModel
            | Action::Tighter
            | Action::Looser
            | Action::Reset => {
                let out = self.apply_scene(action);
                if !out.is_empty() {
                    self.scene += 1;
                }
                out
            }
            _ => {
                self.apply_view(action);
                Vec::new()
            }
        };
        if self.chart
            && matches!(
                action,
                Action::Left
                    | Action::Right
                    | Action::Up
                    | Action::Down
                    | Action::CycleStyle
                    | Action::MoveLight
            )
        {
            self.notice = Some("the view changed behind the chart (c shows it)".into());
        }
        out
    }

    /// The threading keys: mode and pool size.
    fn apply_threads(&mut self, action: Action, ran: &Snapshot) -> Vec<Command> {
        let mut out = Vec::new();
        match action {
            Action::ToggleThreading => {
                if self.threading == Threading::Off {
                    self.threading = self.last_threaded;
                } else {
                    self.last_threaded = self.threading;
                    self.threading = Threading::Off;
                }
                out.push(Command::SetThreading(self.threading));
            }
            Action::CycleThreadedMode => {
                if self.threading == Threading::Off {
                    self.last_threaded = self.last_threaded.next_threaded();
                    self.notice = Some(format!(
                        "t will switch to {} (threading is off)",
                        self.last_threaded
                    ));
                } else {
                    self.threading = self.threading.next_threaded();
                    self.last_threaded = self.threading;
                    out.push(Command::SetThreading(self.threading));
                }
            }
            Action::FewerThreads | Action::MoreThreads => {
                let want = if action == Action::MoreThreads {
                    (self.threads + 1).min(MAX_THREADS)
                } else {
                    self.threads.saturating_sub(1).max(1)
                };
                if want == self.threads {
                    self.notice = Some(format!("pool threads limit: {want}"));
                } else {
                    self.threads = want;
                    out.push(Command::SetThreads(want));
                }
                // The size is kept and sent either way; say when it has no
                // effect yet, so the key does not seem to do nothing.
                if self.notice.is_none() {
                    if self.threading != Threading::Pool {
                        self.notice = Some(format!(
                            "pool threads {want}: kept for pool mode (now {})",
                            self.threading
                        ));
                    } else if ran.one_lane && ran.settings.model == self.model {
                        // The engine said the model kept to one lane, and
                        // no other model is asked since.
                        self.notice = Some(format!(
                            "pool threads {want}: {} runs on one thread",
                            ran.model_ran()
                        ));
                    }
                }
            }
            _ => {}
        }
        out
    }

    /// The pace keys: tick, flat out, pause. A new engine tick is sent
    /// paused or not (a paused frame runs no step but keeps it); the pause
    /// itself is the loop's to hold (`Engine::set_hold`).
    fn apply_pace(&mut self, action: Action) -> Vec<Command> {
        let before = self.engine_tick();
        match action {
            Action::FlatOut => {
                self.flat_out = !self.flat_out;
                self.notice = Some(if self.flat_out {
                    format!(
                        "flat out: as many steps as each frame allows (x: back to tick {})",
                        self.tick
                    )
                } else {
                    format!("flat out off: tick {}", self.tick)
                });
                self.tell_if_paused();
            }
            Action::TickDown | Action::TickUp if self.flat_out => {
                self.notice = Some(format!(
                    "flat out sets the steps; x goes back to tick {}",
                    self.tick
                ));
            }
            Action::TickDown => {
                if self.tick == 0 {
                    self.notice = Some("tick 0: physics frozen".into());
                } else {
                    self.tick -= 1;
                    self.tell_if_paused();
                }
            }
            Action::TickUp => {
                if self.tick >= MAX_TICK {
                    self.notice = Some(format!("tick limit: {MAX_TICK}"));
                } else {
                    self.tick += 1;
                    self.tell_if_paused();
                }
            }
            Action::Pause => self.paused = !self.paused,
            _ => {}
        }
        let after = self.engine_tick();
        if after == before {
            Vec::new()
        } else {
            vec![Command::SetTick(after)]
        }
    }

    /// The scene keys: what is simulated and by which model; every command
    /// starts a new scene for the readouts.
    fn apply_scene(&mut self, action: Action) -> Vec<Command> {
        let mut out = Vec::new();
        match action {
            Action::HalveCount => {
                if self.count <= 1 {
                    self.notice = Some("count limit: 1 sphere".into());
                } else {
                    self.count = self.count.div_ceil(2);
                    out.push(Command::SetCount(self.count));
                }
            }
            Action::DoubleCount => {
                if self.count * 2 > MAX_KEY_COUNT {
                    self.notice = Some(format!("count limit: {MAX_KEY_COUNT}"));
                } else {
                    self.count = (self.count * 2).max(1);
                    out.push(Command::SetCount(self.count));
                    if self.count >= BIG_EDIT {
                        self.notice = Some(format!("placing {} spheres...", self.count));
                        self.under_way = true;
                    }
                }
            }
            Action::Smaller => {
                let want = self.radius / RADIUS_STEP;
                if want < MIN_RADIUS {
                    self.notice = Some(format!("radius limit: {MIN_RADIUS}"));
                } else {
                    self.radius = want;
                    out.push(Command::SetRadius(want));
                }
            }
            Action::Bigger => {
                self.radius *= RADIUS_STEP;
                out.push(Command::SetRadius(self.radius));
            }
            Action::CycleModel => {
                self.model = match self.model.next() {
                    ModelKind::Auto(_) => ModelKind::Auto(self.tolerance),
                    m => m,
                };
                out.push(Command::SetModel(self.model));
            }
            Action::Tighter | Action::Looser => out.extend(self.step_tolerance(action)),
            Action::Reset => {
                out.push(Command::Reset);
                self.notice = Some("scene back to its start".into());
            }
            _ => {}
        }
        out
    }

    /// The view keys: nothing for the engine.
    fn apply_view(&mut self, action: Action) {
        match action {
            Action::Quit => self.quit = true,
            Action::Escape => {
                if self.help {
                    self.help = false;
                } else if self.chart {
                    self.chart = false;
                } else {
                    self.quit = true;
                }
            }
            Action::Left => self.camera.yaw -= CAMERA_STEP,
            Action::Right => self.camera.yaw += CAMERA_STEP,
            Action::Up => self.camera.pitch = (self.camera.pitch + CAMERA_STEP).min(MAX_PITCH),
            Action::Down => self.camera.pitch = (self.camera.pitch - CAMERA_STEP).max(-MAX_PITCH),
            Action::CycleStyle => self.style = self.style.next(),
            Action::MoveLight => {
                self.light = (self.light + 1) % LIGHT_STEPS;
                if self.style != DrawStyle::Shaded && !self.chart {
                    self.notice = Some("the light shows in the shaded style (v)".into());
                }
            }
            Action::Chart => self.chart = !self.chart,
            Action::SortThreads => self.threads_by_cpu = !self.threads_by_cpu,
            Action::Help => self.help = !self.help,
            Action::SlowerFps => match FPS_STEPS.iter().rev().find(|&&f| f < self.fps - 1e-9) {
                Some(&f) => self.fps = f,
                None => self.notice = Some(format!("fps limit: {}", FPS_STEPS[0])),
            },
            Action::FasterFps => match FPS_STEPS.iter().find(|&&f| f > self.fps + 1e-9) {
                Some(&f) => self.fps = f,
                None => {
                    self.notice = Some(format!("fps limit: {}", FPS_STEPS[FPS_STEPS.len() - 1]));
                }
            },
            // Suspend: the input thread stops the process.
            _ => {}
        }
    }

    /// `<` / `>`: the tolerance one step of the ladder tighter / looser;
    /// `auto` is asked again with it, the other models keep it for `m`.
    fn step_tolerance(&mut self, action: Action) -> Option<Command> {
        let want = self.tolerance.step(action == Action::Looser);
        let auto = matches!(self.model, ModelKind::Auto(_));
        let limit = if want == self.tolerance { "limit " } else { "" };
        self.tolerance = want;
        self.notice = Some(if auto {
            format!("tolerance {limit}{want} of the smaller radius: auto chooses for it")
        } else {
            format!(
                "tolerance {limit}{want}: it only steers auto ({} runs; m cycles to auto)",
                self.model
            )
        });
        (auto && limit.is_empty()).then(|| {
            self.model = ModelKind::Auto(want);
            Command::SetModel(self.model)
        })
    }

    /// The tick is kept while paused; it runs on resume.
    fn tell_if_paused(&mut self) {
        if self.paused && self.flat_out {
            self.notice = Some("flat out: runs when resumed (space)".into());
        } else if self.paused {
            self.notice = Some(format!("tick {}: runs when resumed (space)", self.tick));
        }
    }

    /// Take what the engine really did (count and radius may stop at a
    /// limit; reset restores the scene). `applied`: this frame applied our
    /// commands, so its notice (or the lack of one) answers them. `asked_since`:
    /// keys were pressed after the frame started, so their threading stands
    /// until a frame answers them.
    pub fn sync(&mut self, snap: &Snapshot, applied: bool, asked_since: bool) {
        self.count = snap.count;
        if let Some(r) = representative_radius(snap) {
            self.radius = r;
        }
        // The engine's notice (a limit it hit) answers the commands; with
        // none, the key's own notice stays, unless it said work was under way.
        if applied && !asked_since {
            // Threads the system refused fall back to what exists.
            self.threading = snap.settings.threading;
            self.threads = snap.settings.threads;
        }
        if applied {
            if snap.notice.is_some() {
                self.notice.clone_from(&snap.notice);
            } else if self.under_way {
                self.notice = None;
            }
            self.under_way = false;
        }
        // `auto` switched: said whatever caused it (a key, an edit, a broken
        // promise), after the answer to the key that frame applied.
        if let Some(sw) = &snap.switch_notice {
            self.notice = Some(match (&self.notice, applied) {
                (Some(k), true) => format!("{k}; {sw}"),
                _ => sw.clone(),
            });
        }
    }
}

/// The radius the `r`/`R` keys scale: the largest one (for mixed scenes the
/// largest sphere is what hits the limit first).
pub fn representative_radius(snap: &Snapshot) -> Option<f64> {
    snap.max_radius
}
