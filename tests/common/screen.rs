//! The app's screen drawn on ratatui's `TestBackend`, for the tests that
//! draw it: the settings they start from, and the drawn cells as text.
use ballpit::engine::{Settings, Threading};
use ballpit::physics::ModelKind;
use ratatui::Terminal;
use ratatui::backend::TestBackend;

/// `swept` at 60 steps a second, one step a frame, threading off, with
/// `threads` for the modes that would use them.
pub fn settings(threads: usize) -> Settings {
    Settings {
        model: ModelKind::Swept,
        dt: 1.0 / 60.0,
        tick: 1,
        threading: Threading::Off,
        threads,
    }
}

/// The screen's rows as text, a cell's symbol after another.
pub fn rows(t: &Terminal<TestBackend>) -> Vec<String> {
    let buf = t.backend().buffer();
    (0..buf.area.height)
        .map(|y| (0..buf.area.width).map(|x| buf[(x, y)].symbol()).collect())
        .collect()
}

/// The whole screen as one line of text: the rows run together.
pub fn text(t: &Terminal<TestBackend>) -> String {
    rows(t).concat()
}
