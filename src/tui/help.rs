//! The help bar (always there) and the `?` overlay (every key, explained).
use super::input::KEYS;
use super::theme::Palette;
use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Clear, Paragraph, Widget};

pub struct HelpBar {
    pub palette: Palette,
}

impl Widget for HelpBar {
    fn render(self, area: Rect, buf: &mut Buffer) {
        let mut spans = Vec::new();
        for (key, label) in KEYS.iter().filter_map(|k| k.1) {
            spans.push(Span::styled(key, self.palette.key()));
            spans.push(Span::raw(format!(" {label} ")));
        }
        Paragraph::new(Line::from(spans)).render(area, buf);
    }
}

pub struct HelpOverlay {
    pub palette: Palette,
}

impl HelpOverlay {
    /// Rows are " key       description": 11 columns, the text, one spare.
    pub fn size() -> (u16, u16) {
        let w = KEYS
            .iter()
            .map(|(_, _, d)| 12 + d.len())
            .max()
            .unwrap_or(40);
        (w as u16 + 2, KEYS.len() as u16 + 4)
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
        let mut lines: Vec<Line> = KEYS
            .iter()
            .map(|(k, _, d)| {
                Line::from(vec![
                    Span::styled(format!(" {k:<9}"), self.palette.label()),
                    Span::raw(format!(" {d}")),
                ])
            })
            .collect();
        lines.push(Line::from(""));
        lines.push(Line::from(" ? or Esc closes this help"));
        Paragraph::new(lines)
            .block(Block::bordered().title(" keys "))
            .render(r, buf);
    }
}
