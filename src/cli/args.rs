//! The command-line grammar (clap derive).

use clap::{Args, Parser, Subcommand};
use conduit::scene::MeshFormat;
use std::path::PathBuf;

/// conduit: slicer plugin and file-format converter for printed electronics and non-planar printing.
#[derive(Debug, Parser)]
#[command(name = "conduit", version, about, long_about = None, propagate_version = true)]
pub struct Cli {
    /// The command to run.
    #[command(subcommand)]
    pub command: Command,
}

/// The commands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Show what is in files: meshes, 3MF builds, EAGLE designs, G-code, point clouds, SVG designs.
    Info(InfoArgs),
    /// Convert meshes between STL, 3MF and OBJ (reads STL, 3MF, OBJ, OFF, PLY), in parallel.
    Convert(ConvertArgs),
}

/// Arguments of `conduit info`.
#[derive(Debug, Args)]
pub struct InfoArgs {
    /// Files to inspect (format recognised by extension, else by content).
    #[arg(required = true, value_name = "FILE")]
    pub files: Vec<PathBuf>,
    /// Print one JSON document (an array with one entry per file) instead of text.
    #[arg(long)]
    pub json: bool,
    /// Skip the trial mesh repair (faster on huge meshes; repair findings are then omitted).
    #[arg(long)]
    pub no_repair: bool,
}

/// Arguments of `conduit convert`.
#[derive(Debug, Args)]
#[command(group(clap::ArgGroup::new("target").required(true).args(["output", "to"])))]
pub struct ConvertArgs {
    /// Mesh files to convert.
    #[arg(required = true, value_name = "IN")]
    pub inputs: Vec<PathBuf>,
    /// Output file (one input only); the format follows its extension (.stl, .3mf, .obj).
    #[arg(short, long, value_name = "OUT", conflicts_with_all = ["to", "out_dir"])]
    pub output: Option<PathBuf>,
    /// Output format for batch conversion (with --out-dir).
    #[arg(long, value_enum, value_name = "FORMAT", requires = "out_dir")]
    pub to: Option<MeshFormat>,
    /// Folder for batch outputs, named after each input's file stem.
    #[arg(long, value_name = "DIR")]
    pub out_dir: Option<PathBuf>,
    /// Repair meshes before writing (merge near vertices, drop degenerate facets, fix winding, fill holes).
    #[arg(long)]
    pub repair: bool,
    /// Write ASCII instead of binary STL.
    #[arg(long)]
    pub ascii: bool,
}
