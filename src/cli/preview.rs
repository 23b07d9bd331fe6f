//! `conduit preview`: replay a G-code file and draw it, one SVG per layer, a PNG contact sheet
//! and side views (SVG and PNG) with the curved extrusions highlighted and the placed parts
//! labelled. Layer views left in the folder by an earlier run with more layers are removed once
//! the new files are in place.

use std::path::{Path, PathBuf};

use super::{Failure, args::PreviewArgs};
use anyhow::Context;
use conduit::check::{Firmware, moves};
use conduit::emit::preview::{
    CONTACT_SHEET, PartMark, PartMethod, PreviewParams, SIDE_VIEWS, is_layer_file_name,
    layered_by_markers, placed_parts, render,
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
    let parts = placed_parts(&gcode, &moves);
    let drawn = render(&moves, &parts, &params).with_context(|| format!("{file}"))?;
    let dir = &args.out_dir;
    std::fs::create_dir_all(dir)
        .with_context(|| format!("{}: cannot create the folder", dir.display()))?;
    // All the files or none: a run that fails on the tenth layer leaves no mix of new and old.
    let mut outputs = OutputSet::new([&args.file]);
    for (name, bytes) in &drawn.files {
        outputs.add(&dir.join(name), bytes)?;
    }
    outputs.commit()?;
    let removed = remove_stale_layers(dir, drawn.files.iter().map(|(n, _)| n.as_str()))?;
    if args.json {
        return super::print_json(&serde_json::json!({
            "outputs": drawn.files.iter().map(|(name, _)| dir.join(name).display().to_string()).collect::<Vec<_>>(),
            "removed": super::paths(removed.iter().map(PathBuf::as_path)),
            "layers": drawn.layers,
            "every": drawn.every,
            "tiles": drawn.tiles,
            "parts": parts.iter().map(part_json).collect::<Vec<_>>(),
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
    if !parts.is_empty() {
        let list: Vec<String> = parts
            .iter()
            .map(|p| {
                let how = match p.method {
                    PartMethod::Machine => "",
                    PartMethod::Hand => ", by hand",
                };
                format!("{} (layer {}{how})", p.name, p.layer + 1)
            })
            .collect();
        outln!("parts labelled: {}", list.join(", "))?;
    }
    if !removed.is_empty() {
        outln!(
            "removed {} layer view(s) of an earlier run: {}",
            removed.len(),
            super::paths(removed.iter().map(PathBuf::as_path)).join(", ")
        )?;
    }
    Ok(())
}

/// A part of the `--json` summary: its name, how it is placed, its 1-based layer, and its
/// position and rotation (`null` for a part inserted by hand).
fn part_json(p: &PartMark) -> serde_json::Value {
    let [x, y, z] = p.position.map_or([None; 3], |v| v.map(Some));
    serde_json::json!({
        "name": p.name,
        "method": match p.method {
            PartMethod::Machine => "machine",
            PartMethod::Hand => "hand",
        },
        "layer": p.layer + 1,
        "line": p.line,
        "x": x,
        "y": y,
        "z": z,
        "rotation": p.position.map(|_| p.rotation_deg),
    })
}

/// Removes the layer views ([`is_layer_file_name`]: `layer_` + digits + `.svg`, regular files
/// only) in `dir` that are not among `written`, and returns their paths, sorted. Nothing else
/// in the folder is touched.
fn remove_stale_layers<'a>(
    dir: &Path,
    written: impl IntoIterator<Item = &'a str>,
) -> anyhow::Result<Vec<PathBuf>> {
    let written: std::collections::BTreeSet<&str> = written.into_iter().collect();
    let mut stale = Vec::new();
    let entries =
        std::fs::read_dir(dir).with_context(|| format!("{}: cannot list", dir.display()))?;
    for entry in entries {
        let entry = entry.with_context(|| format!("{}: cannot list", dir.display()))?;
        let name = entry.file_name();
        let Some(name) = name.to_str() else {
            continue;
        };
        let regular = entry.file_type().is_ok_and(|t| t.is_file());
        if regular && is_layer_file_name(name) && !written.contains(name) {
            stale.push(entry.path());
        }
    }
    stale.sort();
    for path in &stale {
        std::fs::remove_file(path).with_context(|| {
            format!(
                "{}: cannot remove this layer view of an earlier run",
                path.display()
            )
        })?;
    }
    Ok(stale)
}
