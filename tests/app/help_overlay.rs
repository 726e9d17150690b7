//! The `?` overlay holds the whole key table at every screen size the app
//! draws at: read back from the drawn screen, each binding's keys and its
//! description, in the table's order, in one column or two.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use crate::common::screen;
use ballpit::cpu::{CpuReport, ThreadLoad, ThreadRole};
use ballpit::engine::Engine;
use ballpit::physics::{Sphere, World};
use ballpit::tui::canvas::Raster;
use ballpit::tui::keys::TABLE;
use ballpit::tui::layout::{self, MIN_HEIGHT, MIN_WIDTH, View};
use ballpit::tui::readouts::Stats;
use ballpit::tui::state::AppState;
use ballpit::tui::theme::Palette;
use glam::DVec3;
use ratatui::Terminal;
use ratatui::backend::TestBackend;

/// The overlay's key column, its leading space included (`help.rs`).
const KEY_W: usize = 10;

fn screen(w: u16, h: u16) -> Vec<Vec<char>> {
    let settings = screen::settings(2);
    let spheres = vec![Sphere::new(DVec3::splat(0.5), DVec3::X, 0.1)];
    let engine = Engine::new(World::new(1.0, spheres), settings).unwrap();
    let mut state = AppState::new(&settings, 1, 0.1, 30.0);
    state.help = true;
    let report = CpuReport {
        threads: ["main", "physics"]
            .map(|name| ThreadLoad {
                tid: 1,
                role: ThreadRole::of(name),
                name: name.into(),
                percent: 10.0,
                cpu_seconds: 1.0,
                history: vec![10.0; 60],
            })
            .to_vec(),
        total_percent: 20.0,
        cores: 2,
        others_percent: None,
    };
    let view = View {
        state: &state,
        snap: engine.snapshot(),
        stats: &Stats::default(),
        report: &report,
        palette: Palette::C16,
        aspect: 2.0,
    };
    let mut t = Terminal::new(TestBackend::new(w, h)).unwrap();
    t.draw(|f| layout::draw(f, &mut Raster::new(), &view))
        .unwrap();
    let buf = t.backend().buffer();
    (0..h)
        .map(|y| {
            (0..w)
                .map(|x| buf[(x, y)].symbol().chars().next().unwrap_or(' '))
                .collect()
        })
        .collect()
}

/// The overlay's inside: the rows between its corners, the columns
/// between its sides.
fn inside(grid: &[Vec<char>]) -> Vec<Vec<char>> {
    let text = |r: &[char]| r.iter().collect::<String>();
    let top = grid
        .iter()
        .position(|r| text(r).contains("┌ keys "))
        .unwrap();
    let left = grid[top].iter().position(|&c| c == '┌').unwrap();
    let right = left + grid[top][left..].iter().position(|&c| c == '┐').unwrap();
    let bottom = top + grid[top..].iter().position(|r| r[left] == '└').unwrap();
    grid[top + 1..bottom]
        .iter()
        .map(|r| r[left + 1..right].to_vec())
        .collect()
}

/// A column `width` wide from `x`: (keys, description) a binding, the
/// description's wrapped rows joined by spaces.
fn read_column(rows: &[Vec<char>], x: usize, width: usize) -> Vec<(String, String)> {
    let cut = |r: &[char], a: usize, b: usize| -> String {
        r[a.min(r.len())..b.min(r.len())]
            .iter()
            .collect::<String>()
            .trim()
            .to_string()
    };
    let mut out: Vec<(String, String)> = Vec::new();
    for r in rows {
        let (key, text) = (cut(r, x, x + KEY_W), cut(r, x + KEY_W, x + width));
        match out.last_mut() {
            _ if !key.is_empty() => out.push((key, text)),
            Some(last) if !text.is_empty() => {
                last.1.push(' ');
                last.1.push_str(&text);
            }
            _ => {}
        }
    }
    out
}

fn assert_whole_table(w: u16, h: u16) {
    let grid = screen(w, h);
    let rows = inside(&grid);
    let want: Vec<(String, String)> = TABLE.iter().map(|b| (b.keys(), b.help.into())).collect();
    let width = rows[0].len();
    let one = read_column(&rows, 0, width);
    let mut two = read_column(&rows, 0, width / 2);
    two.extend(read_column(&rows, width / 2, width));
    let all: String = grid
        .iter()
        .map(|r| r.iter().collect::<String>() + "\n")
        .collect();
    assert!(
        one == want || two == want,
        "{w}x{h}: the table is not all there\n{all}"
    );
    assert!(all.contains("? or Esc closes this help"), "{w}x{h}\n{all}");
}

#[test]
fn every_key_is_in_the_help_at_80x24_and_120x40() {
    assert_whole_table(80, 24);
    assert_whole_table(120, 40);
}

/// Too few rows for one binding a row: two columns, every key still there.
#[test]
fn at_the_smallest_screen_the_help_takes_two_columns_and_holds_every_key() {
    assert!(
        usize::from(MIN_HEIGHT) < TABLE.len() + 3,
        "no longer too short"
    );
    assert_whole_table(MIN_WIDTH, MIN_HEIGHT);
    assert_whole_table(100, MIN_HEIGHT);
}
