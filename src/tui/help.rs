//! The key bar (always there) and the `?` overlay (every key, explained),
//! both read from `keys::TABLE`.
use super::keys::{self, TABLE};
use super::theme::Palette;
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

/// Columns of the key column, its leading space included.
const KEY_W: usize = 10;

impl HelpOverlay {
    /// Rows are " key      description ": the key column, the text, one
    /// spare; the border carries the title and how to close it.
    pub fn size() -> (u16, u16) {
        let w = TABLE
            .iter()
            .map(|b| KEY_W + 2 + b.help.chars().count())
            .max()
            .unwrap_or(40);
        (w as u16 + 2, TABLE.len() as u16 + 2)
    }
}

impl Widget for HelpOverlay {
    fn render(self, area: Rect, buf: &mut Buffer) {
        let (w, h) = HelpOverlay::size();
        let w = w.min(area.width);
        let h = h.min(area.height);
        let r = Rect::new(
            area.x + (area.width - w) / 2,
            area.y + (area.height - h) / 2,
            w,
            h,
        );
        Clear.render(r, buf);
        let lines: Vec<Line> = TABLE
            .iter()
            .map(|b| {
                Line::from(vec![
                    Span::styled(
                        format!(" {:<w$}", b.keys(), w = KEY_W - 1),
                        self.palette.label(),
                    ),
                    Span::raw(format!(" {}", b.help)),
                ])
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
