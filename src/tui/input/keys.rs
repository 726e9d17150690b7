//! The one key table: dispatch (`lookup`), the `?` overlay, the key
//! bar and the README check (`tests/app/readme_keys.rs`) all read `TABLE`, so a
//! key cannot be added in one place and forgotten in another.

/// What a key asks for; `TABLE` binds the keys to them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Action {
    Quit,
    /// Esc: closes the help if it is open, else the chart, else quits.
    Escape,
    ToggleThreading,
    CycleThreadedMode,
    FewerThreads,
    MoreThreads,
    /// Flat out (tick `max`) on/off, back to the tick before.
    FlatOut,
    TickDown,
    TickUp,
    Pause,
    HalveCount,
    DoubleCount,
    Smaller,
    Bigger,
    CycleModel,
    /// `auto`'s tolerance one step of `Tolerance::LADDER` down / up.
    Tighter,
    Looser,
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
    /// Swap the canvas for the chart of per-thread CPU, and back.
    Chart,
    /// Ctrl-Z: give the terminal back and stop (the input thread acts on it).
    Suspend,
    /// Sort the thread panel by CPU, and back to its fixed order.
    SortThreads,
}

/// A key as the table names it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Press {
    Char(char),
    Esc,
    Left,
    Right,
    Up,
    Down,
    /// With Control held (the letter in lower case).
    Ctrl(char),
}

impl Press {
    fn is_arrow(self) -> bool {
        matches!(self, Press::Left | Press::Right | Press::Up | Press::Down)
    }

    /// The name the README's "## Keys" table uses: `q`, `space`, `Esc`,
    /// `Ctrl-C`, and `←` `→` `↑` `↓` for the arrow keys.
    pub fn doc_name(self) -> String {
        match self {
            Press::Ctrl(c) => format!("Ctrl-{}", c.to_ascii_uppercase()),
            other => other.short(),
        }
    }

    /// The short form for the bar and the overlay.
    fn short(self) -> String {
        match self {
            Press::Char(' ') => "space".into(),
            Press::Char(c) => c.to_string(),
            Press::Esc => "Esc".into(),
            Press::Ctrl(c) => format!("^{}", c.to_ascii_uppercase()),
            Press::Left => "←".into(),
            Press::Right => "→".into(),
            Press::Up => "↑".into(),
            Press::Down => "↓".into(),
        }
    }
}

/// One line of help: the keys, what each does, and its place in the bar.
#[derive(Debug)]
pub struct Binding {
    pub presses: &'static [(Press, Action)],
    /// The `?` overlay's description.
    pub help: &'static str,
    /// The key bar's label and rank (0 is kept first when columns run out).
    pub bar: Option<(&'static str, u8)>,
}

impl Binding {
    /// The keys as the overlay shows them: `p/P`, `q/Esc/^C`, `arrows`.
    pub fn keys(&self) -> String {
        if self.presses.iter().all(|(p, _)| p.is_arrow()) {
            return "arrows".into();
        }
        let names: Vec<String> = self.presses.iter().map(|(p, _)| p.short()).collect();
        names.join("/")
    }

    /// The keys as the bar shows them (shorter where it can be).
    pub fn bar_keys(&self) -> String {
        if self.presses.iter().all(|(p, _)| p.is_arrow()) {
            return self.presses.iter().map(|(p, _)| p.short()).collect();
        }
        match self.presses {
            [(Press::Char(' '), _)] => "spc".into(),
            // The bar has no room for every way to quit; the overlay lists them.
            [(first, _), ..] if *first == Press::Char('q') => "q".into(),
            _ => self.keys(),
        }
    }
}

use Action as A;
use Press as K;

pub const TABLE: &[Binding] = &[
    Binding {
        presses: &[(K::Char('?'), A::Help)],
        help: "this help",
        bar: Some(("help", 0)),
    },
    Binding {
        presses: &[
            (K::Char('q'), A::Quit),
            (K::Esc, A::Escape),
            (K::Ctrl('c'), A::Quit),
        ],
        help: "quit (Esc first closes the help, then the chart)",
        bar: Some(("quit", 1)),
    },
    Binding {
        presses: &[(K::Char('t'), A::ToggleThreading)],
        help: "threading on/off (off <-> last threaded mode)",
        bar: Some(("thread", 2)),
    },
    Binding {
        presses: &[(K::Char('d'), A::CycleThreadedMode)],
        help: "cycle threaded mode: worker -> pool -> split",
        bar: Some(("mode", 3)),
    },
    Binding {
        presses: &[
            (K::Char('p'), A::FewerThreads),
            (K::Char('P'), A::MoreThreads),
        ],
        help: "pool threads - / + (used in pool mode)",
        bar: Some(("pool", 5)),
    },
    Binding {
        presses: &[(K::Char('c'), A::Chart)],
        help: "chart of per-thread CPU, last minute / canvas",
        bar: Some(("chart", 4)),
    },
    Binding {
        presses: &[(K::Char('s'), A::SortThreads)],
        help: "threads panel: sort by CPU / by role",
        bar: Some(("sort", 16)),
    },
    Binding {
        presses: &[(K::Char('x'), A::FlatOut)],
        help: "flat out on/off: as many steps as a frame allows",
        bar: Some(("flat", 2)),
    },
    Binding {
        presses: &[(K::Char('['), A::TickDown), (K::Char(']'), A::TickUp)],
        help: "physics tick - / + (0 freezes; max 1000000)",
        bar: Some(("tick", 7)),
    },
    Binding {
        presses: &[(K::Char(' '), A::Pause)],
        help: "pause / resume",
        bar: Some(("pause", 6)),
    },
    Binding {
        presses: &[
            (K::Char('n'), A::HalveCount),
            (K::Char('N'), A::DoubleCount),
        ],
        help: "sphere count /2 / x2",
        bar: Some(("count", 8)),
    },
    Binding {
        presses: &[(K::Char('r'), A::Smaller), (K::Char('R'), A::Bigger)],
        help: "sphere radius smaller / bigger",
        bar: Some(("size", 9)),
    },
    Binding {
        presses: &[(K::Char('m'), A::CycleModel)],
        help: "cycle collision model",
        bar: Some(("model", 10)),
    },
    Binding {
        presses: &[(K::Char('<'), A::Tighter), (K::Char('>'), A::Looser)],
        help: "auto's tolerance - / + (sinking, in radii)",
        bar: Some(("tol", 17)),
    },
    Binding {
        presses: &[
            (K::Left, A::Left),
            (K::Right, A::Right),
            (K::Up, A::Up),
            (K::Down, A::Down),
        ],
        help: "rotate the camera",
        bar: Some(("camera", 12)),
    },
    Binding {
        presses: &[(K::Char('v'), A::CycleStyle)],
        help: "cycle drawing style (braille / shaded blocks)",
        bar: Some(("style", 11)),
    },
    Binding {
        presses: &[(K::Char('l'), A::MoveLight)],
        help: "move the light (shaded style)",
        bar: Some(("light", 14)),
    },
    Binding {
        presses: &[(K::Char('0'), A::Reset)],
        help: "reset the scene",
        bar: Some(("reset", 13)),
    },
    Binding {
        presses: &[(K::Char('f'), A::SlowerFps), (K::Char('F'), A::FasterFps)],
        help: "frame rate - / +",
        bar: Some(("fps", 15)),
    },
    Binding {
        presses: &[(K::Ctrl('z'), A::Suspend)],
        help: "suspend (fg resumes)",
        bar: None,
    },
];

/// What `press` does, if anything.
pub fn lookup(press: Press) -> Option<Action> {
    TABLE
        .iter()
        .flat_map(|b| b.presses)
        .find(|(p, _)| *p == press)
        .map(|&(_, a)| a)
}

/// The bar's entries that fit in `width` columns, the most useful first
/// chosen, shown in table order. Each takes `keys label ` columns.
pub fn bar_entries(width: usize) -> Vec<(String, &'static str)> {
    let mut ranked: Vec<(usize, u8, String, &'static str)> = TABLE
        .iter()
        .enumerate()
        .filter_map(|(i, b)| b.bar.map(|(label, rank)| (i, rank, b.bar_keys(), label)))
        .collect();
    ranked.sort_by_key(|e| e.1);
    let mut used = 0;
    let mut chosen = Vec::new();
    for e in ranked {
        let w = bar_width(&e.2, e.3);
        if used + w <= width + 1 {
            used += w;
            chosen.push(e);
        }
    }
    chosen.sort_by_key(|e| e.0);
    chosen.into_iter().map(|e| (e.2, e.3)).collect()
}

/// Columns one bar entry takes, its trailing space included.
pub fn bar_width(keys: &str, label: &str) -> usize {
    keys.chars().count() + 1 + label.len() + 1
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_design_key_maps_to_its_action() {
        let table = [
            (Press::Char('q'), Action::Quit),
            (Press::Esc, Action::Escape),
            (Press::Char('t'), Action::ToggleThreading),
            (Press::Char('d'), Action::CycleThreadedMode),
            (Press::Char('p'), Action::FewerThreads),
            (Press::Char('P'), Action::MoreThreads),
            (Press::Char('['), Action::TickDown),
            (Press::Char(']'), Action::TickUp),
            (Press::Char(' '), Action::Pause),
            (Press::Char('n'), Action::HalveCount),
            (Press::Char('N'), Action::DoubleCount),
            (Press::Char('r'), Action::Smaller),
            (Press::Char('R'), Action::Bigger),
            (Press::Char('m'), Action::CycleModel),
            (Press::Char('<'), Action::Tighter),
            (Press::Char('>'), Action::Looser),
            (Press::Left, Action::Left),
            (Press::Right, Action::Right),
            (Press::Up, Action::Up),
            (Press::Down, Action::Down),
            (Press::Char('v'), Action::CycleStyle),
            (Press::Char('l'), Action::MoveLight),
            (Press::Char('0'), Action::Reset),
            (Press::Char('?'), Action::Help),
            (Press::Char('f'), Action::SlowerFps),
            (Press::Char('F'), Action::FasterFps),
            (Press::Char('c'), Action::Chart),
            (Press::Char('s'), Action::SortThreads),
            (Press::Char('x'), Action::FlatOut),
        ];
        for (press, want) in table {
            assert_eq!(lookup(press), Some(want), "{press:?}");
        }
        assert_eq!(lookup(Press::Ctrl('c')), Some(Action::Quit));
        assert_eq!(lookup(Press::Char('y')), None);
        assert_eq!(lookup(Press::Ctrl('t')), None);
    }

    #[test]
    fn no_key_is_bound_twice() {
        let all: Vec<Press> = TABLE
            .iter()
            .flat_map(|b| b.presses.iter().map(|p| p.0))
            .collect();
        for (i, p) in all.iter().enumerate() {
            assert!(!all[i + 1..].contains(p), "{p:?} bound twice");
        }
    }

    #[test]
    fn the_bar_keeps_the_first_ranks_and_fits() {
        for width in [20, 40, 80, 120, 200] {
            let e = bar_entries(width);
            let used: usize = e.iter().map(|(k, l)| bar_width(k, l)).sum();
            assert!(used <= width + 1, "{width}: {used}");
            assert_eq!(e[0], ("?".to_string(), "help"));
        }
        let at80: Vec<&str> = bar_entries(80).iter().map(|e| e.1).collect();
        for must in ["help", "quit", "thread", "mode", "chart", "pool", "pause"] {
            assert!(at80.contains(&must), "{must} missing at 80: {at80:?}");
        }
        let with_bar = TABLE.iter().filter(|b| b.bar.is_some()).count();
        assert_eq!(bar_entries(200).len(), with_bar);
    }
}
