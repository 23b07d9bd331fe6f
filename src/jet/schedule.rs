//! Layers, blocks, direction and structures: which paths each layer prints, in which order and
//! which way round.
//!
//! Place in the pipeline: design → fill → corners → fillet → contour → **schedule** → program →
//! emit.
//!
//! - Every outline of the design is one structure. Layer `k` prints layer `k` of every
//!   structure in turn, then layer `k + 1` of all, so each structure's layer has the others'
//!   time to set before the next goes on top.
//! - Layers come in blocks of `jet.block_layers`; every odd block runs each path the other way
//!   round (and the pieces of a split outline in reverse order), so with the default 16 layers a
//!   block and 16 gap places, 32 distinct layers repeat.
//! - A closed contour of layer `k` is opened at its gap place `k mod n`
//!   ([`super::contour`]).

use super::JetSettings;
use super::contour::{GapPlaces, gap_places, open_at};
use super::corners::CornerRules;
use super::design::Outline;
use super::fill::lines;
use super::fillet::{Corner, fillet};
use super::path::Chain;

/// Line width, layer height and layer count of a job, mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JetParams {
    /// Line width, mm.
    pub width: f64,
    /// Layer height, mm.
    pub layer_height: f64,
    /// Number of layers.
    pub layers: usize,
}

/// One line of a structure after filleting: its chains and, when closed, its gap places.
#[derive(Debug, Clone, PartialEq)]
pub struct PreparedLine {
    /// The chains (one, or several where corners were split).
    pub chains: Vec<Chain>,
    /// Gap places of a closed chain.
    pub gaps: Option<GapPlaces>,
    /// Part of a fill.
    pub fill: bool,
    /// The corners of the line.
    pub corners: Vec<Corner>,
}

/// One structure: an outline of the design and its lines.
#[derive(Debug, Clone, PartialEq)]
pub struct Structure {
    /// The outline's name.
    pub name: String,
    /// Whether the outline is closed.
    pub closed: bool,
    /// Its lines (the wall, or the fill's lines).
    pub lines: Vec<PreparedLine>,
}

/// One path of a layer.
#[derive(Debug, Clone, PartialEq)]
pub struct JetPath {
    /// Index of the structure it belongs to.
    pub structure: usize,
    /// The path, open (closed contours are opened at their gap).
    pub chain: Chain,
    /// Part of a fill.
    pub fill: bool,
    /// A closed contour opened at a gap.
    pub gapped: bool,
}

/// One layer of the job.
#[derive(Debug, Clone, PartialEq)]
pub struct JetLayer {
    /// 0-based index.
    pub index: usize,
    /// Nozzle height, mm (top of the layer).
    pub z: f64,
    /// Layer height, mm.
    pub height: f64,
    /// This layer runs every path reversed.
    pub reversed: bool,
    /// Gap place index of this layer.
    pub gap_place: usize,
    /// Paths in print order.
    pub paths: Vec<JetPath>,
}

/// The outlines as structures: filled, filleted, with gap places.
pub fn prepare(outlines: &[Outline], params: &JetParams, s: &JetSettings) -> Vec<Structure> {
    let rules = CornerRules::new(s);
    outlines
        .iter()
        .map(|o| {
            let lines = lines(
                &o.points,
                o.closed,
                s.fill,
                params.width,
                s.fill_spacing,
                s.fill_angle,
            )
            .into_iter()
            .map(|l| {
                let f = fillet(&l.points, l.closed, params.width, &rules);
                let gaps = match f.chains.as_slice() {
                    [c] if c.closed => Some(gap_places(c, s.gap_positions, s.gap, params.width)),
                    _ => None,
                };
                PreparedLine {
                    chains: f.chains,
                    gaps,
                    fill: l.fill,
                    corners: f.corners,
                }
            })
            .collect();
            Structure {
                name: o.name.clone(),
                closed: o.closed,
                lines,
            }
        })
        .collect()
}

/// The layers of the job (see the [module docs](self)).
pub fn schedule(structures: &[Structure], params: &JetParams, s: &JetSettings) -> Vec<JetLayer> {
    let block = s.block_layers.max(1);
    let places = s.gap_positions.max(1);
    (0..params.layers)
        .map(|k| {
            let reversed = (k / block) % 2 == 1;
            let place = k % places;
            let mut paths = Vec::new();
            for (si, st) in structures.iter().enumerate() {
                for line in &st.lines {
                    match (&line.gaps, line.chains.as_slice()) {
                        (Some(g), [c]) => {
                            let at = g.at.get(place).copied().unwrap_or(0.0);
                            let (chain, at) = if reversed {
                                (c.reversed(), c.length() - at)
                            } else {
                                (c.clone(), at)
                            };
                            paths.push(JetPath {
                                structure: si,
                                chain: open_at(&chain, at, s.gap),
                                fill: line.fill,
                                gapped: true,
                            });
                        }
                        _ => {
                            let mut chains: Vec<Chain> = line.chains.clone();
                            if reversed {
                                chains.reverse();
                                for c in &mut chains {
                                    *c = c.reversed();
                                }
                            }
                            for c in chains {
                                paths.push(JetPath {
                                    structure: si,
                                    chain: Chain {
                                        segs: c.segs,
                                        closed: false,
                                    },
                                    fill: line.fill,
                                    gapped: false,
                                });
                            }
                        }
                    }
                }
            }
            JetLayer {
                index: k,
                z: (k + 1) as f64 * params.layer_height,
                height: params.layer_height,
                reversed,
                gap_place: place,
                paths,
            }
        })
        .collect()
}
