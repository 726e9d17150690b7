//! The bytes that go to the terminal: one buffered write per frame, wrapped
//! in synchronized output (DEC mode 2026) so a slow link never shows half a
//! frame, and counted so the readouts can say what a frame costs.
use super::escapes::{MoveRight, MoveTo, RESET_ATTRIBUTES, Sgr};
use crossterm::queue;
use ratatui::backend::{Backend, ClearType, CrosstermBackend, WindowSize};
use ratatui::buffer::Cell;
use ratatui::layout::{Position, Size};
use ratatui::style::{Color, Modifier};
use std::io::{self, Write};
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

/// Counts every byte passed to the inner writer.
pub struct Counting<W: Write> {
    inner: W,
    count: Arc<AtomicU64>,
}

impl<W: Write> Counting<W> {
    pub fn new(inner: W) -> (Counting<W>, Arc<AtomicU64>) {
        let count = Arc::new(AtomicU64::new(0));
        (
            Counting {
                inner,
                count: count.clone(),
            },
            count,
        )
    }
}

impl<W: Write> Write for Counting<W> {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        let n = self.inner.write(buf)?;
        self.count.fetch_add(n as u64, Ordering::Relaxed);
        Ok(n)
    }
    fn flush(&mut self) -> io::Result<()> {
        self.inner.flush()
    }
}

/// A ratatui backend that writes the cells of a frame in fewer bytes than
/// crossterm's: short SGR codes for the 16 basic colours, only the colour
/// that changed, relative moves along a row, and no attribute reset after
/// every frame. Everything but `draw` is crossterm's.
pub struct Lean<W: Write> {
    inner: CrosstermBackend<W>,
    /// Where the cursor was last put: ratatui asks for it on a clear, and
    /// asking the terminal is a round trip whose answer the input thread
    /// would take.
    cursor: Position,
    /// Colours are written (not for a terminal that has none).
    colours: bool,
    /// What the terminal's SGR state is known to be.
    fg: Color,
    bg: Color,
    modifier: Modifier,
}

impl<W: Write> Lean<W> {
    pub fn new(writer: W) -> Lean<W> {
        Lean {
            inner: CrosstermBackend::new(writer),
            cursor: Position::ORIGIN,
            colours: true,
            fg: Color::Reset,
            bg: Color::Reset,
            modifier: Modifier::empty(),
        }
    }

    /// No colour escape ever: the terminal has no colours (attributes such
    /// as bold and reverse are kept).
    #[must_use]
    pub fn without_colours(mut self) -> Lean<W> {
        self.colours = false;
        self
    }

    /// Back to default colours (before clearing: a cleared screen takes the
    /// current background).
    fn reset_sgr(&mut self) -> io::Result<()> {
        if self.fg != Color::Reset || self.bg != Color::Reset || !self.modifier.is_empty() {
            self.inner.write_all(RESET_ATTRIBUTES)?;
            self.fg = Color::Reset;
            self.bg = Color::Reset;
            self.modifier = Modifier::empty();
        }
        Ok(())
    }
}

/// SGR parameters for a colour (foreground `base` 30, background 40).
fn push_colour(out: &mut String, c: Color, base: u8) {
    use std::fmt::Write as _;
    let basic = |n: u8| if n < 8 { base + n } else { base + 60 + n - 8 };
    let _ = match c {
        Color::Reset => write!(out, "{}", base + 9),
        Color::Black => write!(out, "{}", basic(0)),
        Color::Red => write!(out, "{}", basic(1)),
        Color::Green => write!(out, "{}", basic(2)),
        Color::Yellow => write!(out, "{}", basic(3)),
        Color::Blue => write!(out, "{}", basic(4)),
        Color::Magenta => write!(out, "{}", basic(5)),
        Color::Cyan => write!(out, "{}", basic(6)),
        Color::Gray => write!(out, "{}", basic(7)),
        Color::DarkGray => write!(out, "{}", basic(8)),
        Color::LightRed => write!(out, "{}", basic(9)),
        Color::LightGreen => write!(out, "{}", basic(10)),
        Color::LightYellow => write!(out, "{}", basic(11)),
        Color::LightBlue => write!(out, "{}", basic(12)),
        Color::LightMagenta => write!(out, "{}", basic(13)),
        Color::LightCyan => write!(out, "{}", basic(14)),
        Color::White => write!(out, "{}", basic(15)),
        Color::Indexed(n) => write!(out, "{};5;{n}", base + 8),
        Color::Rgb(r, g, b) => write!(out, "{};2;{r};{g};{b}", base + 8),
    };
}

const MODIFIER_CODES: [(Modifier, u8); 9] = [
    (Modifier::BOLD, 1),
    (Modifier::DIM, 2),
    (Modifier::ITALIC, 3),
    (Modifier::UNDERLINED, 4),
    (Modifier::SLOW_BLINK, 5),
    (Modifier::RAPID_BLINK, 6),
    (Modifier::REVERSED, 7),
    (Modifier::HIDDEN, 8),
    (Modifier::CROSSED_OUT, 9),
];

impl<W: Write> Backend for Lean<W> {
    type Error = io::Error;

    fn draw<'a, I>(&mut self, content: I) -> io::Result<()>
    where
        I: Iterator<Item = (u16, u16, &'a Cell)>,
    {
        use std::fmt::Write as _;
        let mut out: Vec<u8> = Vec::with_capacity(16 * 1024);
        let mut cursor: Option<(u16, u16)> = None;
        let mut sgr = String::with_capacity(32);
        for (x, y, cell) in content {
            match cursor {
                Some((cx, cy)) if cy == y && cx == x => {}
                Some((cx, cy)) if cy == y && cx < x => {
                    let _ = queue!(out, MoveRight(x - cx));
                }
                _ => {
                    let _ = queue!(out, MoveTo { x, y });
                }
            }
            sgr.clear();
            if !(self.modifier - cell.modifier).is_empty() {
                // Something to switch off: start from scratch.
                sgr.push('0');
                self.fg = Color::Reset;
                self.bg = Color::Reset;
                self.modifier = Modifier::empty();
            }
            let switched_on = MODIFIER_CODES
                .into_iter()
                .filter(|&(m, _)| cell.modifier.contains(m) && !self.modifier.contains(m));
            for (_, code) in switched_on {
                if !sgr.is_empty() {
                    sgr.push(';');
                }
                let _ = write!(sgr, "{code}");
            }
            self.modifier = cell.modifier;
            let (fg, bg) = if self.colours {
                (cell.fg, cell.bg)
            } else {
                (Color::Reset, Color::Reset)
            };
            if fg != self.fg {
                if !sgr.is_empty() {
                    sgr.push(';');
                }
                push_colour(&mut sgr, fg, 30);
                self.fg = fg;
            }
            if bg != self.bg {
                if !sgr.is_empty() {
                    sgr.push(';');
                }
                push_colour(&mut sgr, bg, 40);
                self.bg = bg;
            }
            if !sgr.is_empty() {
                let _ = queue!(out, Sgr(&sgr));
            }
            let symbol = cell.symbol();
            out.extend_from_slice(symbol.as_bytes());
            let width = unicode_width::UnicodeWidthStr::width(symbol);
            // Unknown widths: place the next cell absolutely.
            cursor = (width == 1).then(|| (x + 1, y));
        }
        self.inner.write_all(&out)
    }

    fn hide_cursor(&mut self) -> io::Result<()> {
        self.inner.hide_cursor()
    }
    fn show_cursor(&mut self) -> io::Result<()> {
        self.inner.show_cursor()
    }
    fn get_cursor_position(&mut self) -> io::Result<Position> {
        Ok(self.cursor)
    }
    fn set_cursor_position<P: Into<Position>>(&mut self, position: P) -> io::Result<()> {
        self.cursor = position.into();
        self.inner.set_cursor_position(self.cursor)
    }
    fn clear(&mut self) -> io::Result<()> {
        self.reset_sgr()?;
        self.inner.clear()
    }
    fn clear_region(&mut self, clear_type: ClearType) -> io::Result<()> {
        self.reset_sgr()?;
        self.inner.clear_region(clear_type)
    }
    fn append_lines(&mut self, n: u16) -> io::Result<()> {
        self.inner.append_lines(n)
    }
    fn size(&self) -> io::Result<Size> {
        self.inner.size()
    }
    fn window_size(&mut self) -> io::Result<WindowSize> {
        self.inner.window_size()
    }
    fn flush(&mut self) -> io::Result<()> {
        Backend::flush(&mut self.inner)
    }
}

impl<W: Write> Write for Lean<W> {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.inner.write(buf)
    }
    fn flush(&mut self) -> io::Result<()> {
        Write::flush(&mut self.inner)
    }
}

/// Where a frame is built before it goes to the `output` thread; clones
/// share the bytes.
#[derive(Clone, Default)]
pub struct Sink(std::rc::Rc<std::cell::RefCell<Vec<u8>>>);

impl Sink {
    /// The bytes written so far, leaving it empty.
    pub fn take(&self) -> Vec<u8> {
        std::mem::take(&mut *self.0.borrow_mut())
    }
}

impl Write for Sink {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.0.borrow_mut().extend_from_slice(buf);
        Ok(buf.len())
    }
    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_what_passes_through() {
        let (mut w, count) = Counting::new(Vec::new());
        w.write_all(b"hello").unwrap();
        w.write_all(b"\x1b[?2026h").unwrap();
        assert_eq!(count.load(Ordering::Relaxed), 5 + 8);
        assert_eq!(w.inner.len(), 13);
    }

    impl Sink {
        fn text(&self) -> String {
            String::from_utf8(self.0.borrow().clone()).unwrap()
        }
    }

    #[test]
    fn frames_use_short_codes_relative_moves_and_only_changed_colours() {
        let sink = Sink::default();
        let mut b = Lean::new(sink.clone());
        let mut cells = [
            Cell::new("a"),
            Cell::new("b"),
            Cell::new("c"),
            Cell::new("d"),
        ];
        cells[0].set_fg(Color::LightRed);
        cells[1].set_fg(Color::LightRed).set_bg(Color::Blue);
        cells[2].set_fg(Color::Rgb(1, 2, 3)).set_bg(Color::Blue);
        cells[3]
            .set_fg(Color::Indexed(200))
            .set_style(ratatui::style::Style::new().add_modifier(Modifier::REVERSED));
        let content = [
            (0u16, 0u16, &cells[0]),
            (1, 0, &cells[1]),
            (5, 0, &cells[2]),
            (2, 3, &cells[3]),
        ];
        b.draw(content.into_iter()).unwrap();
        let written = sink.text();
        assert_eq!(
            written,
            "\x1b[1;1H\x1b[91ma\x1b[44mb\x1b[3C\x1b[38;2;1;2;3mc\x1b[4;3H\x1b[7;38;5;200;49md"
        );
        // The state carries over: the same colours again cost nothing.
        let sink = Sink::default();
        let mut b2 = Lean::new(sink.clone());
        b2.draw([(0u16, 0u16, &cells[0]), (0, 1, &cells[0])].into_iter())
            .unwrap();
        let written = sink.text();
        assert_eq!(written, "\x1b[1;1H\x1b[91ma\x1b[2;1Ha");
    }
}
