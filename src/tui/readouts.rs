//! The readouts panel: every figure as text in a fixed place, so values
//! change without the layout moving.
use super::state::{AppState, physics_threads};
use super::theme::Palette;
use crate::engine::{Snapshot, Threading};
use crate::physics::ModelKind;
use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Paragraph, Widget};

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
}

/// 16 rows and the border.
pub const HEIGHT: u16 = 18;

pub struct Readouts<'a> {
    pub state: &'a AppState,
    pub snap: &'a Snapshot,
    pub stats: &'a Stats,
    pub palette: Palette,
}

impl Readouts<'_> {
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
        let threads = physics_threads(s.threading, s.threads);
        let threading = match s.threading {
            Threading::Off => format!("off      on main; t -> {}", s.last_threaded),
            // The event loop of `exact` does not split: say where it runs.
            t @ (Threading::Pool | Threading::Split) if s.model == ModelKind::Exact => {
                format!("{:<8} exact runs on physics", t.name())
            }
            t => format!(
                "{:<8} {threads} physics thread{}",
                t.name(),
                if threads == 1 { "" } else { "s" }
            ),
        };
        let mut tick = format!(
            "{:<8} step{}/frame",
            s.tick,
            if s.tick == 1 { "" } else { "s" }
        );
        if s.tick == 0 {
            tick.push_str("  frozen");
        }
        let collisions = format!("{:<8.0} per s", st.collisions_per_second);
        let colour = match st.detected {
            Some(d) if d != self.palette => {
                format!("{} (terminal: {})", self.palette.name(), d.name())
            }
            _ => self.palette.name().to_string(),
        };
        let mut lines = vec![
            row("threading", threading),
            row("tick", tick),
            row("count", format!("{}", snap.spheres.len())),
            row("radius", format!("{:.5}", s.radius)),
            row("model", model_row(s.model, snap.parts)),
            row("style", s.style.name().to_string()),
            row("colour", colour),
            row("fps", format!("{:<8.1} target {}", st.fps, s.fps)),
            row(
                "physics",
                format!("{:<8.2} ms/frame", st.physics_seconds * 1e3),
            ),
            row(
                "render",
                format!("{:<8.2} ms/frame", st.render_seconds * 1e3),
            ),
            row("steps/s", format!("{:<8.0}", st.steps_per_second)),
            row(
                "drift",
                format!("{:<8.1e} energy since reset", snap.energy_drift()),
            ),
            row(
                "overlap",
                format!(
                    "{:<8.1e} deepest/r  escaped {}",
                    snap.max_overlap_rel, snap.escaped
                ),
            ),
            row("collisions", collisions),
            row(
                "output",
                match &st.link {
                    Some(link) => format!("{:<8} {link}", human_bytes(st.frame_bytes)),
                    None => format!("{:<8} per frame", human_bytes(st.frame_bytes)),
                },
            ),
        ];
        if s.paused {
            lines.push(Line::from(Span::styled(
                " PAUSED (space resumes) ",
                self.palette.alert(),
            )));
        } else if let Some(n) = &s.notice {
            lines.push(Line::from(Span::styled(n.clone(), self.palette.alert())));
        } else if snap.counters.capped_steps > 0 {
            // A capped step skipped contacts: say so, it explains overlaps.
            lines.push(Line::from(Span::styled(
                format!(" event cap hit in {} steps ", snap.counters.capped_steps),
                self.palette.alert(),
            )));
        } else {
            lines.push(Line::from(""));
        }
        lines
    }
}

/// The model, and the parts it cut its last step into when it did (fast
/// or crowded scenes: see `physics/swept/parts.rs`).
fn model_row(model: ModelKind, parts: u32) -> String {
    if parts > 1 {
        format!("{:<8} steps cut in {parts}", model.name())
    } else {
        model.name().to_string()
    }
}

impl Widget for Readouts<'_> {
    fn render(self, area: Rect, buf: &mut Buffer) {
        Paragraph::new(self.lines())
            .block(Block::bordered().title(" ballpit "))
            .render(area, buf);
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
