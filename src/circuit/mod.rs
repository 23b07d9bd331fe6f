//! Circuits, part placement and rubberbands: the inputs of the route stage.
//!
//! ```text
//! .sch/.brd, .kicad_pcb/.kicad_sch/.net ──Circuit::load──► Circuit (parts, pads, nets)
//! .toml/.3de ──Placement::load──► Placement (poses, waypoints, wires)   ──validate(&Circuit)
//!                 place(circuit, placement, object bboxes) ──► PlacedPart (pads in model frame)
//!                 rubberbands(circuit, placement, placed) ──► Rubberband (connections to route)
//! ```
//!
//! This module only describes *what* must be connected and *where* the parts sit; it never
//! reads a mesh and never routes. The EAGLE files are read by the `conduit-eagle` crate; this
//! module turns its [`conduit_eagle::Schematic`] or [`conduit_eagle::Board`] into a
//! [`Circuit`] the pipeline uses. KiCad files are read by `conduit-kicad` and converted in
//! [`kicad`].

pub mod board_layout;
pub mod fit;
pub mod kicad;
mod placed;
mod placement;
pub mod placement_toml;
mod rubberband;
pub mod octopnp;
pub mod pack;
pub mod settings;
pub mod stage;
mod three_de;

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

pub use placed::{ARC_SEGMENTS, PlacedPad, PlacedPart, place};
pub use placement::{
    Connection, Endpoint, NetRouting, Origin, PartPlacement, Placement, PlacementError,
    PlacingMethod, Problem, Waypoint,
};
pub use rubberband::{Rubberband, Rubberbands, rubberbands};
pub use settings::RouteSettings;
pub use stage::{Electronics, ElectronicsError, ElectronicsParams, ElectronicsReport};

/// The copper shape of a pad, in the pad's own frame (before the pad rotation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PadShape {
    /// A circle.
    Round {
        /// Diameter in mm.
        diameter: f64,
    },
    /// A rectangle with sharp corners.
    Rect {
        /// Size along the pad's x axis, mm.
        width: f64,
        /// Size along the pad's y axis, mm.
        height: f64,
    },
    /// A rectangle whose shorter sides are half circles (a stadium).
    Oblong {
        /// Size along the pad's x axis, mm.
        width: f64,
        /// Size along the pad's y axis, mm.
        height: f64,
    },
}

impl PadShape {
    /// Width and height along the pad's own x and y axes, mm (a round pad's diameter twice).
    pub fn size(&self) -> (f64, f64) {
        match *self {
            PadShape::Round { diameter } => (diameter, diameter),
            PadShape::Rect { width, height } | PadShape::Oblong { width, height } => {
                (width, height)
            }
        }
    }

    /// Maps an EAGLE pad shape:
    /// - SMD pads are [`PadShape::Rect`]; with `roundness` 100 they are [`PadShape::Oblong`]
    ///   (or [`PadShape::Round`] when square). Partial roundness is drawn as a sharp rectangle,
    ///   which covers the real pad.
    /// - Through-hole pads: `round` and `octagon` are [`PadShape::Round`], `square` a square
    ///   [`PadShape::Rect`], `long` and `offset` a 2:1 [`PadShape::Oblong`] (EAGLE's default
    ///   elongation of 100 %; an `offset` pad is centred on its drill here, not shifted). Without
    ///   a diameter the copper is the drill plus EAGLE's default restring on each side: 25 % of
    ///   the drill, clamped to 0.254-0.508 mm.
    pub fn from_eagle(shape: &conduit_eagle::PadShape) -> Self {
        match shape {
            conduit_eagle::PadShape::Smd { dx, dy, roundness } => {
                let (width, height) = (*dx, *dy);
                if *roundness < 100.0 {
                    PadShape::Rect { width, height }
                } else if width == height {
                    PadShape::Round { diameter: width }
                } else {
                    PadShape::Oblong { width, height }
                }
            }
            conduit_eagle::PadShape::Through {
                drill,
                diameter,
                shape,
            } => {
                let d = diameter.unwrap_or(drill + 2.0 * (0.25 * drill).clamp(0.254, 0.508));
                match shape.as_str() {
                    "square" => PadShape::Rect {
                        width: d,
                        height: d,
                    },
                    "long" | "offset" => PadShape::Oblong {
                        width: 2.0 * d,
                        height: d,
                    },
                    _ => PadShape::Round { diameter: d },
                }
            }
        }
    }
}

/// A pad of a part, in the package frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Pad {
    /// Pad name, unique within the package (`1`, `A`, `+`).
    pub name: String,
    /// Centre x in mm, package frame.
    pub x: f64,
    /// Centre y in mm, package frame.
    pub y: f64,
    /// Counter-clockwise rotation of the pad within the package, degrees.
    pub rotation_deg: f64,
    /// Copper shape.
    pub shape: PadShape,
    /// Surface-mount (`true`) or through-hole (`false`).
    pub smd: bool,
}

impl Pad {
    /// Half the size of the pad's bounding box along the package's x and y axes, mm: its
    /// [`PadShape::size`] turned by its rotation.
    pub fn half_extent(&self) -> [f64; 2] {
        let (w, h) = self.shape.size();
        let (s, c) = self.rotation_deg.to_radians().sin_cos();
        [
            ((w * c).abs() + (h * s).abs()) / 2.0,
            ((w * s).abs() + (h * c).abs()) / 2.0,
        ]
    }

    /// The pad's bounding box in the package frame, `[x0, y0, x1, y1]` mm.
    pub fn extent(&self) -> [f64; 4] {
        let [hx, hy] = self.half_extent();
        [self.x - hx, self.y - hy, self.x + hx, self.y + hy]
    }
}

/// A number for a message: plain below a million, in scientific notation above, so a value of
/// 1e308 read from a file does not print 309 digits.
pub(crate) fn short_number(v: f64) -> String {
    if v.abs() < 1e6 {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// The largest distance of a pad centre from its package origin, and the largest pad side or
/// diameter, mm (100 mm). The largest packages placed in a print (battery holders, connectors,
/// displays) measure a few centimetres; a pad beyond this is a typo or a corrupted file, and
/// pads within it keep every cavity, keep-out and routing grid sized from them bounded.
pub const MAX_PAD_MM: f64 = 100.0;

/// The largest magnitude of a pad rotation, degrees (ten turns).
pub const MAX_PAD_ROTATION_DEG: f64 = 3_600.0;

impl Pad {
    /// The first number of the pad that is not finite, negative where it is a size, or beyond
    /// [`MAX_PAD_MM`] / [`MAX_PAD_ROTATION_DEG`]: its key and value.
    pub fn bad_number(&self) -> Option<(&'static str, f64)> {
        let sizes: &[(&'static str, f64)] = match self.shape {
            PadShape::Round { diameter } => &[("diameter", diameter)],
            PadShape::Rect { width, height } | PadShape::Oblong { width, height } => {
                &[("dx", width), ("dy", height)]
            }
        };
        let ok = |v: f64, limit: f64| v.is_finite() && v.abs() <= limit;
        [("x", self.x), ("y", self.y)]
            .into_iter()
            .find(|&(_, v)| !ok(v, MAX_PAD_MM))
            .or_else(|| {
                (!ok(self.rotation_deg, MAX_PAD_ROTATION_DEG)).then_some(("rot", self.rotation_deg))
            })
            .or_else(|| {
                sizes
                    .iter()
                    .copied()
                    .find(|&(_, v)| !ok(v, MAX_PAD_MM) || v < 0.0)
            })
    }

    fn from_eagle(p: &conduit_eagle::Pad) -> Self {
        Pad {
            name: p.name.clone(),
            x: p.x,
            y: p.y,
            rotation_deg: p.rotation.degrees,
            shape: PadShape::from_eagle(&p.shape),
            smd: matches!(p.shape, conduit_eagle::PadShape::Smd { .. }),
        }
    }
}

/// An electronic part with its package's pads.
#[derive(Debug, Clone, PartialEq)]
pub struct Part {
    /// Part name (`R1`), as in the schematic and on the board.
    pub name: String,
    /// The part's value (`220R`), if set.
    pub value: Option<String>,
    /// Package name (`R0805`).
    pub package: String,
    /// The package's pads, in file order.
    pub pads: Vec<Pad>,
    /// Schematic pins (`gate.pin`, e.g. `G$1.A`) and the pads each one connects to. Empty for
    /// parts read from a board.
    pub pins: BTreeMap<String, Vec<String>>,
    /// The pins of `pins` whose pads are joined inside the part (EAGLE's `route="any"`, e.g. a
    /// regulator's several GND pads): a net reaches such a pin through any one of its pads.
    pub route_any: BTreeSet<String>,
}

impl Part {
    /// The extent of the part's pads in its package frame, `[x0, y0, x1, y1]` mm, or `None`
    /// for a package without pads.
    pub fn pad_extent(&self) -> Option<[f64; 4]> {
        self.pads.iter().map(Pad::extent).reduce(|a, b| {
            [
                a[0].min(b[0]),
                a[1].min(b[1]),
                a[2].max(b[2]),
                a[3].max(b[3]),
            ]
        })
    }

    /// The `route="any"` pin that `pad` belongs to together with other pads, if any: the pads of
    /// that pin are one connection point.
    pub fn joined_pin(&self, pad: &str) -> Option<&str> {
        self.route_any
            .iter()
            .find(|pin| {
                self.pins
                    .get(pin.as_str())
                    .is_some_and(|pads| pads.len() > 1 && pads.iter().any(|p| p == pad))
            })
            .map(String::as_str)
    }

    /// The pad named `name`: exactly, then by schematic pin (`G$1.A`, or `A` when only one gate
    /// has such a pin, as Electronic Slic3r's `.3de` files name them; the pin's first pad), then
    /// ASCII case-insensitively as EAGLE compares names.
    pub fn pad(&self, name: &str) -> Option<&Pad> {
        let exact = |n: &str| self.pads.iter().find(|p| p.name == n);
        if let Some(p) = exact(name) {
            return Some(p);
        }
        let by_key = self.pins.get(name);
        let mut by_pin = self
            .pins
            .iter()
            .filter(|(k, _)| k.split_once('.').is_some_and(|(_, pin)| pin == name));
        let bare = match (by_pin.next(), by_pin.next()) {
            (Some((_, pads)), None) => Some(pads),
            _ => None,
        };
        if let Some(p) = by_key.or(bare).and_then(|pads| pads.first()) {
            return exact(p);
        }
        self.pads.iter().find(|p| p.name.eq_ignore_ascii_case(name))
    }
}

/// One end of a net: a pad of a part.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct PinRef {
    /// Part name.
    pub part: String,
    /// Pad name.
    pub pad: String,
}

impl PinRef {
    /// A reference to `part`'s pad `pad`.
    pub fn new(part: impl Into<String>, pad: impl Into<String>) -> Self {
        PinRef {
            part: part.into(),
            pad: pad.into(),
        }
    }
}

impl std::fmt::Display for PinRef {
    /// `PART.PAD`, as placement files write it.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}.{}", self.part, self.pad)
    }
}

/// An electrical net: the pads it connects.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Net {
    /// Net name (`VCC`, `N$3`).
    pub name: String,
    /// The pads, sorted by part then pad, at least one.
    pub pins: Vec<PinRef>,
}

/// Parts and nets: what has to be placed and connected.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Circuit {
    /// Parts with a package, in file order.
    pub parts: Vec<Part>,
    /// Nets with at least one pin, sorted by name. A net with a single pin has nothing to join
    /// inside the circuit; a placement's wires may take it to waypoints (a terminal where a
    /// battery, a connector or a wire is attached), as Electronic Slic3r's `.3de` files do.
    pub nets: Vec<Net>,
}

/// Why a circuit could not be loaded.
///
/// # How to fix
/// Pass an EAGLE 6+ XML schematic (`.sch`) or board (`.brd`), or a KiCad 6+ board
/// (`.kicad_pcb`), schematic (`.kicad_sch`) or netlist export (`.net`); re-save older files in
/// their program. The wrapped [`conduit_eagle::EagleError`] or [`conduit_kicad::KicadError`]
/// says what is wrong inside the file. A KiCad schematic or netlist needs its board beside it
/// for the pads.
///
/// A variant that wraps another error shows it in its own message rather than chaining it as
/// a source, so an error printed with its chain names the cause once.
#[derive(Debug, thiserror::Error)]
pub enum CircuitError {
    /// The file could not be read.
    #[error("{path}: {error}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        error: std::io::Error,
    },
    /// The file is not a readable EAGLE schematic or board.
    #[error("{path}: EAGLE: {error}")]
    Eagle {
        /// The file.
        path: PathBuf,
        /// What the EAGLE reader found.
        error: Box<conduit_eagle::EagleError>,
    },
    /// The file is not a readable KiCad board, schematic or netlist export.
    #[error("{path}: KiCad: {error}")]
    Kicad {
        /// The file.
        path: PathBuf,
        /// What the KiCad reader found.
        error: Box<conduit_kicad::KicadError>,
    },
    /// A KiCad schematic or netlist export whose parts have no pads: their footprints are only
    /// named, and the board beside it is missing or lacks them.
    #[error(
        "{path}: no pad geometry for {} part(s) ({}): {}",
        parts.len(),
        parts.join(", "),
        match board {
            Some(b) => format!("{} has no footprint with their references; update the board from the schematic in KiCad", b.display()),
            None => format!("put the KiCad board {} beside it (the schematic only names footprints)", expected.display()),
        }
    )]
    KicadPadsMissing {
        /// The schematic or netlist export.
        path: PathBuf,
        /// The board read beside it, if there is one.
        board: Option<PathBuf>,
        /// The board looked for.
        expected: PathBuf,
        /// The references of the parts without pads, sorted.
        parts: Vec<String>,
    },
    /// A pad whose position, size or rotation is not finite or beyond its bound
    /// ([`MAX_PAD_MM`], [`MAX_PAD_ROTATION_DEG`]).
    #[error(
        "{path}: part {part} pad {pad}: {key} = {} is not a finite number within ±{limit}", short_number(*value)
    )]
    BadPad {
        /// The file.
        path: PathBuf,
        /// The part.
        part: String,
        /// The pad.
        pad: String,
        /// The attribute (`x`, `y`, `dx`, `dy`, `diameter`, `rot`).
        key: &'static str,
        /// The value read.
        value: f64,
        /// The bound (mm, or degrees for `rot`).
        limit: f64,
    },
    /// The file is an EAGLE library, which holds no circuit.
    #[error("{path}: an EAGLE library (.lbr) holds no circuit; pass a schematic or a board")]
    Library {
        /// The file.
        path: PathBuf,
    },
}

impl Circuit {
    /// The circuit of an EAGLE schematic. Parts without a package (supply symbols, frames) are
    /// not in it; nets without a pad are not either (a net with one pad is kept).
    pub fn from_schematic(s: &conduit_eagle::Schematic) -> Self {
        let parts = s
            .parts
            .iter()
            .filter_map(|p| {
                let pkg = p.package.as_ref()?;
                Some(Part {
                    name: p.name.clone(),
                    value: p.value.clone(),
                    package: pkg.name.clone(),
                    pads: pkg.pads.iter().map(Pad::from_eagle).collect(),
                    pins: p.pin_pads.clone(),
                    route_any: p.route_any.clone(),
                })
            })
            .collect();
        Circuit {
            parts,
            nets: nets(&s.nets),
        }
    }

    /// The circuit of an EAGLE board: every element with its package's pads, and the signals
    /// with at least one pad.
    pub fn from_board(b: &conduit_eagle::Board) -> Self {
        let parts = b
            .elements
            .iter()
            .map(|e| Part {
                name: e.name.clone(),
                value: e.value.clone(),
                package: e.package.name.clone(),
                pads: e.package.pads.iter().map(Pad::from_eagle).collect(),
                pins: BTreeMap::new(),
                route_any: BTreeSet::new(),
            })
            .collect();
        Circuit {
            parts,
            nets: nets(&b.nets),
        }
    }

    /// Reads an EAGLE `.sch` or `.brd`, or a KiCad `.kicad_pcb`, `.kicad_sch` or `.net`
    /// (with its board beside it, see [`kicad`]); which one is decided by the content, not the
    /// name.
    ///
    /// # Errors
    /// [`CircuitError`] naming the file.
    pub fn load(path: &Path) -> Result<Self, CircuitError> {
        let bytes = std::fs::read(path).map_err(|error| CircuitError::Io {
            path: path.to_path_buf(),
            error,
        })?;
        if conduit_kicad::sniff(&bytes).is_some() {
            let circuit = Self::from_kicad(&kicad::read(&bytes, path)?, path)?;
            circuit.check_pads(path)?;
            return Ok(circuit);
        }
        let circuit = match conduit_eagle::read(&bytes) {
            Ok(conduit_eagle::Document::Schematic(s)) => Self::from_schematic(&s),
            Ok(conduit_eagle::Document::Board(b)) => Self::from_board(&b),
            Ok(conduit_eagle::Document::Library) => {
                return Err(CircuitError::Library {
                    path: path.to_path_buf(),
                });
            }
            Err(error) => {
                return Err(CircuitError::Eagle {
                    path: path.to_path_buf(),
                    error: Box::new(error),
                });
            }
        };
        circuit.check_pads(path)?;
        Ok(circuit)
    }

    /// Checks every pad of every part with [`Pad::bad_number`].
    ///
    /// # Errors
    /// [`CircuitError::BadPad`] for the first bad pad, naming `path`, the part and the pad.
    pub fn check_pads(&self, path: &Path) -> Result<(), CircuitError> {
        for part in &self.parts {
            for pad in &part.pads {
                if let Some((key, value)) = pad.bad_number() {
                    return Err(CircuitError::BadPad {
                        path: path.to_path_buf(),
                        part: part.name.clone(),
                        pad: pad.name.clone(),
                        key,
                        value,
                        limit: if key == "rot" {
                            MAX_PAD_ROTATION_DEG
                        } else {
                            MAX_PAD_MM
                        },
                    });
                }
            }
        }
        Ok(())
    }

    /// The part named `name`.
    pub fn part(&self, name: &str) -> Option<&Part> {
        self.parts.iter().find(|p| p.name == name)
    }

    /// The net named `name`.
    pub fn net(&self, name: &str) -> Option<&Net> {
        self.nets.iter().find(|n| n.name == name)
    }

    /// The number of pads on nets (each net pin once).
    pub fn pin_count(&self) -> usize {
        self.nets.iter().map(|n| n.pins.len()).sum()
    }

    /// The number of pads of all parts, connected or not.
    pub fn pad_count(&self) -> usize {
        self.parts.iter().map(|p| p.pads.len()).sum()
    }
}

/// Nets with at least one pad, merged by name and sorted by name.
fn nets(src: &[conduit_eagle::Net]) -> Vec<Net> {
    let mut by_name: BTreeMap<&str, std::collections::BTreeSet<PinRef>> = BTreeMap::new();
    for n in src {
        by_name
            .entry(&n.name)
            .or_default()
            .extend(n.pads.iter().map(|(part, pad)| PinRef::new(part, pad)));
    }
    by_name
        .into_iter()
        .filter(|(_, pins)| !pins.is_empty())
        .map(|(name, pins)| Net {
            name: name.to_owned(),
            pins: pins.into_iter().collect(),
        })
        .collect()
}

#[cfg(test)]
pub(crate) mod tests {
    use std::collections::BTreeSet;

    use super::*;

    pub(crate) fn sample_dir() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/circuit_demo")
    }

    pub(crate) fn sample() -> Circuit {
        match Circuit::load(&sample_dir().join("led_coin.sch")) {
            Ok(c) => c,
            Err(e) => panic!("{e}"),
        }
    }

    #[test]
    fn sample_schematic_has_three_parts_three_nets() {
        let c = sample();
        let names: Vec<&str> = c.parts.iter().map(|p| p.name.as_str()).collect();
        assert_eq!(names, ["BAT1", "R1", "LED1"]); // SUPPLY1 (no package) dropped
        let pads = |part: &str| -> Vec<(String, f64, f64, PadShape, bool)> {
            c.part(part)
                .map(|p| p.pads.iter())
                .into_iter()
                .flatten()
                .map(|p| (p.name.clone(), p.x, p.y, p.shape, p.smd))
                .collect()
        };
        let rect = |width, height| PadShape::Rect { width, height };
        assert_eq!(
            pads("BAT1"),
            [
                ("+".into(), -11.0, 0.0, rect(2.5, 4.0), true),
                (
                    "-".into(),
                    0.0,
                    0.0,
                    PadShape::Round { diameter: 6.0 },
                    true
                ),
            ]
        );
        assert_eq!(
            pads("R1"),
            [
                ("1".into(), -0.95, 0.0, rect(1.0, 1.3), true),
                ("2".into(), 0.95, 0.0, rect(1.0, 1.3), true),
            ]
        );
        assert_eq!(
            pads("LED1"),
            [
                ("A".into(), -1.0, 0.0, rect(1.0, 1.2), true),
                ("C".into(), 1.0, 0.0, rect(1.0, 1.2), true),
            ]
        );
        assert_eq!(c.part("R1").and_then(|p| p.value.as_deref()), Some("220R"));
        assert_eq!(c.part("LED1").map(|p| p.package.as_str()), Some("LED-0805"));
        let nets: Vec<(&str, Vec<String>)> = c
            .nets
            .iter()
            .map(|n| {
                (
                    n.name.as_str(),
                    n.pins.iter().map(|p| p.to_string()).collect(),
                )
            })
            .collect();
        assert_eq!(
            nets,
            [
                ("GND", vec!["BAT1.-".to_owned(), "LED1.C".to_owned()]),
                ("N1", vec!["LED1.A".to_owned(), "R1.2".to_owned()]),
                ("VCC", vec!["BAT1.+".to_owned(), "R1.1".to_owned()]),
            ]
        );
        assert_eq!(c.pin_count(), 6);
        assert_eq!(c.pad_count(), 6);
        // Pins resolve by pad name and by schematic pin name.
        let led = c.part("LED1");
        assert_eq!(led.and_then(|p| p.pad("A")).map(|p| p.x), Some(-1.0));
        let bat = c.part("BAT1");
        assert_eq!(bat.and_then(|p| p.pad("G$1.-")).map(|p| p.x), Some(0.0));
        assert!(led.and_then(|p| p.pad("X")).is_none());
    }

    #[test]
    fn eagle_pad_shapes_map_to_round_rect_oblong() {
        use conduit_eagle::PadShape as E;
        let smd = |dx, dy, roundness| PadShape::from_eagle(&E::Smd { dx, dy, roundness });
        assert_eq!(
            smd(1.0, 2.0, 0.0),
            PadShape::Rect {
                width: 1.0,
                height: 2.0
            }
        );
        assert_eq!(
            smd(1.0, 2.0, 100.0),
            PadShape::Oblong {
                width: 1.0,
                height: 2.0
            }
        );
        assert_eq!(smd(1.5, 1.5, 100.0), PadShape::Round { diameter: 1.5 });
        let th = |drill, diameter: Option<f64>, shape: &str| {
            PadShape::from_eagle(&E::Through {
                drill,
                diameter,
                shape: shape.into(),
            })
        };
        assert_eq!(
            th(0.8, Some(1.6), "round"),
            PadShape::Round { diameter: 1.6 }
        );
        assert_eq!(
            th(0.8, Some(1.6), "octagon"),
            PadShape::Round { diameter: 1.6 }
        );
        assert_eq!(
            th(0.8, Some(1.6), "square"),
            PadShape::Rect {
                width: 1.6,
                height: 1.6
            }
        );
        assert_eq!(
            th(0.8, Some(1.6), "long"),
            PadShape::Oblong {
                width: 3.2,
                height: 1.6
            }
        );
        let diameter = |s: PadShape| match s {
            PadShape::Round { diameter } => diameter,
            _ => f64::NAN,
        };
        // Default restring: 25 % of 1.2 mm = 0.3 mm each side.
        assert!((diameter(th(1.2, None, "round")) - 1.8).abs() < 1e-12);
        // Clamped to 0.254 mm for small drills and 0.508 mm for large ones.
        assert!((diameter(th(0.6, None, "round")) - 1.108).abs() < 1e-12);
        assert!((diameter(th(3.0, None, "round")) - 4.016).abs() < 1e-12);
    }

    #[test]
    fn load_errors_name_the_file() {
        let missing = sample_dir().join("no_such.sch");
        let e = Circuit::load(&missing).err().map(|e| e.to_string());
        assert!(e.is_some_and(|m| m.contains("no_such.sch")));
        let dir = tempfile::tempdir().ok();
        let Some(dir) = dir else { return };
        let junk = dir.path().join("junk.brd");
        std::fs::write(&junk, "<svg/>").ok();
        let e = Circuit::load(&junk).err().map(|e| e.to_string());
        assert!(
            e.as_deref()
                .is_some_and(|m| m.contains("junk.brd") && m.contains("not an EAGLE file")),
            "{e:?}"
        );
    }

    #[test]
    fn wild_pads_are_refused_naming_the_file_part_and_pad() {
        let dir = tempfile::tempdir().ok();
        let Some(dir) = dir else { return };
        let text = std::fs::read_to_string(sample_dir().join("led_coin.sch")).unwrap_or_default();
        let smd = r#"<smd name="2" x="0.95" y="0" dx="1" dy="1.3" layer="1"/>"#;
        assert!(text.contains(smd));
        for (bad, want) in [
            (
                r#"<smd name="2" x="0.95" y="-1e9" dx="1" dy="1.3" layer="1"/>"#,
                "y = -1e9",
            ),
            (
                r#"<smd name="2" x="0.95" y="0" dx="1" dy="2147483648" layer="1"/>"#,
                "dy = 2.147483648e9",
            ),
            (
                r#"<smd name="2" x="0.95" y="0" dx="-1" dy="1.3" layer="1"/>"#,
                "dx = -1",
            ),
        ] {
            let path = dir.path().join("wild.sch");
            std::fs::write(&path, text.replacen(smd, bad, 1)).ok();
            let msg = Circuit::load(&path)
                .err()
                .map(|e| e.to_string())
                .unwrap_or_default();
            assert!(
                msg.contains("wild.sch: part R1 pad 2: ") && msg.contains(want),
                "{want:?} not in {msg:?}"
            );
        }
        assert!(sample().check_pads(Path::new("x.sch")).is_ok());
    }

    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(dir).into_iter().flatten().flatten() {
            let p = e.path();
            if p.is_dir() {
                walk(&p, out);
            } else {
                out.push(p);
            }
        }
    }

    #[test]
    fn corpus_schematics_and_boards_give_equal_net_pin_sets() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/corpus/eagle");
        if !root.is_dir() {
            println!("skipped: {} not found", root.display());
            return;
        }
        let mut files = Vec::new();
        walk(&root, &mut files);
        files.sort();
        let mut compared = 0;
        for sch in files
            .iter()
            .filter(|f| f.extension().is_some_and(|e| e == "sch"))
        {
            let brd = sch.with_extension("brd");
            if !brd.is_file() {
                continue;
            }
            let binary = |r: &Result<Circuit, CircuitError>| match r {
                Err(CircuitError::Eagle { error, .. }) => {
                    matches!(**error, conduit_eagle::EagleError::BinaryFormat)
                }
                _ => false,
            };
            let (s, b) = match (Circuit::load(sch), Circuit::load(&brd)) {
                (Ok(s), Ok(b)) => (s, b),
                (s, b) if binary(&s) && binary(&b) => {
                    println!("{}: binary EAGLE 5 files, rejected", sch.display());
                    continue;
                }
                (s, b) => panic!("{:?} {:?}", s.err(), b.err()),
            };
            let pin_sets = |c: &Circuit| -> BTreeSet<Vec<PinRef>> {
                c.nets.iter().map(|n| n.pins.clone()).collect()
            };
            assert!(!s.nets.is_empty(), "{}", sch.display());
            assert_eq!(pin_sets(&s), pin_sets(&b), "{}", sch.display());
            // Every net pin is a pad of a part of the circuit.
            for c in [&s, &b] {
                for n in &c.nets {
                    for p in &n.pins {
                        assert!(
                            c.part(&p.part).and_then(|q| q.pad(&p.pad)).is_some(),
                            "{}: {p}",
                            sch.display()
                        );
                    }
                }
            }
            // Every board element placed where the board has it: a spanning tree per net.
            let board = std::fs::read(&brd)
                .ok()
                .and_then(|bytes| conduit_eagle::read_board(&bytes).ok());
            let Some(board) = board else {
                panic!("{}: board unreadable", brd.display())
            };
            let placement = Placement::from_board(&board, 1.0, [0.0, 0.0]);
            let bands =
                place(&b, &placement, &[]).and_then(|placed| rubberbands(&b, &placement, &placed));
            let bands = match bands {
                Ok(r) => r,
                Err(e) => panic!("{}: {e}", brd.display()),
            };
            assert!(bands.unplaced.is_empty());
            assert_eq!(bands.bands.len(), b.pin_count() - b.nets.len());
            assert!(bands.bands.iter().all(|r| r.from.z == 1.0 && r.to.z == 1.0));
            println!(
                "{}: {} parts / {} elements, {} nets, {} pins",
                sch.display(),
                s.parts.len(),
                b.parts.len(),
                s.nets.len(),
                s.pin_count()
            );
            compared += 1;
        }
        assert!(compared > 0, "no .sch/.brd pairs under {}", root.display());
    }
}
