//! `conduit completions` and `conduit man`: the shell completion scripts and manual pages,
//! generated from the same command-line grammar the binary parses (`args`), so they cannot
//! drift from it.

use std::path::Path;

use anyhow::Context;
use clap::CommandFactory;
use conduit::scene::OutputSet;

use super::Failure;
use super::args::{Cli, CompletionsArgs, ManArgs};

/// Prints the completion script for one shell.
pub(crate) fn completions(args: CompletionsArgs) -> Result<(), Failure> {
    let mut script = Vec::new();
    clap_complete::generate(args.shell, &mut Cli::command(), "conduit", &mut script);
    out!("{}", String::from_utf8_lossy(&script))
}

/// Writes `conduit.1` and `conduit-COMMAND.1` (and `conduit-COMMAND-SUB.1` for nested
/// commands) into the folder, all or nothing.
pub(crate) fn man(args: ManArgs) -> Result<(), Failure> {
    std::fs::create_dir_all(&args.out_dir)
        .with_context(|| format!("{}: cannot create the folder", args.out_dir.display()))?;
    let mut root = Cli::command();
    // Building gives every subcommand its display name (`conduit-slice`), the page's name.
    root.build();
    let mut pages = Vec::new();
    collect_pages(&root, &mut pages)?;
    let mut set = OutputSet::new(&[] as &[&Path]);
    for (name, page) in &pages {
        set.add(&args.out_dir.join(format!("{name}.1")), page)?;
    }
    set.commit()?;
    outln!("{} manual pages in {}", pages.len(), args.out_dir.display())
}

/// The page of `cmd` and of every subcommand below it, named by their display names.
fn collect_pages(cmd: &clap::Command, pages: &mut Vec<(String, Vec<u8>)>) -> Result<(), Failure> {
    let name = cmd.get_display_name().unwrap_or(cmd.get_name()).to_owned();
    let mut page = Vec::new();
    clap_mangen::Man::new(cmd.clone())
        .render(&mut page)
        .with_context(|| format!("rendering the manual page {name}"))?;
    pages.push((name, page));
    for sub in cmd.get_subcommands().filter(|s| s.get_name() != "help") {
        collect_pages(sub, pages)?;
    }
    Ok(())
}
