//! One screen: where each part goes at this size, and the message when the
//! terminal is too small for them. At 80x24 the readouts go compact so
//! every thread keeps a row; with more threads than rows the thread panel
//! goes compact (a grid) and the readouts may stay whole.
use super::canvas::{Raster, Scene};
use super::chart::CpuChart;
use super::help::{HelpBar, HelpOverlay};
use super::readouts::{self, Readouts, Stats};
use super::theme::Palette;
use super::threads::{self, Threads};
use crate::cpu::CpuReport;
use crate::engine::Snapshot;
use crate::tui::state::AppState;
use ratatui::Frame;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::text::Line;
use ratatui::widgets::Paragraph;

pub const MIN_WIDTH: u16 = 72;
pub const MIN_HEIGHT: u16 = 22;
/// The side panel's width, and the most it grows to on wide terminals
/// (a minute of sparkline: name, figure and 60 bars).
pub const PANEL_WIDTH: u16 = 44;
pub const PANEL_MAX: u16 = 84;

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

/// Where the parts go.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Areas {
    pub canvas: Rect,
    pub readouts: Rect,
    pub threads: Rect,
    pub bar: Rect,
    /// Canvas and panel: where the help overlay is centred.
    pub main: Rect,
}

/// The layout for `area` with no notice, or None when it is below the
/// minimum.
pub fn areas(area: Rect, report: &CpuReport) -> Option<Areas> {
    areas_with(area, report, None)
}

/// The layout for `area` showing `notice`: one longer than the readouts'
/// kept rows takes more, from the threads' blank rows first, never so many
/// that a thread is hidden.
pub fn areas_with(area: Rect, report: &CpuReport, notice: Option<&str>) -> Option<Areas> {
    if area.width < MIN_WIDTH || area.height < MIN_HEIGHT {
        return None;
    }
    let [main, bar] = Layout::vertical([Constraint::Fill(1), Constraint::Length(1)]).areas(area);
    let panel = PANEL_WIDTH.max((area.width.saturating_add(2) / 3).min(PANEL_MAX));
    let [canvas, side] =
        Layout::horizontal([Constraint::Fill(1), Constraint::Length(panel)]).areas(main);
    let extra = readouts::notice_rows(notice, panel - 2) - readouts::NOTICE_ROWS;
    let top = readouts_height(side, report, extra);
    let [readouts, threads] =
        Layout::vertical([Constraint::Length(top), Constraint::Fill(1)]).areas(side);
    Some(Areas {
        canvas,
        readouts,
        threads,
        bar,
        main,
    })
}

/// Whole readouts when the threads still fit beside them (a row each, or
/// a grid with a cell each), else compact ones; `extra` rows more for a
/// long notice, as far as the threads can spare them.
fn readouts_height(side: Rect, report: &CpuReport, extra: u16) -> u16 {
    let inner_w = usize::from(side.width.saturating_sub(2));
    let threads = threads::full_height(report).min(threads::compact_height(report, inner_w));
    let top = if side.height >= readouts::HEIGHT + extra + threads {
        readouts::HEIGHT
    } else {
        readouts::COMPACT_HEIGHT
    };
    let spare = side.height.saturating_sub(top + threads);
    top + extra.min(spare)
}

pub fn draw(frame: &mut Frame, raster: &mut Raster, v: &View) {
    let area = frame.area();
    let panel = Readouts {
        state: v.state,
        snap: v.snap,
        stats: v.stats,
        palette: v.palette,
    };
    let Some(a) = areas_with(area, v.report, panel.notice().as_deref()) else {
        let msg: Vec<Line> =
            crate::tui::term::caps::size_message(area.width, area.height, (MIN_WIDTH, MIN_HEIGHT))
                .into_iter()
                .map(Line::from)
                .collect();
        let h = (msg.len() as u16).min(area.height);
        let r = Rect::new(area.x, area.y + (area.height - h) / 2, area.width, h);
        frame.render_widget(Paragraph::new(msg).centered(), r);
        return;
    };
    if v.state.chart {
        frame.render_widget(
            CpuChart {
                report: v.report,
                palette: v.palette,
            },
            a.canvas,
        );
    } else {
        let scene = Scene {
            box_size: v.snap.size,
            camera: v.state.camera,
            style: v.state.style,
            light: v.state.light,
            palette: v.palette,
            aspect: v.aspect,
        };
        raster.draw(&v.snap.spheres, &scene, a.canvas, frame.buffer_mut());
    }
    frame.render_widget(panel, a.readouts);
    frame.render_widget(
        Threads {
            report: v.report,
            palette: v.palette,
            by_cpu: v.state.threads_by_cpu,
            pool: threads::pool_line_of(v.snap),
        },
        a.threads,
    );
    frame.render_widget(HelpBar { palette: v.palette }, a.bar);
    if v.state.help {
        frame.render_widget(HelpOverlay { palette: v.palette }, a.main);
    }
}
