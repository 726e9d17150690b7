//! The presenter: owns the terminal, the byte sink, the `output` thread and
//! the pacing, and turns a view of the state into one chunk on the wire. The
//! frame loop (`run.rs`) owns the engine, the state and the deadlines, and
//! asks the presenter to draw.
use super::msg::Msg;
use super::state::AppState;
use super::term::backend::{Counting, Lean, Sink};
use super::term::escapes::STATUS_QUERY;
use super::term::pacing::Pacer;
use super::term::writer::Output;
use super::view::canvas::Raster;
use super::view::layout::{self, View};
use super::view::readouts::Stats;
use super::view::theme::Palette;
use crate::cpu::CpuReport;
use crate::engine::Snapshot;
use anyhow::anyhow;
use crossbeam_channel::Sender;
use crossterm::queue;
use crossterm::terminal::{BeginSynchronizedUpdate, EndSynchronizedUpdate};
use ratatui::Terminal;
use ratatui::backend::Backend;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

/// Called once on the frame loop's thread when the first frame has gone to
/// the terminal.
pub type AfterFirstFrame = Box<dyn FnOnce()>;

type Term = Terminal<Lean<Counting<Sink>>>;

pub(super) struct Presenter {
    terminal: Term,
    sink: Sink,
    output: Output,
    pub(super) pacer: Pacer,
    /// On a slow link, the snapshot last drawn: a key's update is drawn on
    /// it, so only what the key changed crosses the link.
    drawn: Option<Snapshot>,
    bytes: Arc<AtomicU64>,
    raster: Raster,
    palette: Palette,
    /// The locale is not UTF-8: every cell is drawn in ASCII.
    ascii: bool,
    /// Cell height over width.
    aspect: f64,
    after_first_frame: Option<AfterFirstFrame>,
}

/// What one draw cost, for the loop's per-second figures.
pub(super) struct Drawn {
    pub seconds: f64,
    pub bytes: u64,
    /// A key's update drawn on the last frame's canvas: the screen is
    /// still owed a whole frame.
    pub kept_canvas: bool,
}

/// What a frame shows besides the snapshot.
pub(super) struct Scene<'a> {
    pub state: &'a AppState,
    pub stats: &'a Stats,
    pub report: &'a CpuReport,
}

impl Presenter {
    pub(super) fn new(
        palette: Palette,
        ascii: bool,
        after_first_frame: Option<AfterFirstFrame>,
        events: Sender<Msg>,
    ) -> anyhow::Result<Presenter> {
        let output = Output::spawn(events)?;
        // The start-up probe: does the terminal answer status requests?
        output.send(STATUS_QUERY.to_vec(), 1);
        let sink = Sink::default();
        let (writer, bytes) = Counting::new(sink.clone());
        let lean = Lean::new(writer);
        // A terminal without colours gets no colour escape at all, whatever
        // a widget asks for.
        let lean = if palette.has_color() {
            lean
        } else {
            lean.without_colours()
        };
        let mut terminal = Terminal::new(lean)?;
        // Not `Terminal::clear`: it asks the terminal for the cursor position,
        // a round trip that a slow link or a dumb pty may never answer.
        Backend::clear(terminal.backend_mut())?;
        Ok(Presenter {
            terminal,
            sink,
            output,
            pacer: Pacer::new(Instant::now()),
            drawn: None,
            bytes,
            raster: Raster::new(),
            palette,
            ascii,
            aspect: cell_aspect(),
            after_first_frame,
        })
    }

    /// The terminal changed size.
    pub(super) fn resize(&mut self) -> anyhow::Result<()> {
        self.aspect = cell_aspect();
        self.terminal.autoresize()?;
        Ok(())
    }

    /// Back from a stop: a new terminal state (ask again whether it
    /// answers) and the whole screen repainted at its current size.
    pub(super) fn resume(&mut self) -> anyhow::Result<()> {
        self.pacer = Pacer::new(Instant::now());
        self.output.send(STATUS_QUERY.to_vec(), 1);
        self.resize()?;
        // Forgets what is on screen, so the next frame draws every cell.
        self.terminal.clear()?;
        self.drawn = None;
        Ok(())
    }

    /// Draw a frame of `latest`, or with `update` a key's answer that keeps
    /// the canvas of the last frame when the link is slow.
    pub(super) fn draw(
        &mut self,
        latest: &Snapshot,
        scene: &Scene<'_>,
        update: bool,
    ) -> anyhow::Result<Drawn> {
        let t0 = Instant::now();
        let before = self.bytes.load(Ordering::Relaxed);
        let slow = self.pacer.slow();
        let kept_canvas = update && slow && self.drawn.is_some();
        if !kept_canvas {
            self.drawn = slow.then(|| latest.clone());
        }
        let snap = match (&self.drawn, kept_canvas) {
            (Some(s), true) => s,
            _ => latest,
        };
        let view = View {
            state: scene.state,
            snap,
            stats: scene.stats,
            report: scene.report,
            // On a slow link, frames without colours are much smaller.
            palette: if self.pacer.cheap() {
                Palette::Mono
            } else {
                self.palette
            },
            aspect: self.aspect,
        };
        let raster = &mut self.raster;
        queue!(self.terminal.backend_mut(), BeginSynchronizedUpdate)?;
        let ascii = self.ascii;
        self.terminal.draw(|f| {
            layout::draw(f, raster, &view);
            if ascii {
                super::term::caps::asciify(f.buffer_mut());
            }
        })?;
        let backend = self.terminal.backend_mut();
        queue!(backend, EndSynchronizedUpdate)?;
        Backend::flush(backend)?;
        let frame = self.sink.take();
        let asked = self.pacer.asks();
        let chunk = if asked {
            [STATUS_QUERY, &frame, STATUS_QUERY].concat()
        } else {
            frame
        };
        let len = chunk.len();
        // A write error comes back from the output thread as Msg::Fatal.
        if !self.output.send(chunk, if asked { 2 } else { 0 }) {
            return Err(anyhow!("the output thread stopped"));
        }
        self.pacer.sent(Instant::now(), len, asked);
        if let Some(hook) = self.after_first_frame.take() {
            hook();
        }
        Ok(Drawn {
            seconds: t0.elapsed().as_secs_f64(),
            bytes: self.bytes.load(Ordering::Relaxed) - before,
            kept_canvas,
        })
    }
}

/// Cell height over width, from the terminal's pixel size when it says;
/// 2 is the usual font.
fn cell_aspect() -> f64 {
    match crossterm::terminal::window_size() {
        Ok(w) if w.width > 0 && w.height > 0 && w.columns > 0 && w.rows > 0 => {
            let cw = f64::from(w.width) / f64::from(w.columns);
            let ch = f64::from(w.height) / f64::from(w.rows);
            (ch / cw).clamp(1.0, 3.0)
        }
        _ => 2.0,
    }
}
