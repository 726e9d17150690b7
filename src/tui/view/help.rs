//! The key bar (always there) and the `?` overlay (every key, explained),
//! both read from `keys::TABLE`.
use super::theme::Palette;
use crate::tui::input::keys::{self, TABLE};
use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Clear, Paragraph, Widget};

/// The keys that matter most at this width (`keys::bar_entries`).
pub struct HelpBar {
    pub palette: Palette,
}

impl Widget for HelpBar {
    fn render(self, area: Rect, buf: &mut Buffer) {
        let mut spans = Vec::new();
        for (key, label) in keys::bar_entries(usize::from(area.width)) {
            spans.push(Span::styled(key, self.palette.key()));
            spans.push(Span::raw(format!(" {label} ")));
        }
        Paragraph::new(Line::from(spans)).render(area, buf);
    }
}

pub struct HelpOverlay {
    pub palette: Palette,
}

/// Columns of the key column, its leading space included; one less in
/// two columns, where the widest keys (`q/Esc/^C`) still fit.
const KEY_W: usize = 10;
const KEY_W_NARROW: usize = 9;

/// One row of one column: the keys (on a binding's first row only) and a
/// piece of the description.
type Cell = (String, String);

/// The overlay's rows, each of one or two cells, and its outer size.
struct Layout {
    rows: Vec<Vec<Cell>>,
    key_w: usize,
    text_w: usize,
    size: (u16, u16),
}

impl HelpOverlay {
    /// One binding a row (" key      description ") while they fit `area`;
    /// else two columns side by side, the descriptions wrapped, the table
    /// cut where the two columns come out the most even.
    fn layout(area: Rect) -> Layout {
        let (aw, ah) = (usize::from(area.width), usize::from(area.height));
        let whole = TABLE
            .iter()
            .map(|b| KEY_W + 2 + b.help.chars().count())
            .max()
            .unwrap_or(40);
        if TABLE.len() + 2 <= ah && whole + 2 <= aw {
            let rows = TABLE.iter().map(|b| vec![(b.keys(), b.help.into())]);
            return Layout {
                rows: rows.collect(),
                key_w: KEY_W,
                text_w: whole - KEY_W - 1,
                size: (whole as u16 + 2, TABLE.len() as u16 + 2),
            };
        }
        let col_w = aw.saturating_sub(2) / 2;
        let text_w = col_w.saturating_sub(KEY_W_NARROW + 1).max(8);
        let cells: Vec<Vec<Cell>> = TABLE
            .iter()
            .map(|b| {
                let lines = wrap(b.help, text_w).into_iter().enumerate();
                let key = |i: usize| if i == 0 { b.keys() } else { String::new() };
                lines.map(|(i, t)| (key(i), t)).collect()
            })
            .collect();
        let total: usize = cells.iter().map(Vec::len).sum();
        let (mut left, mut best) = (0, (total, 0));
        for (k, c) in cells.iter().enumerate() {
            left += c.len();
            let tall = left.max(total - left);
            if tall < best.0 {
                best = (tall, k + 1);
            }
        }
        let (tall, cut) = best;
        let column = |cs: &[Vec<Cell>]| cs.concat().into_iter();
        let mut right = column(&cells[cut..]);
        let rows: Vec<Vec<Cell>> = column(&cells[..cut])
            .chain(std::iter::repeat_with(|| (String::new(), String::new())))
            .take(tall)
            .map(|l| [l].into_iter().chain(right.next()).collect())
            .collect();
        Layout {
            size: (area.width, tall as u16 + 2),
            rows,
            key_w: KEY_W_NARROW,
            text_w,
        }
    }
}

/// `text` in lines of at most `w` characters, broken at spaces (a longer
/// word stays whole and is clipped).
fn wrap(text: &str, w: usize) -> Vec<String> {
    let (mut lines, mut line) = (Vec::new(), String::new());
    for word in text.split(' ') {
        let n = line.chars().count();
        if n > 0 && n + 1 + word.chars().count() > w {
            lines.push(std::mem::take(&mut line));
        }
        if !line.is_empty() {
            line.push(' ');
        }
        line.push_str(word);
    }
    lines.push(line);
    lines
}

impl Widget for HelpOverlay {
    fn render(self, area: Rect, buf: &mut Buffer) {
        let layout = HelpOverlay::layout(area);
        let (w, h) = layout.size;
        let w = w.min(area.width);
        let h = h.min(area.height);
        let r = Rect::new(
            area.x + (area.width - w) / 2,
            area.y + (area.height - h) / 2,
            w,
            h,
        );
        Clear.render(r, buf);
        let (kw, tw) = (layout.key_w - 1, layout.text_w);
        let lines: Vec<Line> = layout
            .rows
            .into_iter()
            .map(|row| {
                let spans = row.into_iter().flat_map(|(key, text)| {
                    [
                        Span::styled(format!(" {key:<kw$}"), self.palette.label()),
                        Span::raw(format!(" {text:<tw$}")),
                    ]
                });
                Line::from(spans.collect::<Vec<_>>())
            })
            .collect();
        Paragraph::new(lines)
            .block(
                Block::bordered()
                    .title(" keys ")
                    .title_bottom(" ? or Esc closes this help "),
            )
            .render(r, buf);
    }
}
