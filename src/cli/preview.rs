//! `conduit preview`: replay a G-code file and draw it, one SVG per layer, a PNG contact sheet
//! and side views (SVG and PNG) with the curved extrusions highlighted.

use super::{Failure, args::PreviewArgs};
use anyhow::Context;
use conduit::check::{Firmware, moves};
use conduit::emit::preview::{
    CONTACT_SHEET, PreviewParams, SIDE_VIEWS, layered_by_markers, render,
};
use conduit::scene::OutputSet;

pub(crate) fn run(args: PreviewArgs) -> Result<(), Failure> {
    let params = PreviewParams {
        every: args.every.map(|n| n as usize),
        tile_px: args.tile,
    };
    let file = args.file.display();
    let bytes = super::check::read_gcode_file(&args.file)?;
    let gcode = conduit_gcode::parse(&bytes).with_context(|| format!("{file}"))?;
    // Marlin's modes; the flavour matters only for Klipper's `G91` making E relative.
    let moves = layered_by_markers(&gcode, moves(&gcode, Firmware::Marlin));
    let drawn = render(&moves, &params).with_context(|| format!("{file}"))?;
    let dir = &args.out_dir;
    std::fs::create_dir_all(dir)
        .with_context(|| format!("{}: cannot create the folder", dir.display()))?;
    // All the files or none: a run that fails on the tenth layer leaves no mix of new and old.
    let mut outputs = OutputSet::new([&args.file]);
    for (name, bytes) in &drawn.files {
        outputs.add(&dir.join(name), bytes)?;
    }
    outputs.commit()?;
    if args.json {
        return super::print_json(&serde_json::json!({
            "outputs": drawn.files.iter().map(|(name, _)| dir.join(name).display().to_string()).collect::<Vec<_>>(),
            "layers": drawn.layers,
            "every": drawn.every,
            "tiles": drawn.tiles,
        }));
    }
    outln!(
        "{file}: {} layers: {} SVG files and {} (every {} layer(s), {} tiles), side views {} in {}",
        drawn.layers,
        drawn.layers,
        dir.join(CONTACT_SHEET).display(),
        drawn.every,
        drawn.tiles,
        SIDE_VIEWS.join(", "),
        dir.display()
    )?;
    Ok(())
}
