//! Keys to actions (docs/design.md, Keys). Kept apart from the state so the state
//! can be tested without a terminal.
use super::keys::{self, Action, Press};
use crossterm::event::{KeyCode, KeyEvent, KeyEventKind, KeyModifiers};

/// The key a press means, if any (releases are ignored). The keys are in
/// `keys::TABLE`, the one place that lists them.
pub fn action(key: KeyEvent) -> Option<Action> {
    if key.kind == KeyEventKind::Release {
        return None;
    }
    let press = if key.modifiers.contains(KeyModifiers::CONTROL) {
        match key.code {
            KeyCode::Char(c) => Press::Ctrl(c.to_ascii_lowercase()),
            _ => return None,
        }
    } else {
        match key.code {
            KeyCode::Char(c) => Press::Char(c),
            KeyCode::Esc => Press::Esc,
            KeyCode::Left => Press::Left,
            KeyCode::Right => Press::Right,
            KeyCode::Up => Press::Up,
            KeyCode::Down => Press::Down,
            _ => return None,
        }
    };
    keys::lookup(press)
}

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
            (KeyCode::Char('<'), Action::Tighter),
            (KeyCode::Char('>'), Action::Looser),
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
            (KeyCode::Char('c'), Action::Chart),
            (KeyCode::Char('s'), Action::SortThreads),
            (KeyCode::Char('x'), Action::FlatOut),
        ];
        for (code, want) in table {
            assert_eq!(action(press(code)), Some(want), "{code:?}");
        }
        let ctrl_c = KeyEvent::new(KeyCode::Char('c'), KeyModifiers::CONTROL);
        assert_eq!(action(ctrl_c), Some(Action::Quit));
        let ctrl_shift_c = KeyEvent::new(
            KeyCode::Char('C'),
            KeyModifiers::CONTROL | KeyModifiers::SHIFT,
        );
        assert_eq!(action(ctrl_shift_c), Some(Action::Quit));
        assert_eq!(action(press(KeyCode::Char('y'))), None);
        let ctrl_t = KeyEvent::new(KeyCode::Char('t'), KeyModifiers::CONTROL);
        assert_eq!(action(ctrl_t), None);
        let mut release = press(KeyCode::Char('q'));
        release.kind = KeyEventKind::Release;
        assert_eq!(action(release), None);
    }
}
