//! The real binary with 100 000 spheres in a pseudo-terminal: it draws
//! frames, the physics advances, keys are answered, and Reset makes the
//! preset again. No speed figure is
//! asserted (the machine may be loaded); the deadlines are generous.
use crate::common::pty;

/// The value after `label` on the readouts line that has it.
fn readout<'a>(screen: &'a str, label: &str) -> Option<&'a str> {
    screen.lines().find_map(|l| {
        let pat = format!("│{label} ");
        let i = l.find(pat.as_str())? + pat.len();
        l[i..].split('│').next().map(str::trim)
    })
}

/// The first number of a readout.
fn number(screen: &str, label: &str) -> Option<f64> {
    readout(screen, label)?
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}

#[test]
fn a_hundred_thousand_spheres_are_drawn_and_keys_answered() {
    let args = [
        "--count",
        "100000",
        "--radius",
        "0.002285",
        "--threading",
        "pool",
        "--threads",
        "2",
    ];
    let mut app = pty::start_with(&args, None, (40, 120), "xterm-256color");
    let s = app.wait_for("frames with steps", 60.0, |s| {
        number(s, "fps").is_some_and(|f| f > 0.0) && number(s, "steps/s").is_some_and(|f| f > 0.0)
    });
    assert_eq!(readout(&s, "count"), Some("100000"), "{s}");
    // Braille dots on the canvas: the spheres are drawn.
    assert!(
        s.chars()
            .filter(|c| ('\u{2801}'..='\u{28ff}').contains(c))
            .count()
            > 500
    );
    // swept keeps every sphere inside and apart.
    let overlap = readout(&s, "overlap").unwrap_or_default();
    assert!(overlap.ends_with("escaped 0"), "{s}");
    assert!(number(&s, "overlap").is_some_and(|o| o <= 1e-9), "{s}");
    // A key changes the picture's style while the physics runs.
    app.send("v");
    app.wait_for("the next style", 20.0, |s| {
        readout(s, "style").is_some_and(|v| v.starts_with("braille, depth"))
    });
    // Halving the count, then Reset: the preset is made again, all of it.
    app.send("n");
    app.wait_for("half the spheres", 20.0, |s| {
        readout(s, "count") == Some("50000")
    });
    app.send("0");
    let s = app.wait_for("the start again", 20.0, |s| {
        readout(s, "count") == Some("100000")
    });
    assert!(!s.contains("reset:"), "{s}");
    app.send("q");
    let st = app.wait_exit(20.0).expect("q ends the app");
    assert!(st.success(), "exit {st:?}");
}
