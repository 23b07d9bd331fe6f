//! The tool as a solid of revolution above its tip: the one shape every check of "what can the
//! nozzle hit" uses.
//!
//! Place in the pipeline: vocabulary. A stage builds its tool from its own settings — the FFF
//! head of `[curved]` ([`ToolSolid::fff_head`]) or the dispensing nozzle of `[conform]`
//! ([`ToolSolid::needle_nozzle`]) — and the checks ask it: the curved tops and the curved-layer
//! replay ([`super::replay`] over printed material), conform's corrections, clearance pass,
//! report and replay (its contacts with a scanned surface, [`super::contact`]).
//!
//! A solid is a stack of [`Piece`]s along the tool axis, each a disc, a cylinder or a cone
//! frustum, with the height range it covers above the tip. Its queries are here: the radius at
//! a height above the tip ([`ToolSolid::radius_at`]), the lowest point at a horizontal distance
//! from the axis ([`ToolSolid::floor_at`]), the widest radius ([`ToolSolid::widest`], also up
//! to a height), the tip's radius, the shoulder (where it first gets wider than the tip) and the
//! top.

use serde::Serialize;

/// Which part of the tool a piece is, as checks and reports name it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ToolPart {
    /// The flat end of the nozzle at the tip.
    Tip,
    /// The straight needle above the tip.
    Needle,
    /// A cone around the nozzle (the FFF head's, or the one above a needle).
    Cone,
    /// The carriage around the nozzle axis.
    Carriage,
}

/// The shape of one piece, with its radii (mm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PieceShape {
    /// A flat disc of `radius` at the piece's bottom (its height is 0).
    Disc {
        /// Radius, mm.
        radius: f64,
    },
    /// A cylinder of `radius`.
    Cylinder {
        /// Radius, mm.
        radius: f64,
    },
    /// A cone frustum widening upward from `radius` at its bottom at `angle_deg` from the axis.
    Cone {
        /// Radius at the bottom, mm (0: the apex).
        radius: f64,
        /// Half-angle from the axis, degrees.
        angle_deg: f64,
        /// `tan(angle_deg)`, computed once.
        tan: f64,
    },
}

/// One piece of a [`ToolSolid`]: a shape covering `bottom ..= bottom + height` above the tip.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Piece {
    /// What the piece is.
    pub part: ToolPart,
    /// Its shape.
    pub shape: PieceShape,
    /// Height of its bottom above the tip, mm.
    pub bottom: f64,
    /// Its height, mm (0 for a disc; infinite for a carriage open upward).
    pub height: f64,
}

impl Piece {
    /// Whether the piece reaches `rise` mm above the tip.
    fn covers(&self, rise: f64) -> bool {
        rise >= self.bottom && rise - self.bottom <= self.height
    }

    /// Its radius at `rise` (within its range), mm.
    fn radius_at(&self, rise: f64) -> f64 {
        match self.shape {
            PieceShape::Disc { radius } | PieceShape::Cylinder { radius } => radius,
            PieceShape::Cone { radius, tan, .. } => radius + (rise - self.bottom) * tan,
        }
    }

    /// Its widest radius, mm.
    pub fn widest(&self) -> f64 {
        match self.shape {
            PieceShape::Disc { radius } | PieceShape::Cylinder { radius } => radius,
            PieceShape::Cone { radius, tan, .. } => radius + self.height * tan,
        }
    }

    /// Its widest radius from its bottom up to `rise` (at or above its bottom), mm.
    fn widest_up_to(&self, rise: f64) -> f64 {
        match self.shape {
            PieceShape::Disc { radius } | PieceShape::Cylinder { radius } => radius,
            PieceShape::Cone { radius, tan, .. } => {
                radius + (rise - self.bottom).min(self.height) * tan
            }
        }
    }

    /// Its radius at its bottom, mm.
    pub fn bottom_radius(&self) -> f64 {
        match self.shape {
            PieceShape::Disc { radius }
            | PieceShape::Cylinder { radius }
            | PieceShape::Cone { radius, .. } => radius,
        }
    }

    /// Height above the tip of the piece's lowest point at `distance` from the axis, mm: its
    /// bottom inside its bottom radius, up the cone's side beyond it. Not limited to the
    /// piece's widest radius.
    pub fn floor_at(&self, distance: f64) -> f64 {
        match self.shape {
            PieceShape::Cone { radius, tan, .. } if distance > radius => {
                self.bottom + (distance - radius) / tan
            }
            _ => self.bottom,
        }
    }

    /// Top of the piece above the tip, mm.
    pub fn top(&self) -> f64 {
        self.bottom + self.height
    }
}

/// The tool as a stack of pieces along its axis, from the tip upward (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct ToolSolid {
    pieces: Vec<Piece>,
}

impl ToolSolid {
    /// A solid of these pieces (lowest first).
    pub fn new(pieces: Vec<Piece>) -> Self {
        Self { pieces }
    }

    /// The FFF print head (`[curved]` head keys): a cone with its apex at the tip opening at
    /// `angle_deg` from the vertical up to `height`, plus, when `carriage_radius > 0`, a
    /// cylinder of that radius from `carriage_clearance` above the tip upward.
    pub fn fff_head(
        angle_deg: f64,
        height: f64,
        carriage_radius: f64,
        carriage_clearance: f64,
    ) -> Self {
        let mut pieces = vec![Piece {
            part: ToolPart::Cone,
            shape: PieceShape::Cone {
                radius: 0.0,
                angle_deg,
                tan: angle_deg.to_radians().tan(),
            },
            bottom: 0.0,
            height,
        }];
        if carriage_radius > 0.0 {
            pieces.push(Piece {
                part: ToolPart::Carriage,
                shape: PieceShape::Cylinder {
                    radius: carriage_radius,
                },
                bottom: carriage_clearance,
                height: f64::INFINITY,
            });
        }
        Self { pieces }
    }

    /// The dispensing nozzle (`[conform]` nozzle keys): the tip disc of diameter `outer`, a
    /// needle of that diameter rising `needle_length`, then, when both are positive, a cone
    /// widening at `cone_angle_deg` from the vertical for `cone_height`.
    pub fn needle_nozzle(
        outer: f64,
        needle_length: f64,
        cone_angle_deg: f64,
        cone_height: f64,
    ) -> Self {
        let ro = outer / 2.0;
        let mut pieces = vec![
            Piece {
                part: ToolPart::Tip,
                shape: PieceShape::Disc { radius: ro },
                bottom: 0.0,
                height: 0.0,
            },
            Piece {
                part: ToolPart::Needle,
                shape: PieceShape::Cylinder { radius: ro },
                bottom: 0.0,
                height: needle_length,
            },
        ];
        let tan = cone_angle_deg.to_radians().tan();
        if tan > 0.0 && cone_height > 0.0 {
            pieces.push(Piece {
                part: ToolPart::Cone,
                shape: PieceShape::Cone {
                    radius: ro,
                    angle_deg: cone_angle_deg,
                    tan,
                },
                bottom: needle_length,
                height: cone_height,
            });
        }
        Self { pieces }
    }

    /// The pieces, lowest first.
    pub fn pieces(&self) -> &[Piece] {
        &self.pieces
    }

    /// The solid's radius at `rise` mm above the tip and the part that is widest there (the
    /// lower piece on a tie); `None` at or below the tip and where the solid has no extent.
    pub fn radius_at(&self, rise: f64) -> Option<(f64, ToolPart)> {
        if rise <= 0.0 {
            return None;
        }
        let mut best: Option<(f64, ToolPart)> = None;
        for piece in self.pieces.iter().filter(|p| p.covers(rise)) {
            let r = piece.radius_at(rise);
            if best.is_none_or(|(b, _)| r > b) {
                best = Some((r, piece.part));
            }
        }
        best
    }

    /// Height above the tip of the solid's lowest point at `distance` mm from its axis; `None`
    /// beyond its widest radius.
    pub fn floor_at(&self, distance: f64) -> Option<f64> {
        self.pieces
            .iter()
            .filter(|p| distance <= p.widest())
            .map(|p| p.floor_at(distance))
            .reduce(f64::min)
    }

    /// The widest the solid gets, mm.
    pub fn widest(&self) -> f64 {
        self.pieces.iter().map(Piece::widest).fold(0.0, f64::max)
    }

    /// The widest the solid gets from its tip up to `rise` mm above it, mm.
    pub fn widest_up_to(&self, rise: f64) -> f64 {
        self.pieces
            .iter()
            .filter(|p| rise >= p.bottom)
            .map(|p| p.widest_up_to(rise))
            .fold(0.0, f64::max)
    }

    /// Radius of the solid at the tip (its tip disc), mm; 0 for a cone's apex.
    pub fn tip_radius(&self) -> f64 {
        self.pieces
            .iter()
            .filter(|p| p.bottom == 0.0)
            .map(Piece::bottom_radius)
            .fold(0.0, f64::max)
    }

    /// Height above the tip where the solid starts getting wider than its tip (the bottom of
    /// the lowest cone, or of a wider piece), mm; its top when it never does. Surface lower
    /// than this beside the tip disc cannot touch the solid.
    pub fn shoulder(&self) -> f64 {
        let tip = self.tip_radius();
        self.pieces
            .iter()
            .find(|p| matches!(p.shape, PieceShape::Cone { .. }) || p.widest() > tip)
            .map_or_else(|| self.top(), |p| p.bottom)
    }

    /// Height of the solid's top above the tip, mm (infinite with an open carriage).
    pub fn top(&self) -> f64 {
        self.pieces.iter().map(Piece::top).fold(0.0, f64::max)
    }

    /// The lowest cone piece (the FFF head's cone), if any.
    pub fn cone(&self) -> Option<&Piece> {
        self.pieces
            .iter()
            .find(|p| matches!(p.shape, PieceShape::Cone { .. }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fff_head_is_a_cone_until_the_carriage_is_wider() {
        let head = ToolSolid::fff_head(45.0, 5.0, 3.0, 4.0);
        let tan = 45f64.to_radians().tan();
        assert_eq!(head.radius_at(0.0), None);
        assert_eq!(head.radius_at(2.0), Some((2.0 * tan, ToolPart::Cone)));
        // At 4.5 mm the carriage (3 mm) is narrower than the cone; past the cone only it.
        assert_eq!(head.radius_at(4.5), Some((4.5 * tan, ToolPart::Cone)));
        assert_eq!(head.radius_at(6.0), Some((3.0, ToolPart::Carriage)));
        assert_eq!(head.widest(), 5.0 * tan);
        assert_eq!(head.widest_up_to(2.0), 2.0 * tan);
        assert_eq!(head.widest_up_to(100.0), 5.0 * tan);
        assert_eq!(head.tip_radius(), 0.0);
        assert_eq!(head.shoulder(), 0.0);
        assert_eq!(head.top(), f64::INFINITY);
        // Without a carriage nothing is above the cone.
        let bare = ToolSolid::fff_head(60.0, 5.0, 0.0, 10.0);
        assert_eq!(bare.radius_at(5.5), None);
        assert_eq!(bare.pieces().len(), 1);
    }

    #[test]
    fn the_needle_nozzle_stands_on_its_tip_disc_and_widens_above_the_needle() {
        let n = ToolSolid::needle_nozzle(0.5, 6.0, 30.0, 10.0);
        let tan = 30f64.to_radians().tan();
        assert_eq!(n.tip_radius(), 0.25);
        assert_eq!(n.shoulder(), 6.0);
        assert_eq!(n.top(), 16.0);
        assert_eq!(n.widest(), 0.25 + 10.0 * tan);
        assert_eq!(n.radius_at(3.0), Some((0.25, ToolPart::Needle)));
        assert_eq!(n.floor_at(0.2), Some(0.0));
        assert_eq!(n.floor_at(1.25), Some(6.0 + 1.0 / tan));
        assert_eq!(n.floor_at(n.widest() + 0.1), None);
        // No cone: the needle is all there is above the disc.
        let bare = ToolSolid::needle_nozzle(0.5, 6.0, 0.0, 10.0);
        assert_eq!((bare.shoulder(), bare.widest()), (6.0, 0.25));
        assert!(bare.cone().is_none());
    }
}
