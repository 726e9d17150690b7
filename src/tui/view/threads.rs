//! The thread panel: CPU % per thread (100 % = one core), the pool's own
//! total, the process total and what other processes take on the same CPUs,
//! each with its base (`of 200 %` on two cores). Threads come in a fixed
//! order (main, physics, pool, split, the rest; `cpu::order_key`). Three
//! layouts, the first that fits: a row per thread with its id on wide panels
//! and a sparkline; the threads' figures in columns; and only when even those
//! rows run out, the numbered threads (`pool-0`…) as a grid of cells shaded
//! by load, as btop shows cores, with a legend. No thread is ever left out.
use super::parallelism::{parallelism_text, pool_rows};
use super::theme::Palette;
use crate::cpu::history;
use crate::cpu::{CpuReport, ThreadLoad, ThreadRole, order_key};
use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::style::Style;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Paragraph, Widget};

const BARS: [char; 9] = [' ', '▁', '▂', '▃', '▄', '▅', '▆', '▇', '█'];
const NAME_W: usize = 12;
/// Cells per block in the grid, a space between blocks so they can be counted.
const BLOCK: usize = 8;
/// Inner width from which rows show the thread id (as `top -H` and `perf`).
pub const TID_WIDTH: usize = 60;
/// A column entry: an 11-column name, a space, `100.0 %`, a space.
const ENTRY_W: usize = 20;

pub struct Threads<'a> {
    pub report: &'a CpuReport,
    pub palette: Palette,
    /// Busiest first (key `s`) instead of the fixed order.
    pub by_cpu: bool,
    /// `pool_line` of the last frame, when a pool ran it.
    pub pool: Option<String>,
}

/// The pool line of a frame a pool ran ([`pool_line`]), from what ran,
/// with the scene's measured parallelism once there is one (none for a
/// model on one lane: the line says it is serial).
pub fn pool_line_of(snap: &crate::engine::Snapshot) -> Option<String> {
    let serial = snap.one_lane.then(|| snap.model_ran());
    let parallelism = snap.parallelism.filter(|_| serial.is_none());
    snap.pool_busy.map(|b| {
        let line = pool_line(&b, snap.count, serial);
        match parallelism {
            Some(p) => line + &parallelism_text(p),
            None => line,
        }
    })
}

/// How many pool threads the scene keeps busy, and why no more, e.g.
/// `pool: 1 of 64 busy — 1000 spheres too few` (short, to fit the panel).
/// `serial`: the model that ran, when it runs on one lane (`exact`): the
/// physics then keeps one thread busy, whatever the frame's readouts
/// spread over the others.
pub fn pool_line(
    b: &crate::physics::exec::Busy,
    spheres: usize,
    serial: Option<crate::physics::ModelKind>,
) -> String {
    use crate::physics::exec::Bound;
    if let Some(m) = serial {
        return format!("pool: 1 of {} busy — {m} is serial", b.threads);
    }
    let why = match b.bound {
        Bound::Work => format!("{spheres} spheres too few"),
        Bound::Blocks => "too few blocks".into(),
        Bound::Cores => "one a core".into(),
        // Every thread had a lane: nothing to explain.
        Bound::Threads => return format!("pool: {} of {} busy", b.busy, b.threads),
    };
    format!("pool: {} of {} busy — {why}", b.busy, b.threads)
}

/// `values` (percent of one core) as bars, newest last, at most `width`,
/// the full bar at `top` percent (see `scale_top`).
pub fn sparkline(values: &[f64], width: usize, top: f64) -> String {
    let start = values.len().saturating_sub(width);
    let mut s: String = values[start..]
        .iter()
        .map(|v| {
            // Any load at all shows as at least the lowest bar.
            let level = ((v / top).clamp(0.0, 1.0) * 8.0).round() as usize;
            BARS[if *v > 0.0 { level.max(1) } else { level }]
        })
        .collect();
    // Right-aligned so the newest sample is always in the same column.
    let pad = width.saturating_sub(values.len() - start);
    s.insert_str(0, &" ".repeat(pad));
    s
}

/// The sparklines' full bar: the busiest second of any thread shown, rounded
/// up to 1, 2 or 5 times a power of ten (at least 1 %), so a thread at 1 %
/// and one at 15 % differ in height at any load; the header says the figure.
pub fn scale_top(report: &CpuReport) -> f64 {
    let peak = report
        .threads
        .iter()
        .flat_map(|t| t.history.iter().copied().chain([t.percent]))
        .fold(1.0, f64::max);
    nice_ceiling(peak)
}

/// The least of 1, 2 or 5 times a power of ten (from 1) at or above `peak`.
pub fn nice_ceiling(peak: f64) -> f64 {
    if !peak.is_finite() {
        return 100.0;
    }
    let mut step = 1.0;
    loop {
        for m in [1.0, 2.0, 5.0] {
            if m * step >= peak {
                return m * step;
            }
        }
        step *= 10.0;
    }
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

/// The grid's legend, the levels `cell` draws.
pub const LEGEND: &str = "· idle  ▁ under 19 %  ▄ 50 %  █ 100 %";

/// The pool's lane threads, if there are `min_members` or more, by lane;
/// and every other thread, in report order.
pub fn group_of(
    report: &CpuReport,
    min_members: usize,
) -> (Vec<&ThreadLoad>, Option<(String, Vec<&ThreadLoad>)>) {
    let (mut members, singles): (Vec<&ThreadLoad>, Vec<&ThreadLoad>) = ordered(report)
        .into_iter()
        .partition(|t| t.role.lane().is_some());
    if members.is_empty() || members.len() < min_members {
        return (ordered(report), None);
    }
    members.sort_by_key(|t| t.role.lane());
    (singles, Some((ThreadRole::POOL_GROUP.to_string(), members)))
}

/// The report's threads in the order the panel shows them (the sampler
/// gives them so; a report built elsewhere is put in order here).
pub fn ordered(report: &CpuReport) -> Vec<&ThreadLoad> {
    let mut all: Vec<&ThreadLoad> = report.threads.iter().collect();
    all.sort_by(|a, b| order_key(a).cmp(&order_key(b)));
    all
}

/// `group_of` with two members at least: a group worth a grid or a mean.
pub fn split_group(report: &CpuReport) -> (Vec<&ThreadLoad>, Option<(String, Vec<&ThreadLoad>)>) {
    group_of(report, 2)
}

/// Panel rows (border included) for one row per thread.
pub fn full_height(report: &CpuReport) -> u16 {
    let t = Threads {
        report,
        palette: Palette::Mono,
        by_cpu: false,
        pool: None,
    };
    t.lines(usize::from(u16::MAX)).len() as u16 + 2
}

/// Panel rows (border included) for the grid with a cell per thread, at
/// `inner_width` columns: the least the panel needs to show every thread.
pub fn compact_height(report: &CpuReport, inner_width: usize) -> u16 {
    let t = Threads {
        report,
        palette: Palette::Mono,
        by_cpu: false,
        pool: None,
    };
    t.compact_lines(inner_width, usize::MAX).len() as u16 + 2
}

/// Which layout the panel takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layout {
    Rows,
    Columns,
    Grid,
}

impl Threads<'_> {
    fn load_style(&self, percent: f64) -> Style {
        self.palette.load(percent)
    }

    /// `threads` busiest first when sorting by CPU (ties in the fixed order).
    fn sorted<'t>(&self, mut threads: Vec<&'t ThreadLoad>) -> Vec<&'t ThreadLoad> {
        if self.by_cpu {
            threads.sort_by(|a, b| b.percent.total_cmp(&a.percent));
        }
        threads
    }

    /// `of 200 %`: what 100 % of every CPU this process may use adds up to.
    fn base(&self) -> String {
        format!("of {} %", self.report.cores * 100)
    }

    fn others(&self) -> String {
        self.report
            .others_percent
            .map_or_else(|| "-".into(), |o| format!("{o:.1}"))
    }

    /// The pool's own total (the numbered group, even of one thread): its
    /// label and its figure.
    fn group_total(&self) -> Option<(String, String)> {
        let (_, group) = group_of(self.report, 1);
        let (prefix, members) = group?;
        let sum: f64 = members.iter().map(|t| t.percent).sum();
        let n = members.len();
        let threads = if n == 1 { "thread" } else { "threads" };
        Some((
            format!("{prefix} total"),
            format!("{sum:>5.1} % of {n} {threads}"),
        ))
    }

    /// The process total and the others, on one line if `width` allows.
    fn totals(&self, width: usize) -> Vec<String> {
        let base = self.base();
        let process = format!("process {:.1} % {base}", self.report.total_percent);
        // Two words, so no reader of the screen takes it for a thread.
        let others = format!("other procs {} % {base}", self.others());
        if process.len() + 2 + others.len() <= width {
            vec![format!("{process}  {others}")]
        } else {
            vec![process, others]
        }
    }

    /// The layout for an inner area of `width` x `height`.
    pub fn layout(&self, width: usize, height: usize) -> Layout {
        if self.lines(width).len() <= height {
            Layout::Rows
        } else if self.column_lines(width).len() <= height {
            Layout::Columns
        } else {
            Layout::Grid
        }
    }

    /// A row per thread with a sparkline of its last seconds (and its id
    /// from `TID_WIDTH` columns).
    pub fn lines(&self, width: usize) -> Vec<Line<'static>> {
        let label = self.palette.label();
        let tid = width >= TID_WIDTH;
        let fixed = NAME_W + 10 + if tid { 8 } else { 0 };
        let spark_w = width.saturating_sub(fixed).min(history::LEN);
        let top = scale_top(self.report);
        let tid_head = if tid {
            format!(" {:>7}", "TID")
        } else {
            String::new()
        };
        let mut lines = vec![Line::from(Span::styled(
            format!(
                "{:<NAME_W$}{tid_head}   CPU %  last {spark_w} s to {top} %",
                "thread"
            ),
            label,
        ))];
        if self.report.threads.is_empty() {
            lines.push(Line::from("(no per-thread figures yet)"));
        }
        for t in self.sorted(ordered(self.report)) {
            let id = if tid {
                format!(" {:>7}", t.tid)
            } else {
                String::new()
            };
            lines.push(Line::from(vec![
                Span::raw(format!(
                    "{}{id} {:>5.1} %  ",
                    padded(&t.name, NAME_W),
                    t.percent
                )),
                Span::styled(sparkline(&t.history, spark_w, top), self.load_style(0.0)),
            ]));
        }
        let row = |l: &str, v: String| {
            let blank = if tid { " ".repeat(8) } else { String::new() };
            Line::from(Span::styled(format!("{l:<NAME_W$}{blank} {v}"), label))
        };
        if let Some((l, v)) = self.group_total() {
            lines.push(row(&l, v));
        }
        let base = self.base();
        lines.push(row(
            "process",
            format!("{:>5.1} % {base}", self.report.total_percent),
        ));
        lines.push(row("other procs", format!("{:>5} % {base}", self.others())));
        lines
    }

    /// `threads` as `name  8.6 %` entries, as many columns as `width` holds.
    fn columns(threads: &[&ThreadLoad], width: usize) -> Vec<Line<'static>> {
        let per_row = ((width + 1) / ENTRY_W).max(1);
        threads
            .chunks(per_row)
            .map(|row| {
                let text: Vec<String> = row
                    .iter()
                    .map(|t| format!("{} {:>5.1} %", padded(&t.name, 11), t.percent))
                    .collect();
                Line::from(text.join(" "))
            })
            .collect()
    }

    /// Every thread's figure in columns, the pool total and the totals.
    pub fn column_lines(&self, width: usize) -> Vec<Line<'static>> {
        let label = self.palette.label();
        let all = self.sorted(ordered(self.report));
        let mut lines = Self::columns(&all, width);
        if all.is_empty() {
            lines.push(Line::from("(no per-thread figures yet)"));
        }
        lines.extend(
            self.group_total()
                .map(|(l, v)| Line::from(Span::styled(format!("{l} {}", v.trim_start()), label))),
        );
        lines.extend(
            self.totals(width)
                .into_iter()
                .map(|t| Line::from(Span::styled(t, label))),
        );
        lines
    }

    /// The other threads in columns, the numbered group as a grid that fits
    /// in `height` rows (several threads to a cell, their max, if it must),
    /// its legend, the pool total and the totals.
    pub fn compact_lines(&self, width: usize, height: usize) -> Vec<Line<'static>> {
        let label = self.palette.label();
        let (singles, group) = split_group(self.report);
        let mut lines = Self::columns(&self.sorted(singles), width);
        if self.report.threads.is_empty() {
            lines.push(Line::from("(no per-thread figures yet)"));
        }
        let totals = self.totals(width);
        if let Some((prefix, members)) = group {
            // Summary, pool total and the totals around the grid; the legend
            // too while two grid rows are left beside it.
            let around = lines.len() + 2 + totals.len();
            let legend = height >= around + 3;
            let grid_rows = height.saturating_sub(around + usize::from(legend)).max(1);
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
                    // A gap between blocks of cells, for counting.
                    let gap = (i > 0 && i % BLOCK == 0).then(|| Span::raw(" "));
                    spans.extend(gap);
                    spans.push(Span::styled(ch.to_string(), self.load_style(load)));
                }
                lines.push(Line::from(spans));
            }
            if legend {
                lines.push(Line::from(Span::styled(LEGEND, label)));
            }
            lines.extend(
                self.group_total().map(|(l, v)| {
                    Line::from(Span::styled(format!("{l} {}", v.trim_start()), label))
                }),
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
        let title = if self.by_cpu {
            " threads by CPU %, 100 % = one core "
        } else {
            " threads: CPU %, 100 % = one core "
        };
        let block = Block::bordered().title(title);
        let inner = block.inner(area);
        block.render(area, buf);
        let (w, h) = (usize::from(inner.width), usize::from(inner.height));
        let mut lines = match self.layout(w, h) {
            Layout::Rows => self.lines(w),
            Layout::Columns => self.column_lines(w),
            Layout::Grid => self.compact_lines(w, h),
        };
        // The pool's line above the process and other-procs totals, where a row is spare.
        if let Some(p) = self.pool.as_deref().filter(|_| h > lines.len()) {
            let at = lines.len().saturating_sub(2);
            for (i, row) in pool_rows(p, w, h - lines.len()).into_iter().enumerate() {
                lines.insert(at + i, Line::from(Span::styled(row, self.palette.label())));
            }
        }
        Paragraph::new(lines).render(inner, buf);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::ModelKind;

    #[test]
    fn the_pool_line_says_why_only_when_threads_wait() {
        use crate::physics::exec::{Bound, Busy, LANE_COST_NS, lanes_for, work_ns};
        let line = |threads, spheres: usize| {
            // A pass of 10 ns a sphere: two lanes' worth from 8000 spheres.
            let work = work_ns(spheres, 10);
            let (busy, bound) = lanes_for(threads, 2, 100, work, LANE_COST_NS);
            let b = Busy {
                busy,
                threads,
                bound,
            };
            pool_line(&b, spheres, None)
        };
        assert_eq!(line(64, 1000), "pool: 1 of 64 busy — 1000 spheres too few");
        // Work for two lanes on two threads: all of them busy.
        assert_eq!(line(2, 8789), "pool: 2 of 2 busy");
        assert_eq!(line(64, 8789), "pool: 2 of 64 busy — one a core");
        let b = Busy {
            busy: 3,
            threads: 8,
            bound: Bound::Blocks,
        };
        assert_eq!(
            pool_line(&b, 10, None),
            "pool: 3 of 8 busy — too few blocks"
        );
        // `exact` runs on one lane: the readouts' lanes are not its busy.
        let all = Busy {
            busy: 2,
            threads: 2,
            bound: Bound::Threads,
        };
        assert_eq!(
            pool_line(&all, 8000, Some(ModelKind::Exact)),
            "pool: 1 of 2 busy — exact is serial"
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
