//! The chart of per-thread CPU over the last minute (key `c`), the
//! article's Figure 10: one braille line per thread, so the load moving
//! from `main` to `physics` on `t` is a picture. With many threads the
//! numbered group (`pool-N`) is drawn as its mean and its max, and the
//! legend says so. The axes are in percent of one core and seconds.
use super::theme::{LINE_COLOURS, Palette};
use super::threads::{nice_ceiling, ordered, split_group};
use crate::cpu::{CpuReport, history};
use ratatui::buffer::Buffer;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::Style;
use ratatui::symbols::Marker;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Axis, Block, Chart, Dataset, GraphType, Paragraph, Widget};

/// More lines than this and the numbered group is drawn as mean and max.
pub const MAX_LINES: usize = 8;

/// Without colour, lines are told apart by their marks, and the legend by
/// the glyph each draws with.
const MARKS: [(Marker, &str); 4] = [
    (Marker::Braille, "━"),
    (Marker::Dot, "•"),
    (Marker::Block, "█"),
    (Marker::Bar, "▄"),
];

/// One line of the chart: its legend name and its values, oldest first,
/// one a second.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    pub name: String,
    pub values: Vec<f64>,
    /// Threads behind the line.
    pub threads: usize,
}

/// What the chart draws for `report`: a line per thread, or, past
/// `MAX_LINES`, the numbered group as two lines (mean and max by second).
pub fn series(report: &CpuReport) -> Vec<Series> {
    let one = |t: &crate::cpu::ThreadLoad| Series {
        name: t.name.clone(),
        values: t.history.clone(),
        threads: 1,
    };
    if report.threads.len() <= MAX_LINES {
        return ordered(report).into_iter().map(one).collect();
    }
    let (singles, group) = split_group(report);
    let mut out: Vec<Series> = singles.into_iter().map(one).collect();
    if let Some((prefix, members)) = group {
        // Histories are right-aligned: the newest second is last in each.
        let len = members.iter().map(|t| t.history.len()).max().unwrap_or(0);
        let mut mean = vec![0.0; len];
        let mut max = vec![0.0f64; len];
        let mut counts = vec![0usize; len];
        for t in &members {
            let off = len - t.history.len();
            for (i, v) in t.history.iter().enumerate() {
                mean[off + i] += v;
                max[off + i] = max[off + i].max(*v);
                counts[off + i] += 1;
            }
        }
        for (m, c) in mean.iter_mut().zip(&counts) {
            *m /= (*c).max(1) as f64;
        }
        let n = members.len();
        out.push(Series {
            name: format!("{prefix}-* mean of {n}"),
            values: mean,
            threads: n,
        });
        out.push(Series {
            name: format!("{prefix}-* max of {n}"),
            values: max,
            threads: 0,
        });
    }
    out
}

/// `series` in at most `styles` lines, so no two look alike: past that,
/// the last line is the busiest of every thread the dropped lines held.
pub fn series_in(report: &CpuReport, styles: usize) -> Vec<Series> {
    let mut all = series(report);
    if all.len() <= styles || styles < 2 {
        return all;
    }
    let rest = all.split_off(styles - 1);
    let len = rest.iter().map(|s| s.values.len()).max().unwrap_or(0);
    let mut max = vec![0.0f64; len];
    for s in &rest {
        // Right-aligned: the newest second is last in each.
        let off = len - s.values.len();
        for (i, v) in s.values.iter().enumerate() {
            max[off + i] = max[off + i].max(*v);
        }
    }
    let n: usize = rest.iter().map(|s| s.threads).sum();
    all.push(Series {
        name: format!("max of {n} others"),
        values: max,
        threads: n,
    });
    all
}

/// The y axis's top: the busiest second drawn, rounded up to 1, 2 or 5
/// times a power of ten, so a load of a few percent fills the plot.
pub fn axis_top(lines: &[Series]) -> f64 {
    let peak = lines
        .iter()
        .flat_map(|s| s.values.iter().copied())
        .fold(1.0, f64::max);
    nice_ceiling(peak)
}

pub struct CpuChart<'a> {
    pub report: &'a CpuReport,
    pub palette: Palette,
}

impl CpuChart<'_> {
    /// How many lines this palette can draw with no two alike.
    pub fn styles(&self) -> usize {
        if self.palette.has_color() {
            LINE_COLOURS.len() * MARKS.len()
        } else {
            MARKS.len()
        }
    }

    /// Line `i`'s marker, its legend glyph and its style: a hue each, then
    /// the next mark; without colour, a mark each.
    pub fn style(&self, i: usize) -> (Marker, &'static str, Style) {
        if self.palette.has_color() {
            let (marker, glyph) = MARKS[(i / LINE_COLOURS.len()) % MARKS.len()];
            (
                marker,
                glyph,
                Style::new().fg(LINE_COLOURS[i % LINE_COLOURS.len()]),
            )
        } else {
            let (marker, glyph) = MARKS[i % MARKS.len()];
            (marker, glyph, Style::new())
        }
    }

    /// The legend as rows of `━ name` entries under the plot, so it never
    /// covers the lines; entries wrap at `width`.
    fn legend(&self, lines: &[Series], width: usize) -> Vec<Line<'static>> {
        let mut rows: Vec<Line> = Vec::new();
        let mut row: Vec<Span> = Vec::new();
        let mut used = 0;
        for (i, s) in lines.iter().enumerate() {
            let (_, mark, style) = self.style(i);
            let w = s.name.chars().count() + 4;
            if used > 0 && used + w > width {
                rows.push(Line::from(std::mem::take(&mut row)));
                used = 0;
            }
            row.push(Span::styled(mark, style));
            row.push(Span::raw(format!(" {}  ", s.name)));
            used += w;
        }
        if !row.is_empty() {
            rows.push(Line::from(row));
        }
        rows
    }
}

impl Widget for CpuChart<'_> {
    fn render(self, area: Rect, buf: &mut Buffer) {
        let lines = series_in(self.report, self.styles());
        // The y axis's labels say the scale (`0 %` … `5 %`).
        let top = axis_top(&lines);
        // Short enough for the 36 columns the canvas has at 80x24.
        let block = Block::bordered()
            .title(" CPU per thread, last 60 s ")
            .title_bottom(" c: back to the spheres ");
        let inner = block.inner(area);
        block.render(area, buf);
        let legend = self.legend(&lines, usize::from(inner.width));
        let legend_h = (legend.len() as u16).min(inner.height / 2);
        let [plot, key] =
            Layout::vertical([Constraint::Fill(1), Constraint::Length(legend_h)]).areas(inner);
        Paragraph::new(legend).render(key, buf);
        let points: Vec<Vec<(f64, f64)>> = lines
            .iter()
            .map(|s| {
                let last = s.values.len() as f64 - 1.0;
                s.values
                    .iter()
                    .enumerate()
                    .map(|(i, v)| (i as f64 - last, *v))
                    .collect()
            })
            .collect();
        let datasets: Vec<Dataset> = points
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let (marker, _, style) = self.style(i);
                Dataset::default()
                    .marker(marker)
                    .graph_type(GraphType::Line)
                    .style(style)
                    .data(p)
            })
            .collect();
        let span = (history::LEN - 1) as f64;
        let label = self.palette.label();
        let x = Axis::default().style(label).bounds([-span, 0.0]).labels([
            format!("-{span} s"),
            format!("-{:.0} s", span / 2.0),
            "now".into(),
        ]);
        let y = Axis::default().style(label).bounds([0.0, top]).labels([
            "0 %".to_string(),
            format!("{} %", top / 2.0),
            format!("{top} %"),
        ]);
        Chart::new(datasets).x_axis(x).y_axis(y).render(plot, buf);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cpu::{ThreadLoad, ThreadRole};

    fn load(tid: i32, name: &str, history: Vec<f64>) -> ThreadLoad {
        ThreadLoad {
            tid,
            role: ThreadRole::of(name),
            name: name.into(),
            percent: history.last().copied().unwrap_or(0.0),
            cpu_seconds: 0.0,
            history,
        }
    }

    #[test]
    fn few_threads_get_a_line_each_many_are_grouped_as_mean_and_max() {
        let mut r = CpuReport {
            threads: vec![load(1, "main", vec![50.0]), load(2, "physics", vec![10.0])],
            ..CpuReport::default()
        };
        let names: Vec<String> = series(&r).into_iter().map(|s| s.name).collect();
        assert_eq!(names, ["main", "physics"]);
        for i in 0..10 {
            // pool-0 started a second later than the rest.
            let h = if i == 0 {
                vec![40.0]
            } else {
                vec![f64::from(i), 20.0]
            };
            r.threads.push(load(10 + i, &format!("pool-{i}"), h));
        }
        let s = series(&r);
        assert_eq!(s.len(), 4);
        assert_eq!(s[2].name, "pool-* mean of 10");
        assert_eq!(s[3].name, "pool-* max of 10");
        // First second: pool-1..9 only; last: all ten.
        assert_eq!(s[2].values, [5.0, (40.0 + 9.0 * 20.0) / 10.0]);
        assert_eq!(s[3].values, [9.0, 40.0]);
    }

    fn loaded(percent: f64) -> CpuReport {
        let mut threads = vec![
            load(1, "main", vec![percent * 0.2; 60]),
            load(2, "physics", vec![percent; 60]),
        ];
        for (i, name) in ["signals", "input", "output"].iter().enumerate() {
            threads.push(load(3 + i as i32, name, vec![0.1; 60]));
        }
        for i in 0..64 {
            threads.push(load(100 + i, &format!("pool-{i}"), vec![percent / 2.0; 60]));
        }
        CpuReport {
            threads,
            cores: 2,
            ..CpuReport::default()
        }
    }

    #[test]
    fn the_axis_fits_the_load_at_3_and_95_percent() {
        let c = |p| axis_top(&series(&loaded(p)));
        // 3 % fills three fifths of a 5 % axis, not the bottom 3 % of 100.
        assert_eq!(c(3.0), 5.0);
        assert_eq!(c(95.0), 100.0);
        assert_eq!(c(0.0), 1.0);
        assert_eq!(c(130.0), 200.0);
    }

    #[test]
    fn no_two_lines_alike_in_16_colours_or_without_colour() {
        let r = loaded(50.0);
        for palette in [Palette::C16, Palette::Mono] {
            let chart = CpuChart {
                report: &r,
                palette,
            };
            let lines = series_in(&r, chart.styles());
            // Every thread is behind some line.
            let n: usize = lines.iter().map(|s| s.threads).sum();
            assert_eq!(n, r.threads.len(), "{palette:?}");
            let looks: Vec<(&str, Style)> = (0..lines.len())
                .map(|i| {
                    let (_, glyph, style) = chart.style(i);
                    (glyph, style)
                })
                .collect();
            for (i, a) in looks.iter().enumerate() {
                for b in &looks[i + 1..] {
                    assert_ne!(a, b, "{palette:?}: {looks:?}");
                }
            }
        }
    }
}
