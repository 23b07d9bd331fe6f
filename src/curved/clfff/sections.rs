//! The three sections of a curved-layer print — scaffold, buffer, model — and how they reach
//! the machine: one program with a tool per section, or one program (file) per section.
//!
//! Place in the pipeline: the last step of [`super::plan`] joins or keeps apart the sections'
//! Program layers; the pipeline writes each resulting Program with
//! [`writer_params`] and names split files with [`Section::file_name`]. Users change material
//! between the sections, so `--split-sections` gives each its own file with its own start and
//! end G-code.

use serde::Serialize;
use std::path::{Path, PathBuf};

use crate::emit::gcode::GcodeParams;
use crate::program::{Layer, Program};

/// The smallest z-hop used on the long travels of a curved-layer print, mm.
///
/// The G-code writer comes down to the next path vertically only when it hops; without a hop
/// it moves diagonally from the travel height, which could cut through a dome between two
/// points on its flanks. A travel of the curved layers is at a height already clear of the
/// material under it ([`super::travel`]); this hop only makes the descent vertical.
pub const MIN_TRAVEL_HOP_MM: f64 = 0.05;

/// One section of a curved-layer print.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Section {
    /// The planar scaffold under the shell.
    Scaffold,
    /// The buffer layer on the scaffold.
    Buffer,
    /// The model's curved layers.
    Model,
}

impl Section {
    /// Every section in print order.
    pub const ALL: [Section; 3] = [Section::Scaffold, Section::Buffer, Section::Model];

    /// The lowercase name (`scaffold`, `buffer`, `model`).
    pub fn name(self) -> &'static str {
        match self {
            Section::Scaffold => "scaffold",
            Section::Buffer => "buffer",
            Section::Model => "model",
        }
    }

    /// The file of this section when `out` is the requested output: `OUT.gcode` becomes
    /// `OUT.scaffold.gcode`, `OUT.buffer.gcode`, `OUT.model.gcode` (an output without an
    /// extension gets `.gcode`).
    pub fn file_name(self, out: &Path) -> PathBuf {
        let ext = out
            .extension()
            .map_or_else(|| "gcode".to_owned(), |e| e.to_string_lossy().into_owned());
        out.with_extension(format!("{}.{ext}", self.name()))
    }
}

/// One section's Program layers.
#[derive(Debug, Clone, PartialEq)]
pub struct SectionLayers {
    /// Which section.
    pub section: Section,
    /// The tool printing it.
    pub tool: usize,
    /// Its Program layers, in print order (indices from 0).
    pub layers: Vec<Layer>,
}

/// The sections as Programs: one with every section (`split = false`), or one per section.
/// Layer indices are renumbered from 0 in each Program.
pub fn programs(sections: &[SectionLayers], split: bool) -> Vec<(Vec<Section>, Program)> {
    let number = |layers: Vec<Layer>| -> Program {
        Program {
            layers: layers
                .into_iter()
                .enumerate()
                .map(|(i, l)| Layer { index: i, ..l })
                .collect(),
        }
    };
    let present: Vec<&SectionLayers> = sections.iter().filter(|s| !s.layers.is_empty()).collect();
    if split {
        present
            .into_iter()
            .map(|s| (vec![s.section], number(s.layers.clone())))
            .collect()
    } else {
        let names = present.iter().map(|s| s.section).collect();
        let layers = present
            .iter()
            .flat_map(|s| s.layers.iter().cloned())
            .collect();
        vec![(names, number(layers))]
    }
}

/// The G-code writer's parameters for a curved-layer print: `params` with every travel lift at
/// least [`MIN_TRAVEL_HOP_MM`].
pub fn writer_params(mut params: GcodeParams) -> GcodeParams {
    params.printer.retract_lift = params.printer.retract_lift.max(MIN_TRAVEL_HOP_MM);
    for t in &mut params.tools {
        if let Some(lift) = &mut t.travel_lift {
            *lift = lift.max(MIN_TRAVEL_HOP_MM);
        }
    }
    params
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::program::machine::Tool;

    #[test]
    fn split_files_are_named_after_the_output() {
        let out = Path::new("/tmp/dish.gcode");
        assert_eq!(
            Section::Scaffold.file_name(out),
            PathBuf::from("/tmp/dish.scaffold.gcode")
        );
        assert_eq!(
            Section::Model.file_name(Path::new("dish")),
            PathBuf::from("dish.model.gcode")
        );
    }

    #[test]
    fn every_travel_lifts_at_least_the_minimum() {
        let mut params = GcodeParams {
            tools: vec![Tool::filament(), Tool::paste()],
            ..GcodeParams::default()
        };
        params.tools[0].travel_lift = Some(0.0);
        let w = writer_params(params);
        assert_eq!(w.travel_lift(0), MIN_TRAVEL_HOP_MM);
        assert_eq!(w.travel_lift(1), w.travel_lift(1).max(MIN_TRAVEL_HOP_MM));
        assert!(w.printer.retract_lift >= MIN_TRAVEL_HOP_MM);
    }
}
