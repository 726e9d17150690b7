//! README.md's and docs/design.md's "## Keys" tables list exactly the keys
//! the app binds (`ballpit::tui::keys::TABLE`, which also drives dispatch,
//! the `?` overlay and the key bar): a key cannot be added, or dropped,
//! without both documents. A row's first cell holds its keys in
//! backticks ("`p`/`P`", "`q`, `Esc`, `Ctrl-C`", "`←`/`→`/`↑`/`↓`"); a
//! cell without backticks may say "arrows" for the four arrow keys.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use ballpit::tui::keys::TABLE;
use std::collections::BTreeSet;

/// The key names in the first column of the table under `## Keys`.
fn table_keys(markdown: &str) -> BTreeSet<String> {
    let section = markdown
        .split("\n## ")
        .find(|s| s.starts_with("Keys"))
        .expect("a \"## Keys\" section");
    let mut keys = BTreeSet::new();
    let rows = section.lines().filter(|l| l.trim_start().starts_with('|'));
    // The header row and the |---| separator come first.
    for row in rows.skip(2) {
        let cell = row
            .trim()
            .trim_start_matches('|')
            .split('|')
            .next()
            .unwrap_or("")
            .trim();
        let quoted: Vec<&str> = cell.split('`').skip(1).step_by(2).collect();
        if quoted.is_empty() {
            if cell == "arrows" {
                keys.extend(["←", "→", "↑", "↓"].map(String::from));
            } else {
                keys.insert(cell.to_string());
            }
        } else {
            keys.extend(quoted.into_iter().map(str::to_string));
        }
    }
    keys
}

fn app_keys() -> BTreeSet<String> {
    TABLE
        .iter()
        .flat_map(|b| b.presses.iter().map(|(p, _)| p.doc_name()))
        .collect()
}

#[test]
fn the_parser_reads_backticks_slashes_commas_and_words() {
    let md = "# x\n\n## Keys\n\n| key | action |\n|---|---|\n\
              | `q`, `Esc`, `Ctrl-C` | quit |\n| `p` / `P` | pool |\n\
              | `[`/`]` | tick |\n| arrows | camera |\n| `space` | pause |\n\
              | `←`/`→` | also arrows |\n\
              \n## Next\n| `z` | not a key |\n";
    let got: Vec<String> = table_keys(md).into_iter().collect();
    assert_eq!(
        got,
        [
            "Ctrl-C", "Esc", "P", "[", "]", "p", "q", "space", "←", "↑", "→", "↓"
        ]
    );
}

/// `file`'s key table against the app's: what it lacks and what it adds.
fn check(file: &str) {
    let text =
        std::fs::read_to_string(format!("{}/{file}", env!("CARGO_MANIFEST_DIR"))).expect(file);
    let doc = table_keys(&text);
    let app = app_keys();
    let missing: Vec<_> = app.difference(&doc).collect();
    let extra: Vec<_> = doc.difference(&app).collect();
    assert!(
        missing.is_empty() && extra.is_empty(),
        "{file}'s ## Keys lacks {missing:?} and lists {extra:?} that the app does not bind"
    );
}

#[test]
fn readme_keys_are_the_apps_keys() {
    check("README.md");
}

#[test]
fn design_keys_are_the_apps_keys() {
    check("docs/design.md");
}
