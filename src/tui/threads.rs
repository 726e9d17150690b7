//! The thread panel: one row per thread of the process, CPU % where 100 % is
//! one core busy, and a sparkline of the last minute (one sample a second).
use super::theme::Palette;
use crate::cpu::CpuReport;
use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Paragraph, Widget};

const BARS: [char; 9] = [' ', '▁', '▂', '▃', '▄', '▅', '▆', '▇', '█'];
const NAME_W: usize = 12;

pub struct Threads<'a> {
    pub report: &'a CpuReport,
    pub palette: Palette,
}

/// `values` (percent of one core) as bars, newest last, at most `width`.
pub fn sparkline(values: &[f64], width: usize) -> String {
    let start = values.len().saturating_sub(width);
    let mut s: String = values[start..]
        .iter()
        .map(|v| {
            // Any load at all shows as at least the lowest bar.
            let level = ((v / 100.0).clamp(0.0, 1.0) * 8.0).round() as usize;
            BARS[if *v > 0.0 { level.max(1) } else { level }]
        })
        .collect();
    // Right-aligned so the newest sample is always in the same column.
    let pad = width.saturating_sub(values.len() - start);
    s.insert_str(0, &" ".repeat(pad));
    s
}

impl Threads<'_> {
    pub fn lines(&self, width: usize) -> Vec<Line<'static>> {
        let label = self.palette.label();
        let mut lines = vec![Line::from(Span::styled(
            format!("{:<NAME_W$} {:>6}  last minute", "thread", "CPU %"),
            label,
        ))];
        if self.report.threads.is_empty() {
            lines.push(Line::from("(no per-thread figures yet)"));
            return lines;
        }
        let spark_w = width.saturating_sub(NAME_W + 10);
        for t in &self.report.threads {
            let mut name: String = t.name.chars().take(NAME_W).collect();
            while name.chars().count() < NAME_W {
                name.push(' ');
            }
            lines.push(Line::from(vec![
                Span::raw(format!("{name} {:>6.1}  ", t.percent)),
                Span::styled(sparkline(&t.history, spark_w), self.bar_style()),
            ]));
        }
        lines.push(Line::from(Span::styled(
            format!(
                "{:<NAME_W$} {:>6.1}  of {} cores",
                "total", self.report.total_percent, self.report.cores
            ),
            label,
        )));
        lines
    }

    fn bar_style(&self) -> ratatui::style::Style {
        if self.palette.has_color() {
            ratatui::style::Style::new().fg(ratatui::style::Color::Green)
        } else {
            ratatui::style::Style::new()
        }
    }
}

impl Widget for Threads<'_> {
    fn render(self, area: Rect, buf: &mut Buffer) {
        let inner = usize::from(area.width.saturating_sub(2));
        Paragraph::new(self.lines(inner))
            .block(Block::bordered().title(" threads: CPU %, 100 % = one core "))
            .render(area, buf);
    }
}
