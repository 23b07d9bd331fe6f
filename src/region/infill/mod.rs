//! Infill patterns: one file per pattern behind [`InfillPattern`], on shared line machinery.
//!
//! Every pattern here is made of straight lines on a lattice anchored at the origin
//! ([`lines`]): generated in scaled integer coordinates, clipped to the area in one scan-line
//! sweep ([`scanline`]), joined into zig-zags by links along the area's boundary
//! (around holes too) and ordered nearest-first.
//!
//! The area handed to a pattern is where line *centrelines* may go (see
//! [`super::perimeters`]): lines run right up to its boundary. `spacing_mm` is the distance
//! between neighbouring lines *at the density wanted*, so a pattern's total line length per unit
//! area is `1 / spacing_mm` whatever its geometry: sparse infill at density `d` is asked for
//! `solid spacing / d`, and a pattern with `m` line directions spaces each family `m · spacing_mm`
//! apart.
//!
//! - [`Rectilinear`]: one family, turned 90° every layer; solid infill uses it at 100 %.
//! - [`Grid`]: both directions on every layer.
//! - [`Triangles`]: three families at 60° meeting in common points, so each layer is a lattice of
//!   equilateral triangles. Chosen as the third pattern over gyroid because it is stiff in every
//!   in-plane direction (triangles cannot shear, grid squares can), reuses the exact
//!   integer line clipping (gyroid needs curve flattening and the layer's z, which this trait
//!   does not carry), and stacks into vertical walls, so it needs no bridging between layers.

mod grid;
pub mod lines;
mod rectilinear;
mod scanline;
mod triangles;

pub use grid::Grid;
pub use rectilinear::Rectilinear;
pub use triangles::Triangles;

use super::params::InfillPatternKind;
use crate::geom::{ExPolygon, Polyline};

/// A way to fill an area with extrusion centrelines.
pub trait InfillPattern {
    /// Short lowercase name, as in configuration files (`"rectilinear"`).
    fn name(&self) -> &'static str;
    /// Centrelines filling `area` with an average distance of `spacing_mm` between neighbouring
    /// lines (total length ≈ area / spacing). `layer_index` lets a pattern vary between layers.
    /// Invalid spacings (not finite, or below 1 nm) give no lines.
    fn fill(&self, area: &[ExPolygon], spacing_mm: f64, layer_index: usize) -> Vec<Polyline>;
}

/// The pattern for `kind`, with its lines based on `angle_deg` (degrees from +X) and joined into
/// zig-zags.
pub fn pattern(kind: InfillPatternKind, angle_deg: f64) -> Box<dyn InfillPattern + Send + Sync> {
    match kind {
        InfillPatternKind::Rectilinear => Box::new(Rectilinear::new(angle_deg)),
        InfillPatternKind::Grid => Box::new(Grid::new(angle_deg)),
        InfillPatternKind::Triangles => Box::new(Triangles::new(angle_deg)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::region::test_util::{rect, square_island, total_area, total_length};

    /// A 100 mm square with a 30 mm square hole.
    fn holed() -> Vec<ExPolygon> {
        let mut hole = rect(35.0, 35.0, 65.0, 65.0);
        hole.points.reverse();
        let mut ex = square_island(0.0, 0.0, 100.0);
        ex.holes.push(hole);
        vec![ex]
    }

    #[test]
    fn every_pattern_gives_the_requested_density() {
        let area = holed();
        let solid_spacing = 0.407;
        for kind in [
            InfillPatternKind::Rectilinear,
            InfillPatternKind::Grid,
            InfillPatternKind::Triangles,
        ] {
            for density in [0.15, 0.2, 0.4] {
                let spacing = solid_spacing / density;
                // Loose lines: connectors along the boundary are extra material on purpose.
                let p: Box<dyn InfillPattern> = match kind {
                    InfillPatternKind::Rectilinear => Box::new(Rectilinear {
                        angle_deg: 45.0,
                        connect: false,
                    }),
                    InfillPatternKind::Grid => Box::new(Grid {
                        angle_deg: 45.0,
                        connect: false,
                    }),
                    InfillPatternKind::Triangles => Box::new(Triangles {
                        angle_deg: 45.0,
                        connect: false,
                    }),
                };
                for layer in 0..2 {
                    let lines = p.fill(&area, spacing, layer);
                    let got = total_length(&lines) * solid_spacing / total_area(&area);
                    assert!(
                        (got - density).abs() <= 0.05 * density,
                        "{} at {density}, layer {layer}: {got}",
                        p.name()
                    );
                }
            }
        }
    }

    #[test]
    fn factory_names_match_config_names() {
        for kind in [
            InfillPatternKind::Rectilinear,
            InfillPatternKind::Grid,
            InfillPatternKind::Triangles,
        ] {
            let json = serde_json::to_string(&kind).unwrap_or_default();
            assert_eq!(json.trim_matches('"'), pattern(kind, 45.0).name());
        }
    }
}
