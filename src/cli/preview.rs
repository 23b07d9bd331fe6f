//! `conduit preview`: replay a G-code file and draw it, one SVG per layer, a PNG contact sheet
//! and side views (SVG and PNG) with the curved extrusions highlighted.

use super::{Failure, args::PreviewArgs};
use anyhow::Context;
use conduit::check::moves;
use conduit::config::Flavor;
use conduit::emit::preview::{PreviewParams, layered_by_markers, write};

pub(crate) fn run(args: PreviewArgs) -> Result<(), Failure> {
    let params = PreviewParams {
        every: args.every.map(|n| n as usize),
        tile_px: args.tile,
    };
    let file = args.file.display();
    let bytes = std::fs::read(&args.file).with_context(|| format!("{file}: cannot read file"))?;
    let gcode = conduit_gcode::parse(&bytes).with_context(|| format!("{file}"))?;
    // Marlin's modes; the flavour matters only for Klipper's `G91` making E relative.
    let moves = layered_by_markers(&gcode, moves(&gcode, Flavor::Marlin));
    let files = write(&moves, &args.out_dir, &params).with_context(|| format!("{file}"))?;
    println!(
        "{file}: {} layers: {} SVG files and {} (every {} layer(s), {} tiles), side views {} in {}",
        files.svgs.len(),
        files.svgs.len(),
        files.contact_sheet.display(),
        files.every,
        files.tiles,
        files
            .side_views
            .iter()
            .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
            .collect::<Vec<_>>()
            .join(", "),
        args.out_dir.display()
    );
    Ok(())
}
