//! One screen: where each part goes, and the message when the terminal is
//! too small for them.
use super::canvas::{Raster, Scene};
use super::help::{HelpBar, HelpOverlay};
use super::readouts::{self, Readouts, Stats};
use super::state::AppState;
use super::theme::Palette;
use super::threads::Threads;
use crate::cpu::CpuReport;
use crate::engine::Snapshot;
use ratatui::Frame;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::text::Line;
use ratatui::widgets::{Paragraph, Wrap};

pub const MIN_WIDTH: u16 = 72;
pub const MIN_HEIGHT: u16 = 22;
pub const PANEL_WIDTH: u16 = 44;

/// Everything one frame shows.
pub struct View<'a> {
    pub state: &'a AppState,
    pub snap: &'a Snapshot,
    pub stats: &'a Stats,
    pub report: &'a CpuReport,
    pub palette: Palette,
    /// Cell height / width.
    pub aspect: f64,
}

pub fn draw(frame: &mut Frame, raster: &mut Raster, v: &View) {
    let area = frame.area();
    if area.width < MIN_WIDTH || area.height < MIN_HEIGHT {
        let msg = vec![
            Line::from("ballpit needs a bigger terminal:"),
            Line::from(format!(
                "at least {MIN_WIDTH}x{MIN_HEIGHT}, this one is {}x{}.",
                area.width, area.height
            )),
            Line::from("q quits."),
        ];
        let h = (msg.len() as u16).min(area.height);
        let r = Rect::new(area.x, area.y + (area.height - h) / 2, area.width, h);
        frame.render_widget(Paragraph::new(msg).centered().wrap(Wrap { trim: true }), r);
        return;
    }
    let [main, bar] = Layout::vertical([Constraint::Fill(1), Constraint::Length(1)]).areas(area);
    let [canvas, side] =
        Layout::horizontal([Constraint::Fill(1), Constraint::Length(PANEL_WIDTH)]).areas(main);
    let [top, bottom] =
        Layout::vertical([Constraint::Length(readouts::HEIGHT), Constraint::Fill(1)]).areas(side);
    let scene = Scene {
        box_size: v.snap.size,
        camera: v.state.camera,
        style: v.state.style,
        light: v.state.light,
        palette: v.palette,
        aspect: v.aspect,
    };
    raster.draw(&v.snap.spheres, &scene, canvas, frame.buffer_mut());
    frame.render_widget(
        Readouts {
            state: v.state,
            snap: v.snap,
            stats: v.stats,
            palette: v.palette,
        },
        top,
    );
    frame.render_widget(
        Threads {
            report: v.report,
            palette: v.palette,
        },
        bottom,
    );
    frame.render_widget(HelpBar { palette: v.palette }, bar);
    if v.state.help {
        frame.render_widget(HelpOverlay { palette: v.palette }, canvas);
    }
}
