//! The readouts panel: every figure as text in a fixed place, so values
//! change without the layout moving.
use super::theme::Palette;
use super::wrap::wrap;
use crate::engine::{Settings, Snapshot, Threading};
use crate::physics::ModelKind;
use crate::physics::auto::Choice;
use crate::tui::state::{AppState, representative_radius};
use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Paragraph, Widget};
use std::time::Duration;
use unicode_width::UnicodeWidthStr;

/// Figures the frame loop measures (the rest come from the snapshot).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Stats {
    /// Frames drawn per second, over the last second.
    pub fps: f64,
    /// Physics per frame, seconds (mean over the last second).
    pub physics_seconds: f64,
    /// Building and writing a frame, seconds (mean over the last second).
    pub render_seconds: f64,
    /// Bytes written to the terminal per frame (mean over the last second).
    pub frame_bytes: u64,
    pub steps_per_second: f64,
    pub collisions_per_second: f64,
    /// The palette the terminal says it can do.
    pub detected: Option<Palette>,
    /// The link to the terminal as the pacing sees it (run.rs, pacing.rs).
    pub link: Option<String>,
    /// The link is slower than the frames: the compact form shows it in
    /// place of the render time, as the reason the picture slowed.
    pub link_slow: bool,
    /// A threaded frame still computing: its steps so far and its age.
    pub under_way: Option<(u64, Duration)>,
    /// Flat out: steps/s measured per mode ([`mode_label`]) on the
    /// scene `flat_scene`, the latest whole second of each.
    pub flat: Vec<(String, f64)>,
    pub flat_scene: u64,
    /// The mode and scene of the last second, to keep only whole seconds
    /// of one mode.
    pub flat_last: Option<(String, u64)>,
}

impl Stats {
    /// Flat out: how long a frame's physics may step. With the physics on
    /// `main` (off), the period less the drawing's share (and a margin);
    /// on a physics thread, most of the period, as the drawing runs beside it.
    pub fn flat_out_budget(&self, state: &AppState) -> Duration {
        let period = 1.0 / state.fps;
        let share = if state.threading == Threading::Off {
            period - 1.5 * self.render_seconds - 1e-3
        } else {
            0.9 * period
        };
        Duration::from_secs_f64(share.clamp(0.1 * period, 0.9 * period))
    }

    /// After a second's figures: keep flat out's steps/s for the mode that
    /// ran (`ran`, the latest snapshot's settings), if the whole second ran
    /// flat out in this mode on this scene; a new scene starts the
    /// comparison again.
    pub fn remember(&mut self, state: &AppState, ran: &Settings) {
        if self.flat_scene != state.scene {
            self.flat.clear();
            self.flat_scene = state.scene;
        }
        let now = (state.flat_out && state.running()).then(|| (mode_label(ran), state.scene));
        if let Some(n) = &now
            && self.flat_last.as_ref() == Some(n)
            && self.steps_per_second > 0.0
        {
            match self.flat.iter_mut().find(|(m, _)| *m == n.0) {
                Some(e) => e.1 = self.steps_per_second,
                None => self.flat.push((n.0.clone(), self.steps_per_second)),
            }
        }
        self.flat_last = now;
    }

    /// Flat out's steps/s in `mode` over those in `off`, when both are known.
    pub fn speed_up(&self, mode: &str) -> Option<f64> {
        let get = |m: &str| self.flat.iter().find(|e| e.0 == m).map(|e| e.1);
        Some(get(mode)? / get("off")?)
    }
}

/// Rows of figures in the full form, and of the compact one.
const FULL_ROWS: u16 = 16;
const COMPACT_ROWS: u16 = 7;
/// Rows kept for a notice, so a long one wraps instead of being cut (every
/// notice of bounded length fits two rows of the narrowest panel,
/// `tests/app/notices.rs`; a longer one takes rows from the threads).
pub const NOTICE_ROWS: u16 = 2;
/// The full panel: its rows, the notice and the border.
pub const HEIGHT: u16 = FULL_ROWS + NOTICE_ROWS + 2;
/// The compact panel, for short terminals.
pub const COMPACT_HEIGHT: u16 = COMPACT_ROWS + NOTICE_ROWS + 2;

pub struct Readouts<'a> {
    pub state: &'a AppState,
    pub snap: &'a Snapshot,
    pub stats: &'a Stats,
    pub palette: Palette,
}

/// The mode as flat out's comparison names it (a pool with its size).
pub fn mode_label(settings: &Settings) -> String {
    match settings.threading {
        Threading::Pool => format!("pool {}", settings.threads),
        t => t.name().to_string(),
    }
}

/// The rows that say what ran (threading, tick, model) read the snapshot's
/// settings and the threads the engine says the physics ran on; the state
/// gives only what is the screen's own: the pause, flat out, the frame
/// rate, the mode `t` goes back to.
impl Readouts<'_> {
    fn threading(&self) -> String {
        let snap = self.snap;
        // `auto` ran on the lanes of the model it chose.
        let m = snap.model_ran();
        let threads = snap.physics_threads.len();
        match snap.settings.threading {
            Threading::Off => format!("off      on main; t -> {}", self.state.last_threaded),
            // A model on one lane does not split: say where it runs (a
            // pool hosts the whole frame on one of its threads).
            Threading::Pool if snap.one_lane => {
                format!("{:<8} {} on 1 pool thread", Threading::Pool.name(), m)
            }
            Threading::Split if snap.one_lane => {
                format!("{:<8} {} runs on physics", Threading::Split.name(), m)
            }
            t => format!(
                "{:<8} {threads} physics thread{}",
                t.name(),
                if threads == 1 { "" } else { "s" }
            ),
        }
    }

    /// The frame rate, or why there is none: paused and frozen screens
    /// are only redrawn when something changes.
    fn fps(&self, compact: bool) -> String {
        let s = self.state;
        match (s.paused, s.engine_tick()) {
            (true, _) => "paused".into(),
            (false, 0) if compact => "frozen".into(),
            (false, 0) => "frozen (tick 0)".into(),
            // A window's count can hold one frame more than its periods:
            // never show more frames than the target allows.
            _ if compact => format!("{:.1} of {}", self.stats.fps.min(s.fps), s.fps),
            _ => format!("{:<8.1} target {}", self.stats.fps.min(s.fps), s.fps),
        }
    }

    /// The radius in force: the snapshot's, never the one asked for.
    /// A mixed scene shows its range, smallest to largest.
    fn radius(&self, compact: bool) -> String {
        let Some(max) = representative_radius(self.snap) else {
            return "-".into();
        };
        match self.snap.min_radius {
            Some(min) if min < max && compact => format!("{min:.3}-{max:.3}"),
            Some(min) if min < max => format!("{min:.5}-{max:.5}"),
            _ => format!("{max:.5}"),
        }
    }

    /// Simulated seconds per second: steps/s times dt, so `f`/`F` (and
    /// the tick) explain the speed they change.
    fn sim_speed(&self) -> String {
        format!(
            "sim {:.2} s/s",
            self.stats.steps_per_second * self.snap.settings.dt
        )
    }

    /// A frame that has run longer than a few periods, as "N steps, T s".
    fn long_frame(&self) -> Option<String> {
        let (steps, age) = self.stats.under_way?;
        (age.as_secs_f64() > 3.0 / self.state.fps)
            .then(|| format!("{steps} steps, {:.1} s", age.as_secs_f64()))
    }

    /// Steps per second: flat out's with its speed-up over `off`, or a
    /// long frame's rate so far.
    fn steps_per_second(&self, compact: bool) -> String {
        let st = self.stats;
        if let Some((steps, age)) = st.under_way.filter(|_| self.long_frame().is_some()) {
            let rate = steps as f64 / age.as_secs_f64().max(1e-9);
            return format!("{rate:.0} this frame");
        }
        let now = if compact {
            format!("{:.0}/s", st.steps_per_second)
        } else {
            format!("{:<8.0}", st.steps_per_second)
        };
        if !self.state.flat_out {
            // The compact form has no tick row of its own to say the
            // simulated seconds per second: they go with the steps.
            return if compact {
                format!(
                    "{now} {:.2}s/s",
                    st.steps_per_second * self.snap.settings.dt
                )
            } else {
                now
            };
        }
        match st.speed_up(&mode_label(&self.snap.settings)) {
            Some(x) if compact => format!("{now} {x:.2}x"),
            Some(x) => format!("{now} flat out, {x:.2}x off"),
            None if compact => now,
            None => format!("{now} flat out"),
        }
    }

    /// Flat out's comparison: every mode measured on this scene, as its
    /// speed-up over `off` (kept while the user switches modes).
    fn comparison(&self) -> String {
        let st = self.stats;
        if !self.state.flat_out {
            return "x: flat out compares the modes".into();
        }
        let rows: Vec<String> = st
            .flat
            .iter()
            .filter(|(m, _)| m != "off")
            .filter_map(|(m, _)| st.speed_up(m).map(|x| format!("{m} {x:.2}x")))
            .collect();
        if st.speed_up("off").is_none() {
            "measure off first (t)".into()
        } else if rows.is_empty() {
            "t, d: measure the other modes".into()
        } else {
            rows.join(" ")
        }
    }

    fn physics_ms(&self) -> String {
        if let Some(long) = self.long_frame() {
            long
        } else if self.state.running() {
            format!("{:.2} ms", self.stats.physics_seconds * 1e3)
        } else {
            "idle".into()
        }
    }

    fn colour(&self) -> String {
        match self.stats.detected {
            Some(d) if d != self.palette => {
                format!("{} (terminal: {})", self.palette.name(), d.name())
            }
            _ => self.palette.name().to_string(),
        }
    }

    /// Every figure, one a row (tall terminals).
    pub fn lines(&self) -> Vec<Line<'static>> {
        let s = self.state;
        let snap = self.snap;
        let st = self.stats;
        let label = self.palette.label();
        let row = |name: &str, value: String| {
            Line::from(vec![
                Span::styled(format!("{name:<11}"), label),
                Span::raw(value),
            ])
        };
        // The tick that ran; flat out is the screen's (it sets the steps
        // each frame, and keeps the tick x goes back to).
        let ran = snap.settings.tick;
        let mut tick = format!("{ran:<8} step{}/frame", if ran == 1 { "" } else { "s" });
        if s.flat_out {
            tick = format!("{:<8} flat out (x: tick {})", "max", s.tick);
        } else if ran == 0 {
            tick.push_str("  frozen");
        } else {
            tick = format!(
                "{ran} step{}/frame  {}",
                if ran == 1 { "" } else { "s" },
                self.sim_speed()
            );
        }
        vec![
            row("threading", self.threading()),
            row("tick", tick),
            row("count", format!("{}", snap.count)),
            row("radius", self.radius(false)),
            row(
                "model",
                model_row(snap.settings.model, snap.parts, snap.choice.as_ref()),
            ),
            row("style", s.style.name().to_string()),
            row("colour", self.colour()),
            row("fps", self.fps(false)),
            row(
                "physics",
                if self.long_frame().is_some() {
                    format!("under way, {}", self.physics_ms())
                } else if s.running() {
                    format!("{:<8} per frame", self.physics_ms())
                } else {
                    self.physics_ms()
                },
            ),
            row(
                "render",
                format!(
                    "{:<8} per frame",
                    format!("{:.2} ms", st.render_seconds * 1e3)
                ),
            ),
            row("steps/s", self.steps_per_second(false)),
            row("vs off", self.comparison()),
            row(
                "drift",
                format!("{:<8.1e} energy vs start/edit", snap.energy_drift()),
            ),
            row(
                "overlap",
                format!("{:<8} deepest/r  escaped {}", overlap(snap), snap.escaped),
            ),
            row(
                "collisions",
                format!("{:<8.0} per s", st.collisions_per_second),
            ),
            row(
                "output",
                match &st.link {
                    Some(link) => format!("{:<8} {link}", human_bytes(st.frame_bytes)),
                    None => format!("{:<8} per frame", human_bytes(st.frame_bytes)),
                },
            ),
        ]
    }

    /// The same figures two to a row (80x24 and other short terminals).
    pub fn compact_lines(&self) -> Vec<Line<'static>> {
        let s = self.state;
        let snap = self.snap;
        let st = self.stats;
        let label = self.palette.label();
        let pair = |a: &str, av: String, b: &str, bv: String| {
            Line::from(vec![
                Span::styled(format!("{a:<8}"), label),
                Span::raw(format!("{av:<13}")),
                Span::styled(format!("{b:<8}"), label),
                Span::raw(bv),
            ])
        };
        let asked = snap.settings.model.name();
        let name = match &snap.choice {
            Some(c) => format!("{asked}→{}", c.model),
            None => asked.to_string(),
        };
        let model = if snap.parts > 1 {
            format!("{name} cut {}", snap.parts)
        } else {
            name
        };
        vec![
            Line::from(vec![
                Span::styled("threading  ", label),
                Span::raw(self.threading()),
            ]),
            pair(
                "tick",
                // The number first and alone, as in the full form, so a
                // reader (or a test) takes the tick from the first word.
                if s.flat_out {
                    "max".into()
                } else {
                    let ran = snap.settings.tick;
                    format!("{ran} step{}", if ran == 1 { "" } else { "s" })
                },
                "count",
                snap.count.to_string(),
            ),
            pair("radius", self.radius(true), "model", model),
            pair("fps", self.fps(true), "physics", self.physics_ms()),
            match (&st.link, st.link_slow) {
                (Some(link), true) => Line::from(vec![
                    Span::styled(format!("{:<8}", "link"), label),
                    Span::raw(format!("{link} {}/fr", human_bytes(st.frame_bytes))),
                ]),
                _ => pair(
                    "render",
                    format!("{:.2} ms", st.render_seconds * 1e3),
                    "output",
                    format!("{}/fr", human_bytes(st.frame_bytes)),
                ),
            },
            pair(
                "drift",
                format!("{:.1e}", snap.energy_drift()),
                "overlap",
                format!("{} esc {}", overlap(snap), snap.escaped),
            ),
            pair(
                "steps",
                self.steps_per_second(true),
                "coll",
                format!("{:.0}/s", st.collisions_per_second),
            ),
        ]
    }

    /// What shows under the figures: the last key's notice (it answers
    /// the key, paused or not), the pause, or the event cap.
    pub fn notice(&self) -> Option<String> {
        let s = self.state;
        if let Some(n) = &s.notice {
            Some(n.clone())
        } else if s.paused {
            Some("PAUSED (space resumes)".into())
        } else if self.snap.counters.capped_steps > 0 {
            // A capped step skipped contacts: say so, it explains overlaps.
            let c = &self.snap.counters;
            let why = if c.budget_steps > 0 {
                "work budget"
            } else {
                "event cap"
            };
            Some(format!(
                "{why} hit in {} steps, overlaps possible: lower --dt or --speed",
                c.capped_steps
            ))
        } else {
            None
        }
    }
}

/// A notice's rows in a panel of inner `width`: a column of margin each
/// side, so in reverse video (no colour) it reads as a bar.
pub fn notice_lines(notice: &str, width: u16) -> Vec<String> {
    wrap(notice, usize::from(width.saturating_sub(2)))
}

/// Rows the panel keeps for `notice` at an inner `width`: the kept ones,
/// or more when it needs them (the layout takes them from the threads).
pub fn notice_rows(notice: Option<&str>, width: u16) -> u16 {
    let rows = notice.map_or(0, |n| notice_lines(n, width).len());
    u16::try_from(rows).unwrap_or(u16::MAX).max(NOTICE_ROWS)
}

/// The model, and the parts it cut its last step into when it did (fast
/// or crowded scenes: see `physics/swept/parts.rs`).
/// `auto` says what it runs and why.
fn model_row(model: ModelKind, parts: u32, choice: Option<&Choice>) -> String {
    let name = match choice {
        Some(c) => format!("{} → {} ({})", model.name(), c.model, c.reason),
        None => model.name().to_string(),
    };
    if parts > 1 {
        format!("{name:<8} steps cut in {parts}")
    } else {
        name
    }
}

impl Widget for Readouts<'_> {
    /// The full form when the area has room for it and the notice, else
    /// the compact one; the notice wraps in the rows under the figures.
    fn render(self, area: Rect, buf: &mut Buffer) {
        let block = Block::bordered().title(" ballpit ");
        let inner = block.inner(area);
        block.render(area, buf);
        let notice = self.notice().map(|n| notice_lines(&n, inner.width));
        let need = notice
            .as_ref()
            .map_or(0, |n| n.len() as u16)
            .max(NOTICE_ROWS);
        let lines = if inner.height >= FULL_ROWS + need && inner.width >= 42 {
            self.lines()
        } else {
            self.compact_lines()
        };
        let rows = (lines.len() as u16).min(inner.height);
        Paragraph::new(lines).render(
            Rect {
                height: rows,
                ..inner
            },
            buf,
        );
        let Some(mut notice) = notice else {
            return;
        };
        // Cut only when the layout could not give the rows (the threads
        // keep theirs): the last row then ends in an ellipsis.
        let room = usize::from(inner.height - rows);
        if notice.len() > room {
            notice.truncate(room);
            if let Some(last) = notice.last_mut() {
                while last.width() + 3 > usize::from(inner.width) && last.pop().is_some() {}
                last.push('…');
            }
        }
        let style = self.palette.alert();
        let text: Vec<Line> = notice
            .into_iter()
            .map(|row| Line::from(Span::styled(format!(" {row} "), style)))
            .collect();
        Paragraph::new(text).render(
            Rect {
                y: inner.y + rows,
                height: inner.height - rows,
                ..inner
            },
            buf,
        );
    }
}

pub fn human_bytes(b: u64) -> String {
    if b < 10_000 {
        format!("{b} B")
    } else if b < 10_000_000 {
        format!("{:.1} KB", b as f64 / 1e3)
    } else {
        format!("{:.1} MB", b as f64 / 1e6)
    }
}

/// The deepest overlap; "≥" when the readout stopped at its pair budget
/// (a heap of overlapping spheres) and so gives a lower bound.
fn overlap(snap: &Snapshot) -> String {
    let at_least = if snap.overlap_partial { "≥" } else { "" };
    format!("{at_least}{:.1e}", snap.max_overlap_rel)
}
