//! Placement: where each part sits in the printed object, how it gets there, and optional wire
//! waypoints. An input of the route stage, read from a TOML file, from Electronic Slic3r's
//! `.3de` XML, or projected from an EAGLE board.
//!
//! The TOML form:
//!
//! ```toml
//! origin = "model"        # or "bbox_center", see [`Origin`]
//! source = "led_coin.sch" # optional: the circuit this placement belongs to
//!
//! [[part]]
//! name = "R1"
//! x = 10.0
//! y = 5.0
//! z = 3.0                 # seating plane: the bottom of the part
//! rotation = 90.0         # degrees about +z, counter-clockwise seen from above
//! tilt = [0.0, 0.0]       # optional, degrees about x and y
//! method = "auto"         # auto | manual | none
//! body_height = 1.6       # mm above the seating plane
//! object = 0              # scene object index
//!
//! [[net]]
//! name = "VCC"
//! waypoints = [{ name = "w1", x = 0.0, y = 0.0, z = 2.0 }]
//! wires = [["R1.1", "w1"], ["w1", "LED1.A"]]
//! ```

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::{Circuit, PinRef};

/// The largest distance of a part or waypoint from the origin of its frame, mm (10 m).
///
/// No printer bed, robot cell or printed object conduit works on comes near 10 m, so a position
/// beyond it is a typo or a corrupted file. The bound also keeps every position, scaled to
/// nanometres, far inside `i64` (1e13 nm against 9.2e18), so sums and `±1` on layer keys
/// cannot overflow, and it bounds every grid or loop the router sizes from positions.
pub const MAX_POSITION_MM: f64 = 10_000.0;

/// The largest part height, footprint height or body side, mm (1 m): far above any part
/// placed in a print, small enough that cavities and keep-outs sized by it stay bounded.
pub const MAX_PART_SIZE_MM: f64 = 1_000.0;

/// The largest rotation or tilt magnitude, degrees (ten turns): larger angles are not
/// written by any tool and lose all precision in `sin`/`cos`.
pub const MAX_ANGLE_DEG: f64 = 3_600.0;

/// What part and waypoint coordinates are relative to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Origin {
    /// Model coordinates of the part's object (the frame of its mesh file).
    #[default]
    Model,
    /// `x`, `y` from the centre of the object's bounding box and `z` from its bottom (minimum
    /// z), in model coordinates. This is Electronic Slic3r's frame: it centres each object on
    /// the bed and stands it on z = 0, so its `.3de` positions use it.
    BboxCenter,
}

/// How a part gets into the object when the print pauses for it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PlacingMethod {
    /// Picked and placed by the machine.
    #[default]
    Auto,
    /// The print pauses and a person inserts the part.
    Manual,
    /// Not inserted during the print (the cavity and wires are still made).
    None,
}

/// When the conductive ink reaches the part's pads (Electronic Slic3r's `connectionMethod`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Connection {
    /// No special connection step: the traces end on the pads.
    #[default]
    None,
    /// Drops on the pads in the first layer above the seating plane.
    Layer,
    /// Drops on the pads once the print has passed the top of the part.
    Part,
}

/// The pose of one part.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PartPlacement {
    /// Part name, as in the circuit.
    pub name: String,
    /// Position of the package origin in mm, frame given by [`Placement::origin`].
    pub x: f64,
    /// See `x`.
    pub y: f64,
    /// Seating plane in mm: the bottom of the part, where its pads sit.
    pub z: f64,
    /// Rotation about +z in degrees, counter-clockwise seen from above.
    #[serde(default)]
    pub rotation: f64,
    /// Rotations about x and y in degrees, applied after `rotation`: a point turns by
    /// `Rx(tilt[0]) · Ry(tilt[1]) · Rz(rotation)`, as Electronic Slic3r turns its part meshes.
    #[serde(default)]
    pub tilt: [f64; 2],
    /// EAGLE's mirror (a bottom-side part): x is negated after `rotation`, as in `MR90`.
    #[serde(default)]
    pub mirror: bool,
    /// How the part is inserted.
    #[serde(default)]
    pub method: PlacingMethod,
    /// When the ink reaches its pads.
    #[serde(default)]
    pub connection: Connection,
    /// Height of the part above the seating plane in mm (0: unknown).
    #[serde(default)]
    pub body_height: f64,
    /// Thickness of the pad layer at the bottom of the part in mm, part of `body_height`
    /// (Electronic Slic3r's `footprintHeight`).
    #[serde(default)]
    pub footprint_height: f64,
    /// Width (package x) and length (package y) of the body in mm, centred on the package
    /// origin, when known.
    #[serde(default)]
    pub body_size: Option<[f64; 2]>,
    /// Index of the scene object the part sits in.
    #[serde(default)]
    pub object: usize,
}

/// A named point a wire passes through.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Waypoint {
    /// Name, unique within the net; may not contain `.`.
    pub name: String,
    /// Position in mm, frame given by [`Placement::origin`].
    pub x: f64,
    /// See `x`.
    pub y: f64,
    /// See `x`.
    pub z: f64,
    /// Index of the scene object whose frame `x`, `y`, `z` are in.
    #[serde(default)]
    pub object: usize,
}

/// One end of a wire: `"PART.PAD"` (split at the first `.`) or a waypoint name (no `.`).
#[derive(Debug, Clone, PartialEq, Eq, Deserialize)]
#[serde(from = "String")]
pub enum Endpoint {
    /// A pad of a part. The pad may also be named by its schematic pin (see
    /// [`super::Part::pad`]).
    Pin(PinRef),
    /// A waypoint of the same net.
    Waypoint(String),
}

impl From<String> for Endpoint {
    fn from(s: String) -> Self {
        match s.split_once('.') {
            Some((part, pad)) => Endpoint::Pin(PinRef::new(part, pad)),
            None => Endpoint::Waypoint(s),
        }
    }
}

impl std::fmt::Display for Endpoint {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Endpoint::Pin(p) => p.fmt(f),
            Endpoint::Waypoint(w) => f.write_str(w),
        }
    }
}

/// Routing hints for one net. A net with wires is connected exactly by them; a net without is
/// connected by a minimum spanning tree (see [`super::rubberbands`]).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NetRouting {
    /// Net name, as in the circuit.
    pub name: String,
    /// Points the wires pass through.
    #[serde(default)]
    pub waypoints: Vec<Waypoint>,
    /// Wires as pairs of endpoints.
    #[serde(default)]
    pub wires: Vec<[Endpoint; 2]>,
}

/// Where the parts of a circuit sit and how the nets run.
#[derive(Debug, Clone, PartialEq, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Placement {
    /// The frame of all coordinates.
    #[serde(default)]
    pub origin: Origin,
    /// The circuit file this placement was made for, relative to the placement file.
    #[serde(default)]
    pub source: Option<String>,
    /// Part poses, `[[part]]` in TOML. Circuit parts not listed are not placed.
    #[serde(default, rename = "part")]
    pub parts: Vec<PartPlacement>,
    /// Net routing hints, `[[net]]` in TOML.
    #[serde(default, rename = "net")]
    pub nets: Vec<NetRouting>,
    /// Parts the file lists but does not place, with the reason, one line each (a `.3de`
    /// part with `placed="false"`): the route stage reports them as warnings.
    #[serde(skip)]
    pub skipped: Vec<String>,
}

/// One thing wrong in a placement, found by [`Placement::validate`].
#[derive(Debug, Clone, PartialEq)]
pub enum Problem {
    /// A placed part the circuit does not have.
    UnknownPart {
        /// Part name.
        part: String,
        /// The circuit's part whose name is closest, when one is close enough to be a typo.
        closest: Option<String>,
    },
    /// A part placed more than once.
    DuplicatePart {
        /// Part name.
        part: String,
    },
    /// A net the circuit does not have.
    UnknownNet {
        /// Net name.
        net: String,
        /// The circuit's net whose name is closest, when one is close enough to be a typo.
        closest: Option<String>,
    },
    /// A net listed more than once.
    DuplicateNet {
        /// Net name.
        net: String,
    },
    /// A wire end naming a part or pad that does not exist.
    UnknownPin {
        /// Net name.
        net: String,
        /// The endpoint as written.
        pin: String,
        /// The closest existing pin (`PART.PAD`), when one is close enough to be a typo.
        closest: Option<String>,
    },
    /// A wire end on a pad of another net.
    PinNotOnNet {
        /// Net name.
        net: String,
        /// The endpoint as written.
        pin: String,
    },
    /// A wire end naming a waypoint the net does not define.
    UnknownWaypoint {
        /// Net name.
        net: String,
        /// Waypoint name.
        name: String,
    },
    /// A waypoint name used twice in a net, or containing `.`.
    BadWaypointName {
        /// Net name.
        net: String,
        /// Waypoint name.
        name: String,
    },
    /// A coordinate or size that is not a finite number, or a negative size.
    BadNumber {
        /// What it belongs to, e.g. `part "R1"`.
        item: String,
        /// The key.
        key: &'static str,
    },
    /// A finite number beyond its bound ([`MAX_POSITION_MM`], [`MAX_PART_SIZE_MM`] or
    /// [`MAX_ANGLE_DEG`]).
    OutOfRange {
        /// What it belongs to, e.g. `part "R1"`.
        item: String,
        /// The key.
        key: &'static str,
        /// The value read.
        value: f64,
        /// The largest magnitude allowed.
        limit: f64,
        /// The unit of both, `mm` or `°`.
        unit: &'static str,
    },
    /// A part turned about x or y: conduit cuts upright cavities and prints the traces to pads
    /// in the seating plane, so it seats parts upright (turned about z only).
    Tilted {
        /// Part name.
        part: String,
        /// The tilt about x and y, degrees.
        tilt: [f64; 2],
    },
}

/// `; did you mean "X"?` after a name that is not in the circuit, when a close one is.
fn did_you_mean(f: &mut std::fmt::Formatter<'_>, closest: &Option<String>) -> std::fmt::Result {
    match closest {
        Some(c) => write!(f, "; did you mean \"{c}\"?"),
        None => Ok(()),
    }
}

/// The name of `candidates` closest to `name` (ASCII case ignored, as EAGLE compares names),
/// when it is close enough to be a typo: a few letters changed, not two thirds of the name.
fn closest<'a>(name: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<String> {
    let wanted = name.to_ascii_lowercase();
    candidates
        .into_iter()
        .map(|c| {
            (
                strsim::damerau_levenshtein(&wanted, &c.to_ascii_lowercase()),
                c,
            )
        })
        .filter(|(d, _)| *d <= 2.max(name.chars().count() / 3))
        .min()
        .map(|(_, c)| c.to_owned())
}

/// The existing pin closest to `pin`: the closest pad of its part, or, when the part is not in
/// the circuit, the same pad of the closest part.
fn closest_pin(circuit: &Circuit, pin: &PinRef) -> Option<String> {
    match circuit.part(&pin.part) {
        Some(part) => closest(&pin.pad, part.pads.iter().map(|p| p.name.as_str()))
            .map(|pad| PinRef::new(&pin.part, &pad).to_string()),
        None => {
            let name = closest(&pin.part, circuit.parts.iter().map(|p| p.name.as_str()))?;
            let part = circuit.part(&name)?;
            let pad = part.pad(&pin.pad)?;
            Some(PinRef::new(&name, &pad.name).to_string())
        }
    }
}

impl std::fmt::Display for Problem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Problem::UnknownPart { part, closest } => {
                write!(f, "placement: part \"{part}\" is not in the circuit")?;
                did_you_mean(f, closest)
            }
            Problem::DuplicatePart { part } => {
                write!(f, "placement: part \"{part}\" is placed more than once")
            }
            Problem::UnknownNet { net, closest } => {
                write!(f, "placement: net \"{net}\" is not in the circuit")?;
                did_you_mean(f, closest)
            }
            Problem::DuplicateNet { net } => {
                write!(f, "placement: net \"{net}\" is listed more than once")
            }
            Problem::UnknownPin { net, pin, closest } => {
                write!(f, "net {net}: pin {pin} does not exist")?;
                did_you_mean(f, closest)
            }
            Problem::PinNotOnNet { net, pin } => {
                write!(f, "net {net}: pin {pin} is not on this net")
            }
            Problem::UnknownWaypoint { net, name } => {
                write!(f, "net {net}: waypoint \"{name}\" is not defined")
            }
            Problem::BadWaypointName { net, name } => write!(
                f,
                "net {net}: waypoint name \"{name}\" is used twice or contains '.'"
            ),
            Problem::BadNumber { item, key } => write!(
                f,
                "placement: {item}: {key} must be a finite number (and not negative for sizes)"
            ),
            Problem::OutOfRange {
                item,
                key,
                value,
                limit,
                unit,
            } => write!(
                f,
                "placement: {item}: {key} = {} {unit} is beyond the limit of ±{limit} {unit}",
                super::short_number(*value)
            ),
            Problem::Tilted { part, tilt } => write!(
                f,
                "placement: part \"{part}\" is turned {}° about x and {}° about y: conduit seats \
                 parts upright (turned about z only), so its cavity and pads cannot be built",
                super::short_number(tilt[0]),
                super::short_number(tilt[1])
            ),
        }
    }
}

/// Why a placement could not be read or used.
///
/// # How to fix
/// File errors name the file and line; [`PlacementError::Invalid`] lists every part, net, pin
/// and waypoint that does not match the circuit: fix the names in the placement file (part
/// names as in the schematic, pins as `PART.PAD`).
///
/// A variant that wraps another error shows it in its own message rather than chaining it as
/// a source, so an error printed with its chain names the cause once.
#[derive(Debug, thiserror::Error)]
pub enum PlacementError {
    /// The file could not be read.
    #[error("{path}: {error}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        error: std::io::Error,
    },
    /// The file name ends in neither `.toml` nor `.3de`.
    #[error(
        "{path}: unknown placement format; expected a .toml or .3de file{}",
        board_hint(path)
    )]
    UnknownFormat {
        /// The file.
        path: PathBuf,
    },
    /// Invalid TOML, or a key that is unknown, missing or of the wrong type.
    #[error("line {line}: {message}")]
    Toml {
        /// 1-based line (0 when the parser gives no position).
        line: usize,
        /// The parser's message, naming the key.
        message: String,
    },
    /// An invalid `.3de` document.
    #[error("line {line}: {message}")]
    ThreeDe {
        /// 1-based line.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// An error in the file `path`.
    #[error("{path}: {error}")]
    WithPath {
        /// The file.
        path: PathBuf,
        /// The error.
        error: Box<PlacementError>,
    },
    /// The placement does not match the circuit.
    #[error("{}", .0.iter().map(ToString::to_string).collect::<Vec<_>>().join("; "))]
    Invalid(Vec<Problem>),
    /// A part or waypoint in an object the scene does not have.
    #[error("{item}: object {object} does not exist (the scene has {count})")]
    NoSuchObject {
        /// What sits in it, e.g. `part "R1"`.
        item: String,
        /// The object index.
        object: usize,
        /// The number of objects.
        count: usize,
    },
    /// Waypoints relative to bounding boxes where model coordinates are needed.
    #[error(
        "net {net}: waypoints are relative to the object bounding box; resolve the placement with Placement::to_model first"
    )]
    NotResolved {
        /// Net name.
        net: String,
    },
}

/// For a board given as a placement: how to make one from it.
fn board_hint(path: &Path) -> &'static str {
    let brd = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("brd"));
    if brd {
        " (an EAGLE board is a circuit, not a placement: `conduit place --from-brd X.brd \
         --model MODEL -o P.toml` writes its layout as a placement)"
    } else {
        ""
    }
}

impl Placement {
    /// Reads a placement by file extension: `.toml` or `.3de`.
    ///
    /// # Errors
    /// [`PlacementError::WithPath`] around the parse error or the numbers
    /// [`Placement::check_numbers`] refuses, or [`PlacementError::Io`] /
    /// [`PlacementError::UnknownFormat`].
    pub fn load(path: &Path) -> Result<Self, PlacementError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        let parse: fn(&str) -> Result<Self, PlacementError> = match ext.as_deref() {
            Some("toml") => Self::from_toml,
            Some("3de") => Self::from_3de,
            _ => {
                return Err(PlacementError::UnknownFormat {
                    path: path.to_path_buf(),
                });
            }
        };
        let text = std::fs::read_to_string(path).map_err(|error| PlacementError::Io {
            path: path.to_path_buf(),
            error,
        })?;
        parse(&text)
            .and_then(|p| p.check_numbers().map(|()| p))
            .map_err(|e| PlacementError::WithPath {
                path: path.to_path_buf(),
                error: Box::new(e),
            })
    }

    /// Parses the TOML form (see the module documentation). Unknown keys are errors.
    ///
    /// # Errors
    /// [`PlacementError::Toml`] for invalid TOML or keys.
    pub fn from_toml(text: &str) -> Result<Self, PlacementError> {
        let located = |e: toml::de::Error, key: Option<String>| {
            let before = |at: usize| &text.as_bytes()[..at.min(text.len())];
            let message = e.message().trim();
            // A value of the wrong type in words, after its key: `part[0].x must be a number
            // in mm, got "a"`.
            let message = match (key, crate::scene::words::must_be(message, None)) {
                (Some(k), Some(words)) => format!("{k} {words}"),
                (None, Some(words)) => words,
                (_, None) => message.to_owned(),
            };
            PlacementError::Toml {
                line: e.span().map_or(0, |s| {
                    before(s.start).iter().filter(|&&c| c == b'\n').count() + 1
                }),
                message,
            }
        };
        let deserializer = toml::Deserializer::parse(text).map_err(|e| located(e, None))?;
        serde_path_to_error::deserialize(deserializer).map_err(|e| {
            let key = e.path().to_string();
            located(e.into_inner(), (key != ".").then_some(key))
        })
    }

    /// The elements of an EAGLE board as parts lying on the plane `z`, shifted by `offset`
    /// (mm, added to the board x, y) in model coordinates. Rotation and mirror (bottom-side
    /// elements) come from the element; heights are unknown (0) and the nets get no hints.
    pub fn from_board(board: &conduit_eagle::Board, z: f64, offset: [f64; 2]) -> Self {
        let parts = board
            .elements
            .iter()
            .map(|e| PartPlacement {
                name: e.name.clone(),
                x: e.x + offset[0],
                y: e.y + offset[1],
                z,
                rotation: e.rotation.degrees,
                tilt: [0.0; 2],
                mirror: e.rotation.mirror,
                method: PlacingMethod::Auto,
                connection: Connection::None,
                body_height: 0.0,
                footprint_height: 0.0,
                body_size: None,
                object: 0,
            })
            .collect();
        Placement {
            parts,
            ..Placement::default()
        }
    }

    /// The pose of part `name`.
    pub fn part(&self, name: &str) -> Option<&PartPlacement> {
        self.parts.iter().find(|p| p.name == name)
    }

    /// The routing hints of net `name`.
    pub fn net(&self, name: &str) -> Option<&NetRouting> {
        self.nets.iter().find(|n| n.name == name)
    }

    /// Checks every number of the placement: finite, sizes not negative, positions within
    /// [`MAX_POSITION_MM`], sizes within [`MAX_PART_SIZE_MM`], angles within
    /// [`MAX_ANGLE_DEG`]. [`Placement::load`] runs it, so a placement file with a wild number is
    /// refused where it is read, naming the file; [`Placement::validate`] reports the same.
    ///
    /// # Errors
    /// [`PlacementError::Invalid`] listing each number, by part or waypoint and key.
    pub fn check_numbers(&self) -> Result<(), PlacementError> {
        let problems = self.number_problems();
        if problems.is_empty() {
            Ok(())
        } else {
            Err(PlacementError::Invalid(problems))
        }
    }

    /// The problems [`Placement::check_numbers`] reports.
    fn number_problems(&self) -> Vec<Problem> {
        let mut problems = Vec::new();
        let mut check = |item: &dyn Fn() -> String,
                         key: &'static str,
                         value: f64,
                         limit: f64,
                         unit: &'static str,
                         size: bool| {
            if !value.is_finite() || (size && value < 0.0) {
                problems.push(Problem::BadNumber { item: item(), key });
            } else if value.abs() > limit {
                problems.push(Problem::OutOfRange {
                    item: item(),
                    key,
                    value,
                    limit,
                    unit,
                });
            }
        };
        for p in &self.parts {
            let item = || format!("part \"{}\"", p.name);
            for (key, v) in [("x", p.x), ("y", p.y), ("z", p.z)] {
                check(&item, key, v, MAX_POSITION_MM, "mm", false);
            }
            check(&item, "rotation", p.rotation, MAX_ANGLE_DEG, "°", false);
            for v in p.tilt {
                check(&item, "tilt", v, MAX_ANGLE_DEG, "°", false);
            }
            for (key, v) in [
                ("body_height", p.body_height),
                ("footprint_height", p.footprint_height),
            ] {
                check(&item, key, v, MAX_PART_SIZE_MM, "mm", true);
            }
            for v in p.body_size.into_iter().flatten() {
                check(&item, "body_size", v, MAX_PART_SIZE_MM, "mm", true);
            }
        }
        for n in &self.nets {
            for w in &n.waypoints {
                let item = || format!("net {} waypoint \"{}\"", n.name, w.name);
                for (key, v) in [("x", w.x), ("y", w.y), ("z", w.z)] {
                    check(&item, key, v, MAX_POSITION_MM, "mm", false);
                }
            }
        }
        // Whole turns about x or y leave a part upright.
        let upright = |a: f64| {
            let r = a.rem_euclid(360.0);
            r.min(360.0 - r) < 1e-6
        };
        for p in &self.parts {
            if p.tilt.iter().all(|a| a.is_finite()) && !p.tilt.iter().all(|&a| upright(a)) {
                problems.push(Problem::Tilted {
                    part: p.name.clone(),
                    tilt: p.tilt,
                });
            }
        }
        problems
    }

    /// Checks the placement against `circuit` and returns every problem: unknown or repeated
    /// parts and nets, wire ends on pins that do not exist or belong to another net, unknown or
    /// badly named waypoints, and numbers that are not finite (or negative sizes).
    pub fn validate(&self, circuit: &Circuit) -> Result<(), PlacementError> {
        let mut problems = self.number_problems();
        for (i, p) in self.parts.iter().enumerate() {
            if circuit.part(&p.name).is_none() {
                problems.push(Problem::UnknownPart {
                    part: p.name.clone(),
                    closest: closest(&p.name, circuit.parts.iter().map(|q| q.name.as_str())),
                });
            } else if self.parts[..i].iter().any(|q| q.name == p.name) {
                problems.push(Problem::DuplicatePart {
                    part: p.name.clone(),
                });
            }
        }
        for (i, n) in self.nets.iter().enumerate() {
            let Some(net) = circuit.net(&n.name) else {
                problems.push(Problem::UnknownNet {
                    net: n.name.clone(),
                    closest: closest(&n.name, circuit.nets.iter().map(|m| m.name.as_str())),
                });
                continue;
            };
            if self.nets[..i].iter().any(|m| m.name == n.name) {
                problems.push(Problem::DuplicateNet {
                    net: n.name.clone(),
                });
            }
            for (j, w) in n.waypoints.iter().enumerate() {
                if w.name.contains('.') || n.waypoints[..j].iter().any(|v| v.name == w.name) {
                    problems.push(Problem::BadWaypointName {
                        net: n.name.clone(),
                        name: w.name.clone(),
                    });
                }
            }
            for end in n.wires.iter().flatten() {
                match end {
                    Endpoint::Waypoint(name) => {
                        if !n.waypoints.iter().any(|w| &w.name == name) {
                            problems.push(Problem::UnknownWaypoint {
                                net: n.name.clone(),
                                name: name.clone(),
                            });
                        }
                    }
                    Endpoint::Pin(pin) => {
                        match circuit.part(&pin.part).and_then(|p| p.pad(&pin.pad)) {
                            None => problems.push(Problem::UnknownPin {
                                net: n.name.clone(),
                                pin: pin.to_string(),
                                closest: closest_pin(circuit, pin),
                            }),
                            Some(pad) => {
                                let resolved = PinRef::new(&pin.part, &pad.name);
                                if !net.pins.contains(&resolved) {
                                    problems.push(Problem::PinNotOnNet {
                                        net: n.name.clone(),
                                        pin: pin.to_string(),
                                    });
                                }
                            }
                        }
                    }
                }
            }
        }
        if problems.is_empty() {
            Ok(())
        } else {
            Err(PlacementError::Invalid(problems))
        }
    }

    /// The same placement in model coordinates ([`Origin::Model`]): with
    /// [`Origin::BboxCenter`], each part and waypoint is shifted by its object's bounding-box
    /// centre in x, y and its minimum z. `object_bboxes[i]` is the model-space bounding box of
    /// scene object `i`; with [`Origin::Model`] it is not used.
    ///
    /// # Errors
    /// [`PlacementError::NoSuchObject`] for an object index without a bounding box.
    pub fn to_model(
        &self,
        object_bboxes: &[crate::geom::BoundingBox],
    ) -> Result<Placement, PlacementError> {
        let mut out = self.clone();
        if self.origin == Origin::Model {
            return Ok(out);
        }
        let shift = |object: usize, item: String| -> Result<[f64; 3], PlacementError> {
            let b = object_bboxes
                .get(object)
                .ok_or(PlacementError::NoSuchObject {
                    item,
                    object,
                    count: object_bboxes.len(),
                })?;
            Ok([
                (b.min[0] + b.max[0]) / 2.0,
                (b.min[1] + b.max[1]) / 2.0,
                b.min[2],
            ])
        };
        for p in &mut out.parts {
            let [dx, dy, dz] = shift(p.object, format!("part \"{}\"", p.name))?;
            (p.x, p.y, p.z) = (p.x + dx, p.y + dy, p.z + dz);
        }
        for n in &mut out.nets {
            for w in &mut n.waypoints {
                let [dx, dy, dz] =
                    shift(w.object, format!("net {} waypoint \"{}\"", n.name, w.name))?;
                (w.x, w.y, w.z) = (w.x + dx, w.y + dy, w.z + dz);
            }
        }
        out.origin = Origin::Model;
        Ok(out)
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::circuit::tests::{sample, sample_dir};

    pub(crate) fn sample_placement() -> Placement {
        match Placement::load(&sample_dir().join("placement.toml")) {
            Ok(p) => p,
            Err(e) => panic!("{e}"),
        }
    }

    pub(crate) fn err_text<T: std::fmt::Debug>(r: Result<T, PlacementError>) -> String {
        match r {
            Ok(v) => panic!("expected an error, got {v:?}"),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn sample_placement_loads_and_matches_the_circuit() {
        let p = sample_placement();
        assert_eq!(p.origin, Origin::Model);
        assert_eq!(p.source.as_deref(), Some("led_coin.sch"));
        let names: Vec<&str> = p.parts.iter().map(|q| q.name.as_str()).collect();
        assert_eq!(names, ["BAT1", "R1", "LED1"]);
        let bat = p.part("BAT1").cloned();
        assert_eq!(
            bat,
            Some(PartPlacement {
                name: "BAT1".into(),
                x: 15.0,
                y: 15.0,
                z: 4.0,
                rotation: 0.0,
                tilt: [0.0, 0.0],
                mirror: false,
                method: PlacingMethod::Manual,
                connection: Connection::None,
                body_height: 3.2,
                footprint_height: 0.0,
                body_size: Some([24.0, 21.0]),
                object: 0,
            })
        );
        assert_eq!(
            p.part("LED1").map(|q| (q.rotation, q.body_height)),
            Some((90.0, 1.0))
        );
        assert_eq!(p.part("R1").map(|q| q.body_height), Some(0.6));
        let vcc = p.net("VCC");
        assert_eq!(
            vcc.map(|n| n.wires.clone()),
            Some(vec![
                [
                    Endpoint::Pin(PinRef::new("BAT1", "+")),
                    Endpoint::Waypoint("w1".into())
                ],
                [
                    Endpoint::Waypoint("w1".into()),
                    Endpoint::Pin(PinRef::new("R1", "1"))
                ],
            ])
        );
        assert!(p.validate(&sample()).is_ok());
    }

    #[test]
    fn unknown_parts_pins_and_waypoints_are_named() {
        let p = Placement::from_toml(
            r#"
            [[part]]
            name = "R9"
            x = 1.0
            y = 2.0
            z = 3.0
            [[part]]
            name = "R1"
            x = 1.0
            y = 2.0
            z = inf
            [[net]]
            name = "VCC"
            wires = [["LED1.X", "w9"], ["R1.2", "BAT1.+"]]
            [[net]]
            name = "NOPE"
            "#,
        );
        let Ok(p) = p else { panic!("{p:?}") };
        let msg = err_text(p.validate(&sample()));
        for want in [
            "placement: part \"R9\" is not in the circuit; did you mean \"R1\"?",
            "placement: part \"R1\": z must be a finite number",
            "net VCC: pin LED1.X does not exist",
            "net VCC: waypoint \"w9\" is not defined",
            "net VCC: pin R1.2 is not on this net",
            "placement: net \"NOPE\" is not in the circuit",
        ] {
            assert!(msg.contains(want), "{want:?} not in {msg:?}");
        }
        let Err(PlacementError::Invalid(problems)) = p.validate(&sample()) else {
            panic!()
        };
        assert_eq!(problems.len(), 6);
    }

    #[test]
    fn wild_numbers_are_refused_where_the_file_is_read() {
        let dir = tempfile::tempdir().ok();
        let Some(dir) = dir else { return };
        let path = dir.path().join("far.toml");
        let text = r#"
            [[part]]
            name = "BAT1"
            x = 0
            y = -1e9
            z = 1e39
            rotation = 1e300
            body_size = [1e9, 1.0]
            [[part]]
            name = "R1"
            x = 10000.0
            y = -10000.0
            z = 4.0
            [[net]]
            name = "VCC"
            waypoints = [{ name = "w1", x = 4.0, y = 9223372036854775807, z = 4.0 }]
        "#;
        std::fs::write(&path, text).ok();
        let msg = err_text(Placement::load(&path));
        for want in [
            "far.toml: ",
            "part \"BAT1\": y = -1e9 mm is beyond the limit of ±10000 mm",
            "part \"BAT1\": z = 1e39 mm",
            "part \"BAT1\": rotation = 1e300 °",
            "part \"BAT1\": body_size = 1e9 mm is beyond the limit of ±1000 mm",
            "net VCC waypoint \"w1\": y = 9.223372036854776e18 mm",
        ] {
            assert!(msg.contains(want), "{want:?} not in {msg:?}");
        }
        assert!(!msg.contains("R1"), "{msg}");
        assert!(!msg.contains('\n'), "{msg}");
        assert!(sample_placement().check_numbers().is_ok());
    }

    #[test]
    fn toml_errors_name_the_file_line_and_key() {
        let dir = tempfile::tempdir().ok();
        let Some(dir) = dir else { return };
        let path = dir.path().join("bad.toml");
        std::fs::write(
            &path,
            "origin = \"model\"\n[[part]]\nname = \"R1\"\ncolour = 3\n",
        )
        .ok();
        let msg = err_text(Placement::load(&path));
        assert!(
            msg.contains("bad.toml") && msg.contains("line 4") && msg.contains("colour"),
            "{msg}"
        );
        let msg = err_text(Placement::from_toml("origin = \"centre\""));
        assert!(msg.contains("line 1") && msg.contains("centre"), "{msg}");
        // Values of the wrong type in words, after their key.
        let msg = err_text(Placement::from_toml("[[part]]\nname = 3\n"));
        assert_eq!(msg, "line 2: part[0].name must be text in quotes, got 3");
        let msg = err_text(Placement::from_toml(
            "[[part]]\nname = \"R1\"\nx = \"a\"\ny = 0\nz = 0\n",
        ));
        assert_eq!(msg, "line 3: part[0].x must be a number, got \"a\"");
        let path = dir.path().join("p.json");
        assert!(err_text(Placement::load(&path)).contains("p.json"));
    }

    pub(crate) const BOARD: &str = r#"<?xml version="1.0"?>
<eagle version="9.6.2"><drawing><board>
 <libraries><library name="L"><packages><package name="P">
  <smd name="1" x="-1" y="0" dx="1" dy="1" layer="1"/>
  <smd name="2" x="1" y="0" dx="1" dy="1" layer="1"/>
 </package></packages></library></libraries>
 <elements>
  <element name="R1" library="L" package="P" value="1k" x="10" y="20" rot="R90"/>
  <element name="R2" library="L" package="P" value="2k" x="30" y="20" rot="MR0"/>
 </elements>
 <signals>
  <signal name="A"><contactref element="R1" pad="2"/><contactref element="R2" pad="1"/></signal>
  <signal name="B"><contactref element="R1" pad="1"/></signal>
 </signals>
</board></drawing></eagle>"#;

    #[test]
    fn board_projection_applies_z_offset_rotation_and_mirror() {
        let b = match conduit_eagle::read_board(BOARD.as_bytes()) {
            Ok(b) => b,
            Err(e) => panic!("{e}"),
        };
        let p = Placement::from_board(&b, 2.5, [-5.0, 3.0]);
        assert_eq!(p.origin, Origin::Model);
        let pose = |n: &str| p.part(n).map(|q| (q.x, q.y, q.z, q.rotation, q.mirror));
        assert_eq!(pose("R1"), Some((5.0, 23.0, 2.5, 90.0, false)));
        assert_eq!(pose("R2"), Some((25.0, 23.0, 2.5, 0.0, true)));
        let c = Circuit::from_board(&b);
        // B has one pad: kept, so a placement may wire it to a terminal.
        assert_eq!(c.nets.len(), 2);
        assert_eq!(
            c.nets[0].pins,
            [PinRef::new("R1", "2"), PinRef::new("R2", "1")]
        );
        assert_eq!((c.nets[1].name.as_str(), c.nets[1].pins.len()), ("B", 1));
        assert!(p.validate(&c).is_ok());
    }
}
