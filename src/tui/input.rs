//! Keys to actions (docs/design.md, Keys). Kept apart from the state so the state
//! can be tested without a terminal.
use crossterm::event::{KeyCode, KeyEvent, KeyEventKind, KeyModifiers};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Action {
    Quit,
    /// Esc: closes the help if it is open, else quits.
    Escape,
    ToggleThreading,
    CycleThreadedMode,
    FewerThreads,
    MoreThreads,
    TickDown,
    TickUp,
    Pause,
    HalveCount,
    DoubleCount,
    Smaller,
    Bigger,
    CycleModel,
    Left,
    Right,
    Up,
    Down,
    CycleStyle,
    MoveLight,
    Reset,
    Help,
    SlowerFps,
    FasterFps,
}

/// The key a press means, if any (releases and repeats of modifiers are ignored).
pub fn action(key: KeyEvent) -> Option<Action> {
    if key.kind == KeyEventKind::Release {
        return None;
    }
    if key.modifiers.contains(KeyModifiers::CONTROL) {
        return match key.code {
            KeyCode::Char('c') | KeyCode::Char('C') => Some(Action::Quit),
            _ => None,
        };
    }
    Some(match key.code {
        KeyCode::Char('q') => Action::Quit,
        KeyCode::Esc => Action::Escape,
        KeyCode::Char('t') => Action::ToggleThreading,
        KeyCode::Char('d') => Action::CycleThreadedMode,
        KeyCode::Char('p') => Action::FewerThreads,
        KeyCode::Char('P') => Action::MoreThreads,
        KeyCode::Char('[') => Action::TickDown,
        KeyCode::Char(']') => Action::TickUp,
        KeyCode::Char(' ') => Action::Pause,
        KeyCode::Char('n') => Action::HalveCount,
        KeyCode::Char('N') => Action::DoubleCount,
        KeyCode::Char('r') => Action::Smaller,
        KeyCode::Char('R') => Action::Bigger,
        KeyCode::Char('m') => Action::CycleModel,
        KeyCode::Left => Action::Left,
        KeyCode::Right => Action::Right,
        KeyCode::Up => Action::Up,
        KeyCode::Down => Action::Down,
        KeyCode::Char('v') => Action::CycleStyle,
        KeyCode::Char('l') => Action::MoveLight,
        KeyCode::Char('0') => Action::Reset,
        KeyCode::Char('?') => Action::Help,
        KeyCode::Char('f') => Action::SlowerFps,
        KeyCode::Char('F') => Action::FasterFps,
        _ => return None,
    })
}

/// Every key with what it does: (keys, help-bar key and label, description
/// for the `?` overlay). The bar leaves out what doesn't fit in 120 columns;
/// `?` comes first so it is always there.
/// Key and label in the help bar, if it has room.
pub type BarEntry = Option<(&'static str, &'static str)>;

pub const KEYS: &[(&str, BarEntry, &str)] = &[
    ("?", Some(("?", "help")), "this help"),
    ("q Esc ^C", Some(("q", "quit")), "quit"),
    (
        "t",
        Some(("t", "thread")),
        "threading on/off (off <-> last threaded mode)",
    ),
    (
        "d",
        Some(("d", "mode")),
        "cycle threaded mode: worker -> pool -> split",
    ),
    ("p/P", Some(("p/P", "pool")), "pool threads - / +"),
    (
        "[/]",
        Some(("[/]", "tick")),
        "physics tick - / + (0 freezes)",
    ),
    ("space", Some(("spc", "pause")), "pause / resume"),
    ("n/N", Some(("n/N", "count")), "sphere count /2 / x2"),
    (
        "r/R",
        Some(("r/R", "size")),
        "sphere radius smaller / bigger",
    ),
    ("m", Some(("m", "model")), "cycle collision model"),
    ("arrows", Some(("←→↑↓", "camera")), "rotate the camera"),
    (
        "v",
        Some(("v", "style")),
        "cycle drawing style (braille / shaded blocks)",
    ),
    ("l", Some(("l", "light")), "move the light (shaded style)"),
    ("0", Some(("0", "reset")), "reset the scene"),
    ("f/F", None, "frame rate - / +"),
];

#[cfg(test)]
mod tests {
    use super::*;

    fn press(code: KeyCode) -> KeyEvent {
        KeyEvent::new(code, KeyModifiers::NONE)
    }

    #[test]
    fn every_design_key_maps_to_its_action() {
        let table = [
            (KeyCode::Char('q'), Action::Quit),
            (KeyCode::Esc, Action::Escape),
            (KeyCode::Char('t'), Action::ToggleThreading),
            (KeyCode::Char('d'), Action::CycleThreadedMode),
            (KeyCode::Char('p'), Action::FewerThreads),
            (KeyCode::Char('P'), Action::MoreThreads),
            (KeyCode::Char('['), Action::TickDown),
            (KeyCode::Char(']'), Action::TickUp),
            (KeyCode::Char(' '), Action::Pause),
            (KeyCode::Char('n'), Action::HalveCount),
            (KeyCode::Char('N'), Action::DoubleCount),
            (KeyCode::Char('r'), Action::Smaller),
            (KeyCode::Char('R'), Action::Bigger),
            (KeyCode::Char('m'), Action::CycleModel),
            (KeyCode::Left, Action::Left),
            (KeyCode::Right, Action::Right),
            (KeyCode::Up, Action::Up),
            (KeyCode::Down, Action::Down),
            (KeyCode::Char('v'), Action::CycleStyle),
            (KeyCode::Char('l'), Action::MoveLight),
            (KeyCode::Char('0'), Action::Reset),
            (KeyCode::Char('?'), Action::Help),
            (KeyCode::Char('f'), Action::SlowerFps),
            (KeyCode::Char('F'), Action::FasterFps),
        ];
        for (code, want) in table {
            assert_eq!(action(press(code)), Some(want), "{code:?}");
        }
        let ctrl_c = KeyEvent::new(KeyCode::Char('c'), KeyModifiers::CONTROL);
        assert_eq!(action(ctrl_c), Some(Action::Quit));
        assert_eq!(action(press(KeyCode::Char('x'))), None);
        let ctrl_t = KeyEvent::new(KeyCode::Char('t'), KeyModifiers::CONTROL);
        assert_eq!(action(ctrl_t), None);
        let mut release = press(KeyCode::Char('q'));
        release.kind = KeyEventKind::Release;
        assert_eq!(action(release), None);
    }
}
