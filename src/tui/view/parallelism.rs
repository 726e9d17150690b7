//! The pool line's parallelism (`Snapshot::parallelism`, measured by the
//! engine): its text, and the line fitted to the panel's width.

/// What the parallelism figure is, dropped first where the line is long.
pub const WORK_SPAN: &str = " (work/span)";
/// Between the pool line and its parallelism.
pub const PARALLELISM: &str = " · parallelism ";

/// ` · parallelism 38 (work/span)`: whole from 10, a decimal below.
#[must_use]
pub fn parallelism_text(p: f64) -> String {
    let figure = if p >= 9.95 {
        format!("{p:.0}")
    } else {
        format!("{p:.1}")
    };
    format!("{PARALLELISM}{figure}{WORK_SPAN}")
}

/// The pool line in `width` columns with `spare` rows free: whole; else
/// without ` (work/span)`; else the parallelism on a row of its own (when
/// a second row is spare) or left out.
#[must_use]
pub fn pool_rows(line: &str, width: usize, spare: usize) -> Vec<String> {
    let fits = |l: &str| l.chars().count() <= width;
    if fits(line) {
        return vec![line.to_string()];
    }
    let short = line.strip_suffix(WORK_SPAN).unwrap_or(line);
    if fits(short) {
        return vec![short.to_string()];
    }
    let Some((busy, figure)) = line.split_once(PARALLELISM) else {
        return vec![line.to_string()];
    };
    let mut rows = vec![busy.to_string()];
    if spare >= 2 {
        let own = format!("parallelism {figure}");
        let cut = own.strip_suffix(WORK_SPAN).unwrap_or(&own).to_string();
        rows.push(if fits(&own) { own } else { cut });
    }
    rows
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_long_line_loses_what_the_figure_is_then_moves_it_then_drops_it() {
        let line = format!("pool: 2 of 64 busy — one a core{}", parallelism_text(41.7));
        assert_eq!(
            line,
            "pool: 2 of 64 busy — one a core · parallelism 42 (work/span)"
        );
        assert_eq!(pool_rows(&line, 60, 1), [line.as_str()]);
        assert_eq!(
            pool_rows(&line, 48, 1),
            ["pool: 2 of 64 busy — one a core · parallelism 42"]
        );
        let busy = "pool: 2 of 64 busy — one a core";
        assert_eq!(
            pool_rows(&line, 40, 2),
            [busy, "parallelism 42 (work/span)"]
        );
        assert_eq!(pool_rows(&line, 20, 2), [busy, "parallelism 42"]);
        // No second row to spare: the figure goes, the busy count stays.
        assert_eq!(pool_rows(&line, 40, 1), [busy]);
        // A line without a figure is left whole (the panel cuts it).
        assert_eq!(pool_rows(busy, 10, 3), [busy]);
        assert_eq!(parallelism_text(9.94), " · parallelism 9.9 (work/span)");
    }
}
