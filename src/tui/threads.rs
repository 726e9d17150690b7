//! The thread panel: CPU % per thread (100 % = one core), the process
//! total and what other processes take. When a row per thread does not fit,
//! the numbered threads (`pool-0`…) become a grid of cells shaded by load,
//! as btop shows cores, with their min/mean/max; every other thread keeps
//! its own figure, so no thread is ever left out.
use super::theme::Palette;
use crate::cpu::history;
use crate::cpu::{CpuReport, ThreadLoad};
use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::style::{Color, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Paragraph, Widget};

const BARS: [char; 9] = [' ', '▁', '▂', '▃', '▄', '▅', '▆', '▇', '█'];
const NAME_W: usize = 12;
/// Cells per block in the grid, a space between blocks so they can be counted.
const BLOCK: usize = 8;

pub struct Threads<'a> {
    pub report: &'a CpuReport,
    pub palette: Palette,
    /// `pool_line` of the last frame, when a pool ran it.
    pub pool: Option<String>,
}

/// How many pool threads the scene keeps busy, and why no more, e.g.
/// `pool: 1 of 64 busy — 1000 spheres too few` (short, to fit the panel).
pub fn pool_line(b: &crate::physics::exec::Busy, spheres: usize) -> String {
    use crate::physics::exec::Bound;
    let why = match b.bound {
        Bound::Work => format!("{spheres} spheres too few"),
        Bound::Blocks => "too few blocks".into(),
        Bound::Cores => "one a core".into(),
        Bound::Threads => "all".into(),
    };
    format!("pool: {} of {} busy — {why}", b.busy, b.threads)
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

/// A grid cell for a load: a dot when idle, else a bar of its height.
pub fn cell(percent: f64) -> char {
    if percent < 0.5 {
        '·'
    } else {
        let level = ((percent / 100.0).clamp(0.0, 1.0) * 8.0).round() as usize;
        BARS[level.max(1)]
    }
}

/// The numbered group (`pool-N`) with the most members, if it has two or
/// more, sorted by number; and every thread not in it, in report order.
pub fn split_group(report: &CpuReport) -> (Vec<&ThreadLoad>, Option<(String, Vec<&ThreadLoad>)>) {
    // `pool-12` -> ("pool", 12); no allocation, as this runs every frame.
    fn numbered(t: &ThreadLoad) -> Option<(&str, u32)> {
        let (prefix, n) = t.name.rsplit_once('-')?;
        Some((prefix, n.parse().ok()?))
    }
    let mut counts: Vec<(&str, usize)> = Vec::new();
    for t in &report.threads {
        if let Some((p, _)) = numbered(t) {
            match counts.iter_mut().find(|c| c.0 == p) {
                Some(c) => c.1 += 1,
                None => counts.push((p, 1)),
            }
        }
    }
    let best = counts.into_iter().filter(|c| c.1 >= 2).max_by_key(|c| c.1);
    let Some((prefix, _)) = best else {
        return (report.threads.iter().collect(), None);
    };
    let mut members: Vec<(u32, &ThreadLoad)> = Vec::new();
    let mut singles: Vec<&ThreadLoad> = Vec::new();
    for t in &report.threads {
        match numbered(t) {
            Some((p, n)) if p == prefix => members.push((n, t)),
            _ => singles.push(t),
        }
    }
    members.sort_by_key(|m| m.0);
    let members = members.into_iter().map(|m| m.1).collect();
    (singles, Some((prefix.to_string(), members)))
}

/// Panel rows (border included) for one row per thread.
pub fn full_height(report: &CpuReport) -> u16 {
    // Header, the threads, total, others, border.
    report.threads.len().max(1) as u16 + 5
}

fn has_pool(report: &CpuReport) -> bool {
    report.threads.iter().any(|t| t.name.starts_with("pool-"))
}

/// Panel rows (border included) for the compact view with a cell per
/// thread, at `inner_width` columns.
pub fn compact_height(report: &CpuReport, inner_width: usize) -> u16 {
    let (singles, group) = split_group(report);
    let group_rows = group.map_or(0, |(_, m)| {
        let loads = vec![0.0; m.len()];
        1 + grid(&loads, inner_width, usize::MAX).1.len()
    }) + usize::from(has_pool(report));
    // The totals take one row, two on narrow panels: count two.
    // An empty report still takes a row to say so.
    (singles.len().div_ceil(2).max(1) + group_rows + 2 + 2) as u16
}

impl Threads<'_> {
    fn load_style(&self, percent: f64) -> Style {
        if !self.palette.has_color() {
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

    fn others(&self) -> String {
        self.report
            .others_percent
            .map_or_else(|| "-".into(), |o| format!("{o:.1}"))
    }

    /// A row per thread with a sparkline of its last seconds.
    pub fn lines(&self, width: usize) -> Vec<Line<'static>> {
        let label = self.palette.label();
        let spark_w = width.saturating_sub(NAME_W + 10).min(history::LEN);
        let mut lines = vec![Line::from(Span::styled(
            format!("{:<NAME_W$} {:>6}  last {spark_w} s", "thread", "CPU %"),
            label,
        ))];
        if self.report.threads.is_empty() {
            lines.push(Line::from("(no per-thread figures yet)"));
        }
        for t in &self.report.threads {
            lines.push(Line::from(vec![
                Span::raw(format!("{} {:>6.1}  ", padded(&t.name, NAME_W), t.percent)),
                Span::styled(sparkline(&t.history, spark_w), self.load_style(0.0)),
            ]));
        }
        lines.push(Line::from(Span::styled(
            format!(
                "{:<NAME_W$} {:>6.1}  of {} cores",
                "total", self.report.total_percent, self.report.cores
            ),
            label,
        )));
        lines.push(Line::from(Span::styled(
            // Two words, so no reader of the screen takes it for a thread.
            format!(
                "{:<NAME_W$} {:>6}  rest of the machine",
                "other procs",
                self.others()
            ),
            label,
        )));
        lines
    }

    /// Two threads to a row, the numbered group as a grid that fits in
    /// `height` rows (several threads to a cell, their max, if it must).
    pub fn compact_lines(&self, width: usize, height: usize) -> Vec<Line<'static>> {
        let label = self.palette.label();
        let (singles, group) = split_group(self.report);
        let mut lines: Vec<Line> = singles
            .chunks(2)
            .map(|pair| {
                let spans: Vec<Span> = pair
                    .iter()
                    .map(|t| Span::raw(format!("{} {:>5.1}   ", padded(&t.name, 11), t.percent)))
                    .collect();
                Line::from(spans)
            })
            .collect();
        if self.report.threads.is_empty() {
            lines.push(Line::from("(no per-thread figures yet)"));
        }
        let total = format!(
            "total {:.1} of {} cores",
            self.report.total_percent, self.report.cores
        );
        let others = format!("other procs {}", self.others());
        let totals = if total.len() + 2 + others.len() <= width {
            vec![format!("{total}  {others}")]
        } else {
            vec![total, others]
        };
        if let Some((prefix, members)) = group {
            let grid_rows = height.saturating_sub(lines.len() + 1 + totals.len()).max(1);
            let loads: Vec<f64> = members.iter().map(|t| t.percent).collect();
            let (min, mean, max) = min_mean_max(&loads);
            let mut grid_at = grid(&loads, width, grid_rows);
            if grid_at.0 > 1 && grid_rows > 1 {
                // Shared cells take a line to explain: one grid row less.
                grid_at = grid(&loads, width, grid_rows - 1);
            }
            let (per_cell, rows) = grid_at;
            let summary = format!(
                "{prefix} x{}: min {min:.0} mean {mean:.0} max {max:.0} %",
                loads.len()
            );
            lines.push(Line::from(Span::styled(summary, label)));
            if per_cell > 1 {
                lines.push(Line::from(Span::styled(
                    format!("each cell: the busiest of {per_cell} threads"),
                    label,
                )));
            }
            for (start, cells) in rows {
                let mut spans = vec![Span::styled(start, label)];
                for (i, (ch, load)) in cells.into_iter().enumerate() {
                    if i > 0 && i % BLOCK == 0 {
                        spans.push(Span::raw(" "));
                    }
                    spans.push(Span::styled(ch.to_string(), self.load_style(load)));
                }
                lines.push(Line::from(spans));
            }
            lines.extend(
                self.pool
                    .clone()
                    .map(|p| Line::from(Span::styled(p, label))),
            );
        }
        lines.extend(
            totals
                .into_iter()
                .map(|t| Line::from(Span::styled(t, label))),
        );
        lines
    }
}

/// Rows of the grid: each a start-index label and its cells (glyph, load).
type GridRow = (String, Vec<(char, f64)>);

/// The fewest threads per cell (1, 2, 4…) whose grid fits in `rows` rows of
/// `width` columns, and the grid's rows.
fn grid(loads: &[f64], width: usize, rows: usize) -> (usize, Vec<GridRow>) {
    let label_w = (loads.len().saturating_sub(1)).to_string().len() + 1;
    let room = width.saturating_sub(label_w).max(1);
    // Whole blocks of 8 and a space each, or as many cells as fit.
    let per_row = if room >= BLOCK {
        (room + 1) / (BLOCK + 1) * BLOCK
    } else {
        room
    };
    let mut per_cell = 1;
    while loads.len().div_ceil(per_cell).div_ceil(per_row) > rows && per_cell < loads.len() {
        per_cell *= 2;
    }
    let cells: Vec<(char, f64)> = loads
        .chunks(per_cell)
        .map(|c| {
            let m = c.iter().copied().fold(0.0, f64::max);
            (cell(m), m)
        })
        .collect();
    let out = cells
        .chunks(per_row)
        .enumerate()
        .map(|(r, c)| {
            let start = r * per_row * per_cell;
            (format!("{start:>w$} ", w = label_w - 1), c.to_vec())
        })
        .collect();
    (per_cell, out)
}

fn min_mean_max(v: &[f64]) -> (f64, f64, f64) {
    let min = v.iter().copied().fold(f64::INFINITY, f64::min);
    let max = v.iter().copied().fold(0.0, f64::max);
    let mean = v.iter().sum::<f64>() / v.len().max(1) as f64;
    (if min.is_finite() { min } else { 0.0 }, mean, max)
}

/// `name` cut or padded to `w` columns.
fn padded(name: &str, w: usize) -> String {
    let mut s: String = name.chars().take(w).collect();
    while s.chars().count() < w {
        s.push(' ');
    }
    s
}

impl Widget for Threads<'_> {
    fn render(self, area: Rect, buf: &mut Buffer) {
        let block = Block::bordered().title(" threads: CPU %, 100 % = one core ");
        let inner = block.inner(area);
        block.render(area, buf);
        let (w, h) = (usize::from(inner.width), usize::from(inner.height));
        let lines = if area.height >= full_height(self.report) {
            let mut lines = self.lines(w);
            // The pool's line above the totals, where a row is spare.
            if let Some(p) = self.pool.clone().filter(|_| h > lines.len()) {
                let at = lines.len().saturating_sub(2);
                lines.insert(at, Line::from(Span::styled(p, self.palette.label())));
            }
            lines
        } else {
            self.compact_lines(w, h)
        };
        Paragraph::new(lines).render(inner, buf);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_pool_line_says_how_many_are_busy_and_why() {
        use crate::physics::exec::{Bound, Busy};
        let b = |busy, bound| Busy {
            busy,
            threads: 64,
            bound,
        };
        assert_eq!(
            super::pool_line(&b(1, Bound::Work), 1000),
            "pool: 1 of 64 busy — 1000 spheres too few"
        );
        assert_eq!(
            super::pool_line(&b(2, Bound::Cores), 100_000),
            "pool: 2 of 64 busy — one a core"
        );
    }

    #[test]
    fn the_grid_doubles_threads_per_cell_until_it_fits() {
        let loads: Vec<f64> = (0..256).map(|i| f64::from(i % 101)).collect();
        // 40 columns: a 4-column label, 32 cells a row.
        let (k, rows) = grid(&loads, 40, 8);
        assert_eq!((k, rows.len()), (1, 8));
        assert_eq!(rows[1].0, " 32 ");
        let (k, rows) = grid(&loads, 40, 3);
        assert_eq!((k, rows.len()), (4, 2));
        // Each cell is the max of its threads.
        assert_eq!(rows[0].1[0].1, 3.0);
        let cells: usize = rows.iter().map(|r| r.1.len()).sum();
        assert_eq!(cells, 64);
    }

    #[test]
    fn cells_show_idle_as_a_dot_and_any_load_as_a_bar() {
        assert_eq!(cell(0.0), '·');
        assert_eq!(cell(1.0), '▁');
        assert_eq!(cell(100.0), '█');
        assert_eq!(cell(250.0), '█');
    }
}
