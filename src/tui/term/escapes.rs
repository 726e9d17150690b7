//! Every escape sequence the app writes itself, named once. crossterm's
//! commands cover the rest; these are the ones it lacks or spells with other
//! bytes (`MoveRight(1)` is `ESC [ C` here, as short as a move can be).
use crossterm::Command;
use std::fmt;

/// All attributes and colours back to the terminal's defaults (SGR 0).
pub const RESET_ATTRIBUTES: &[u8] = b"\x1b[0m";
/// Pasted text arrives bracketed, so it is not taken for key presses.
pub const PASTE_ON: &[u8] = b"\x1b[?2004h";
pub const PASTE_OFF: &[u8] = b"\x1b[?2004l";
/// A device status request: the terminal answers `ESC [ 0 n` once it has
/// processed everything before it (the pacing's round-trip probe).
pub const STATUS_QUERY: &[u8] = b"\x1b[5n";

/// The cursor `n` columns right (CUF), the one-column case without its count.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MoveRight(pub u16);

/// The cursor to column `x`, row `y`, counted from 0 (CUP).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MoveTo {
    pub x: u16,
    pub y: u16,
}

/// Select graphic rendition with parameters already joined by `;`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Sgr<'a>(pub &'a str);

impl Command for MoveRight {
    fn write_ansi(&self, f: &mut impl fmt::Write) -> fmt::Result {
        match self.0 {
            1 => f.write_str("\x1b[C"),
            n => write!(f, "\x1b[{n}C"),
        }
    }
}

impl Command for MoveTo {
    fn write_ansi(&self, f: &mut impl fmt::Write) -> fmt::Result {
        write!(
            f,
            "\x1b[{};{}H",
            u32::from(self.y) + 1,
            u32::from(self.x) + 1
        )
    }
}

impl Command for Sgr<'_> {
    fn write_ansi(&self, f: &mut impl fmt::Write) -> fmt::Result {
        write!(f, "\x1b[{}m", self.0)
    }
}

#[cfg(test)]
mod tests {
    use super::{MoveRight, MoveTo, Sgr};
    use crossterm::queue;

    #[test]
    fn the_commands_write_the_bytes_the_screen_diff_was_pinned_to() {
        let mut out = Vec::new();
        queue!(
            out,
            MoveRight(1),
            MoveRight(3),
            MoveTo { x: 0, y: 0 },
            MoveTo { x: 2, y: 3 },
            Sgr("7;38;5;200;49")
        )
        .unwrap();
        assert_eq!(out, b"\x1b[C\x1b[3C\x1b[1;1H\x1b[4;3H\x1b[7;38;5;200;49m");
    }
}
