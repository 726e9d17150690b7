//! Colours: which palette the terminal gets, and the ramps the canvas uses.
//! 16 colours is the default because every colour change costs bytes on the
//! wire; 256 and truecolor are opt-in. With no colour, the canvas keeps its
//! cues in glyphs and the panels in reverse video.
use ratatui::style::{Color, Modifier, Style};
use strum::{EnumString, IntoStaticStr};

/// `--color`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, EnumString)]
pub enum ColorChoice {
    /// 16 colours if the terminal does colour at all; none with `NO_COLOR`.
    #[default]
    #[strum(serialize = "auto")]
    Auto,
    #[strum(serialize = "16")]
    C16,
    #[strum(serialize = "256")]
    C256,
    #[strum(serialize = "true", serialize = "truecolor", serialize = "24bit")]
    True,
}

/// What is really drawn with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, IntoStaticStr)]
pub enum Palette {
    #[strum(serialize = "none")]
    Mono,
    #[strum(serialize = "16")]
    C16,
    #[strum(serialize = "256")]
    C256,
    #[strum(serialize = "true")]
    True,
}

impl Palette {
    pub fn name(self) -> &'static str {
        self.into()
    }

    /// Resolve `--color` against the environment. An explicit flag wins over
    /// `NO_COLOR` (the `NO_COLOR` convention lets flags override it).
    pub fn resolve(choice: ColorChoice, env: &dyn Fn(&str) -> Option<String>) -> Palette {
        match choice {
            ColorChoice::C16 => Palette::C16,
            ColorChoice::C256 => Palette::C256,
            ColorChoice::True => Palette::True,
            ColorChoice::Auto => {
                if env("NO_COLOR").is_some_and(|v| !v.is_empty()) {
                    return Palette::Mono;
                }
                match Self::detect(env) {
                    Palette::Mono => Palette::Mono,
                    _ => Palette::C16,
                }
            }
        }
    }

    /// What the terminal says it can do (shown in the readouts, so the user
    /// knows which `--color` is worth trying).
    pub fn detect(env: &dyn Fn(&str) -> Option<String>) -> Palette {
        let colorterm = env("COLORTERM").unwrap_or_default().to_lowercase();
        let term = env("TERM").unwrap_or_default().to_lowercase();
        if colorterm.contains("truecolor") || colorterm.contains("24bit") {
            Palette::True
        } else if term.contains("256color") {
            Palette::C256
        } else if crate::tui::term::caps::monochrome(&term) {
            Palette::Mono
        } else {
            Palette::C16
        }
    }

    pub fn has_color(self) -> bool {
        self != Palette::Mono
    }

    /// A colour for a ramp position `t` in 0..=1 (cold → hot), at brightness
    /// `shade` in 0..=1.
    pub fn ramp(self, kind: Ramp, t: f32, shade: f32) -> Color {
        let t = t.clamp(0.0, 1.0);
        let shade = shade.clamp(0.0, 1.0);
        match self {
            Palette::Mono => Color::Reset,
            Palette::C16 => {
                let named = match kind {
                    Ramp::Speed => {
                        SPEED16[((t * SPEED16.len() as f32) as usize).min(SPEED16.len() - 1)]
                    }
                    Ramp::Depth => {
                        DEPTH16[((t * DEPTH16.len() as f32) as usize).min(DEPTH16.len() - 1)]
                    }
                };
                if shade < 0.2 {
                    Color::DarkGray
                } else if shade < 0.6 {
                    dim16(named)
                } else {
                    named
                }
            }
            Palette::C256 => {
                let [r, g, b] = rgb(kind, t, shade);
                let q = |c: u8| (u16::from(c) * 5 + 127) / 255;
                Color::Indexed((16 + 36 * q(r) + 6 * q(g) + q(b)) as u8)
            }
            Palette::True => {
                let [r, g, b] = rgb(kind, t, shade);
                Color::Rgb(r, g, b)
            }
        }
    }

    /// The cube's edges.
    pub fn edge(self) -> Color {
        match self {
            Palette::Mono => Color::Reset,
            Palette::C16 => Color::Gray,
            Palette::C256 => Color::Indexed(245),
            Palette::True => Color::Rgb(150, 150, 150),
        }
    }

    /// Emphasis that survives without colour.
    pub fn alert(self) -> Style {
        if self.has_color() {
            Style::new().fg(Color::Yellow).add_modifier(Modifier::BOLD)
        } else {
            Style::new().add_modifier(Modifier::REVERSED)
        }
    }

    pub fn label(self) -> Style {
        if self.has_color() {
            Style::new().fg(Color::Cyan)
        } else {
            Style::new()
        }
    }

    pub fn key(self) -> Style {
        Style::new().add_modifier(Modifier::REVERSED)
    }

    /// A thread's load: red when near full, yellow past half, green below.
    pub fn load(self, percent: f64) -> Style {
        if !self.has_color() {
            return Style::new();
        }
        let c = if percent >= 85.0 {
            Color::LightRed
        } else if percent >= 50.0 {
            Color::Yellow
        } else {
            Color::Green
        };
        Style::new().fg(c)
    }
}

/// The CPU chart's lines: eight hues a 16-colour terminal tells apart (no
/// dark twin of a light one).
pub const LINE_COLOURS: [Color; 8] = [
    Color::LightRed,
    Color::LightGreen,
    Color::LightYellow,
    Color::LightBlue,
    Color::LightMagenta,
    Color::LightCyan,
    Color::White,
    Color::Gray,
];

/// What a sphere's colour says.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ramp {
    Speed,
    Depth,
}

// Few classes on purpose: neighbouring cells share a colour more often, and
// every colour change is bytes on the wire.
const SPEED16: [Color; 3] = [Color::LightBlue, Color::LightGreen, Color::LightRed];
// Near is 1, far is 0.
const DEPTH16: [Color; 4] = [Color::Blue, Color::Cyan, Color::LightCyan, Color::White];

fn dim16(c: Color) -> Color {
    match c {
        Color::LightBlue => Color::Blue,
        Color::LightCyan => Color::Cyan,
        Color::LightGreen => Color::Green,
        Color::LightYellow => Color::Yellow,
        Color::LightRed => Color::Red,
        Color::White => Color::Gray,
        other => other,
    }
}

fn rgb(kind: Ramp, t: f32, shade: f32) -> [u8; 3] {
    let stops: &[[f32; 3]] = match kind {
        Ramp::Speed => &[
            [40.0, 80.0, 255.0],
            [0.0, 220.0, 255.0],
            [40.0, 230.0, 60.0],
            [255.0, 230.0, 0.0],
            [255.0, 40.0, 20.0],
        ],
        Ramp::Depth => &[
            [20.0, 40.0, 140.0],
            [60.0, 160.0, 220.0],
            [240.0, 250.0, 255.0],
        ],
    };
    let x = t * (stops.len() - 1) as f32;
    let i = (x as usize).min(stops.len() - 2);
    let f = x - i as f32;
    let mut out = [0u8; 3];
    for k in 0..3 {
        let c = stops[i][k] + (stops[i + 1][k] - stops[i][k]) * f;
        out[k] = (c * (0.15 + 0.85 * shade)).round().clamp(0.0, 255.0) as u8;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn env_of(pairs: &'static [(&'static str, &'static str)]) -> impl Fn(&str) -> Option<String> {
        move |k| {
            pairs
                .iter()
                .find(|(n, _)| *n == k)
                .map(|(_, v)| v.to_string())
        }
    }

    #[test]
    fn colour_names_read_and_print_as_the_command_line_writes_them() {
        for (text, want) in [
            ("auto", ColorChoice::Auto),
            ("16", ColorChoice::C16),
            ("256", ColorChoice::C256),
            ("true", ColorChoice::True),
            ("truecolor", ColorChoice::True),
            ("24bit", ColorChoice::True),
        ] {
            assert_eq!(text.parse(), Ok(want), "{text}");
        }
        for bad in ["", "Auto", "8", "none"] {
            assert!(bad.parse::<ColorChoice>().is_err(), "{bad}");
        }
        let names: Vec<_> = [Palette::Mono, Palette::C16, Palette::C256, Palette::True]
            .map(Palette::name)
            .into();
        assert_eq!(names, ["none", "16", "256", "true"]);
    }

    #[test]
    fn auto_is_16_colours_on_a_colour_terminal_and_none_with_no_color() {
        let e = env_of(&[("TERM", "xterm-256color"), ("COLORTERM", "truecolor")]);
        assert_eq!(Palette::resolve(ColorChoice::Auto, &e), Palette::C16);
        assert_eq!(Palette::detect(&e), Palette::True);
        let e = env_of(&[("TERM", "xterm-256color"), ("NO_COLOR", "1")]);
        assert_eq!(Palette::resolve(ColorChoice::Auto, &e), Palette::Mono);
        assert_eq!(Palette::resolve(ColorChoice::C256, &e), Palette::C256);
        let e = env_of(&[("TERM", "dumb")]);
        assert_eq!(Palette::resolve(ColorChoice::Auto, &e), Palette::Mono);
        let e = env_of(&[("TERM", "xterm-256color")]);
        assert_eq!(Palette::detect(&e), Palette::C256);
    }

    #[test]
    fn ramps_go_from_cold_to_hot_and_dim_with_shade() {
        assert_eq!(Palette::C16.ramp(Ramp::Speed, 0.0, 1.0), Color::LightBlue);
        assert_eq!(Palette::C16.ramp(Ramp::Speed, 1.0, 1.0), Color::LightRed);
        assert_eq!(Palette::C16.ramp(Ramp::Speed, 1.0, 0.4), Color::Red);
        assert_eq!(
            Palette::True.ramp(Ramp::Speed, 1.0, 1.0),
            Color::Rgb(255, 40, 20)
        );
        assert_eq!(
            Palette::C256.ramp(Ramp::Speed, 0.0, 1.0),
            Color::Indexed(69)
        );
        assert_eq!(Palette::Mono.ramp(Ramp::Depth, 0.5, 0.5), Color::Reset);
    }
}
