//! docs/design.md's command-line synopsis against clap's definition
//! (`ballpit::cli::Cli` through `CommandFactory`): the same subcommands, and
//! each with the same long flags, so a command or a flag cannot be added,
//! or dropped, without the contract.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a failed unwrap is a failed test
use ballpit::cli::Cli;
use clap::CommandFactory;
use std::collections::{BTreeMap, BTreeSet};

const DESIGN: &str = include_str!("../../docs/design.md");

/// The `--flag` names in `text`.
fn flags(text: &str) -> BTreeSet<String> {
    text.split(|c: char| c.is_whitespace() || c == '[' || c == ']')
        .filter_map(|t| t.strip_prefix("--"))
        .map(|t| {
            t.chars()
                .take_while(|c| c.is_ascii_lowercase() || *c == '-')
                .collect::<String>()
        })
        .filter(|t| !t.is_empty())
        .collect()
}

/// The synopsis: for each command (`""` for the app itself) the long flags
/// its line gives, with `SCENE FLAGS` and `RUN FLAGS` read from the groups
/// the block defines below the command lines.
fn synopsis(design: &str) -> BTreeMap<String, BTreeSet<String>> {
    let section = design
        .split("\n## ")
        .find(|s| s.starts_with("Command line"))
        .expect("design.md has a \"## Command line\" section");
    let block = section
        .split("```text\n")
        .nth(1)
        .and_then(|b| b.split("```").next())
        .expect("a text block in it");
    // Groups: a line that starts with the group's name, and the indented
    // lines under it.
    let mut groups: BTreeMap<&str, BTreeSet<String>> = BTreeMap::new();
    let mut current = None;
    for line in block.lines() {
        if let Some(name) = ["SCENE FLAGS", "RUN FLAGS"]
            .into_iter()
            .find(|g| line.starts_with(g))
        {
            current = Some(name);
            groups
                .entry(name)
                .or_default()
                .extend(flags(&line[name.len()..]));
        } else if line.starts_with(' ') {
            if let Some(name) = current {
                groups.entry(name).or_default().extend(flags(line));
            }
        } else {
            current = None;
        }
    }
    let mut commands = BTreeMap::new();
    for line in block.lines().filter(|l| l.starts_with("ballpit")) {
        let second = line.split_whitespace().nth(1).unwrap_or("");
        let name = if second
            .chars()
            .next()
            .is_some_and(|c| c.is_ascii_lowercase())
        {
            second.to_string()
        } else {
            String::new()
        };
        let mut set = flags(line);
        for (group, members) in &groups {
            if line.contains(group) {
                set.extend(members.iter().cloned());
            }
        }
        assert!(
            commands.insert(name.clone(), set).is_none(),
            "`{name}` twice in the synopsis"
        );
    }
    commands
}

/// clap's commands and their long flags, `--help` and `--version` aside.
fn clap_commands() -> BTreeMap<String, BTreeSet<String>> {
    let cli = Cli::command();
    let longs = |c: &clap::Command| -> BTreeSet<String> {
        c.get_arguments()
            .filter_map(|a| a.get_long())
            .filter(|l| !matches!(*l, "help" | "version"))
            .map(str::to_string)
            .collect()
    };
    let mut out = BTreeMap::new();
    out.insert(String::new(), longs(&cli));
    for sub in cli.get_subcommands().filter(|s| s.get_name() != "help") {
        out.insert(sub.get_name().to_string(), longs(sub));
    }
    out
}

#[test]
fn the_parser_reads_commands_groups_and_flags() {
    let md = "# d\n\n## Command line\n\n```text\n\
              ballpit [SCENE FLAGS] [--fps F]\n\
              ballpit bench [SCENE FLAGS] --steps K\n\
              ballpit man\n\n\
              SCENE FLAGS  --scene NAME  --count N (0..9)\n\
              \x20            --seed S\n\
              ```\n\n## Next\n";
    let got = synopsis(md);
    let set = |v: &[&str]| v.iter().map(ToString::to_string).collect::<BTreeSet<_>>();
    assert_eq!(got[""], set(&["count", "fps", "scene", "seed"]));
    assert_eq!(got["bench"], set(&["count", "scene", "seed", "steps"]));
    assert_eq!(got["man"], set(&[]));
    assert_eq!(got.len(), 3);
}

#[test]
fn design_synopsis_is_clap_s_commands_and_flags() {
    let doc = synopsis(DESIGN);
    let cli = clap_commands();
    let doc_names: BTreeSet<_> = doc.keys().collect();
    let cli_names: BTreeSet<_> = cli.keys().collect();
    assert_eq!(
        doc_names, cli_names,
        "design.md's synopsis names these commands, clap these"
    );
    for (name, flags) in &cli {
        assert_eq!(
            &doc[name], flags,
            "`ballpit {name}`: design.md's synopsis gives these flags, clap these"
        );
    }
}
