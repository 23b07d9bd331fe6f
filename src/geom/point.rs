//! Points: scaled-integer 2D points for exact polygon work, `f64` 3D points for meshes.

/// One scaled 2D coordinate: 1 unit = 1 nm. `i64` holds ±9.2e9 mm, far beyond any build volume.
pub type Coord = i64;

/// Scaled units per millimetre.
pub const UNITS_PER_MM: f64 = 1_000_000.0;

/// A 3D point in millimetres.
pub type Point3 = nalgebra::Point3<f64>;

/// A 3D vector in millimetres.
pub type Vector3 = nalgebra::Vector3<f64>;

/// Converts millimetres to scaled integer units, rounding to the nearest nanometre.
pub fn scaled(mm: f64) -> Coord {
    (mm * UNITS_PER_MM).round() as Coord
}

/// Converts scaled integer units back to millimetres.
pub fn unscaled(units: Coord) -> f64 {
    units as f64 / UNITS_PER_MM
}

/// A 2D point in scaled integer units (1 unit = 1 nm).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
pub struct Point2 {
    /// X in nanometres.
    pub x: Coord,
    /// Y in nanometres.
    pub y: Coord,
}

impl Point2 {
    /// A point from scaled coordinates.
    pub const fn new(x: Coord, y: Coord) -> Self {
        Self { x, y }
    }

    /// A point from millimetre coordinates, snapped to the nanometre grid.
    pub fn from_mm(x: f64, y: f64) -> Self {
        Self::new(scaled(x), scaled(y))
    }

    /// The point in millimetres.
    pub fn to_mm(self) -> (f64, f64) {
        (unscaled(self.x), unscaled(self.y))
    }

    /// The z component of `(a - self) × (b - self)`, exact in `i128`.
    pub fn cross(self, a: Point2, b: Point2) -> i128 {
        let (ax, ay) = ((a.x - self.x) as i128, (a.y - self.y) as i128);
        let (bx, by) = ((b.x - self.x) as i128, (b.y - self.y) as i128);
        ax * by - ay * bx
    }

    /// Squared distance to `other`, exact in `i128`.
    pub fn distance_squared(self, other: Point2) -> i128 {
        let dx = (other.x - self.x) as i128;
        let dy = (other.y - self.y) as i128;
        dx * dx + dy * dy
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scaling_round_trips_to_the_nanometre() {
        assert_eq!(scaled(1.0), 1_000_000);
        assert_eq!(scaled(-0.0000004), 0);
        assert_eq!(scaled(0.0000006), 1);
        assert_eq!(unscaled(scaled(123.456789)), 123.456789);
    }

    #[test]
    fn cross_product_sign_gives_turn_direction() {
        let o = Point2::new(0, 0);
        assert!(o.cross(Point2::new(10, 0), Point2::new(0, 10)) > 0);
        assert!(o.cross(Point2::new(0, 10), Point2::new(10, 0)) < 0);
        let far = Point2::from_mm(1e6, 1e6);
        assert_eq!(o.cross(far, far), 0);
    }
}
