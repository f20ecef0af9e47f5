//! `docs/cli.md` documents the command line: a section for every command (`### \`hpge-cv fit\``),
//! naming each of its flags (a test: a flag added to a command without a word in the reference
//! fails it).

use clap::CommandFactory;

/// The commands without subcommands, each with its path of names (`["validate", "coverage"]`).
fn leaves(cmd: &clap::Command, path: &[String], out: &mut Vec<(Vec<String>, clap::Command)>) {
    let subs: Vec<&clap::Command> = cmd
        .get_subcommands()
        .filter(|c| c.get_name() != "help" && !c.is_hide_set())
        .collect();
    if subs.is_empty() {
        out.push((path.to_vec(), cmd.clone()));
        return;
    }
    for s in subs {
        let mut p = path.to_vec();
        p.push(s.get_name().to_string());
        leaves(s, &p, out);
    }
}

/// `text` names `flag` as a whole word (`--grid` is not found in `--grids` or `--grid-x`).
fn mentions(text: &str, flag: &str) -> bool {
    text.match_indices(flag).any(|(i, _)| {
        let next = text[i + flag.len()..].chars().next();
        !next.is_some_and(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
    })
}

/// The text of the section `### \`NAME\`` up to the next heading.
fn section(doc: &str, name: &str) -> Option<String> {
    let head = format!("### `{name}`");
    let mut lines = doc.lines().skip_while(|l| l.trim_end() != head);
    lines.next()?;
    Some(
        lines
            .take_while(|l| !l.starts_with('#'))
            .collect::<Vec<_>>()
            .join("\n"),
    )
}

#[test]
fn mentions_matches_whole_flags_only() {
    assert!(mentions("[--grid KEY=VALUE]", "--grid"));
    assert!(mentions("`--grid`", "--grid"));
    assert!(!mentions("[--grids N]", "--grid"));
    assert!(!mentions("[--exact-grids N]", "--grid"));
    assert!(!mentions("[--grid-x N]", "--grid"));
}

#[test]
fn docs_cli_md_has_a_section_for_every_command_naming_each_of_its_flags() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/docs/cli.md");
    let doc = std::fs::read_to_string(path).expect("docs/cli.md");
    let mut commands = Vec::new();
    leaves(&super::Cli::command(), &[], &mut commands);
    assert!(commands.len() > 20, "{} commands", commands.len());
    let mut missing = Vec::new();
    for (names, cmd) in &commands {
        let name = format!("hpge-cv {}", names.join(" "));
        let Some(row) = section(&doc, &name) else {
            missing.push(format!("no section for `{name}`"));
            continue;
        };
        let row = row.as_str();
        for a in cmd.get_arguments() {
            let Some(long) = a.get_long() else { continue };
            if a.is_hide_set() || matches!(long, "help" | "version") {
                continue;
            }
            if !mentions(row, &format!("--{long}")) {
                missing.push(format!("`{name}`: --{long}"));
            }
        }
    }
    assert!(
        missing.is_empty(),
        "docs/cli.md lacks {} entries:\n{}",
        missing.len(),
        missing.join("\n")
    );
}
