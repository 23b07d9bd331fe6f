//! Previews of a G-code file: one SVG per printed layer, a PNG contact sheet and side views.
//!
//! Place in the pipeline: the end of the line, beside `check`. It reads the [`Moves`] that
//! [`conduit_gcode::moves`] replays from any G-code (conduit's own or another
//! slicer's), and the part events and part description in its comments ([`parts`]), and never
//! reaches back into the pipeline.
//!
//! - [`Preview::from_moves`] groups the moves of each layer into polylines: extrusions by
//!   feature role (the latest `;TYPE:` / `; FEATURE:` comment), tool and width (the latest
//!   `;WIDTH:` comment, else [`DEFAULT_WIDTH`]), and travels (XY moves that do not extrude).
//!   [`Preview::with_parts`] adds the parts [`placed_parts`] reads, each on the layer printed
//!   over it.
//! - Colours: one per role ([`role_colour`]: PrusaSlicer's where it has the role, conduit's
//!   conductive traces in a magenta no other role has), a darker or lighter tint per tool
//!   ([`tint`]); parts in [`PART_COLOUR`]. The legends name each (role, tool) pair as
//!   [`Preview::style_label`] does: `External perimeter (T0)`.
//! - [`svg`] draws one layer: a heading with the layer's number and Z ([`layer_heading`]),
//!   the drawing (its view box covers the extrusions of every layer so the files line up, +Y
//!   up, extrusions stroked at their width, travels as [`TRAVEL_WIDTH`] grey lines, the parts
//!   placed before the layer outlined and named), then a scale bar and the legend. The view
//!   box is in millimetres; `width` and `height` are in pixels, [`SCREEN_PX`] on the longer
//!   side, and the scale bar ([`scale_bar_length`]) keeps the millimetres readable.
//! - [`png`] rasterises every Nth layer into a grid of square tiles with `tiny-skia`
//!   (extrusions and parts; travels left out), each labelled in a strip under it
//!   ([`tile_label`]: `L12  z 2.400`), with the legend under the grid. Text is an 8 × 8 bitmap
//!   font (`font8x8`), so the pixels are the same everywhere.
//! - Side views ([`SIDE_VIEWS`]): every extrusion of the print projected onto the XZ and YZ
//!   planes, planar layers in grey and non-planar (curved) extrusions highlighted, each part a
//!   labelled box from its seating plane up its height, as SVG ([`svg::side`], with a scale
//!   bar) and PNG ([`png::side`]). An extrusion is curved when a point of it lies off its
//!   layer's Z; [`layered_by_markers`] keeps curved extrusions in the layer they are printed
//!   in (by the `;LAYER_CHANGE` markers) instead of making a layer of every height.
//! - [`render`] draws `layer_0001.svg`…, [`CONTACT_SHEET`] and the side views as named files
//!   for the caller to write; [`is_layer_file_name`] tells the caller which files in the
//!   folder are layer views, so that those of an earlier run with more layers can go.
//!
//! Output bytes depend only on the input: SVG numbers have a fixed 3 decimals, pixel sizes
//! are whole numbers, and the PNG encoder writes no timestamp.

pub mod parts;
pub mod png;
pub mod svg;
mod text;

use conduit_gcode::Moves;
pub use parts::{PartMark, PartMethod, placed_parts};

/// Stroke width of extrusions without a `;WIDTH:` comment, mm.
pub const DEFAULT_WIDTH: f64 = 0.4;
/// Stroke width of travels in the SVGs, mm.
pub const TRAVEL_WIDTH: f64 = 0.05;
/// Colour of travels, RGB.
pub const TRAVEL_COLOUR: [u8; 3] = [0x99, 0x99, 0x99];
/// Most tiles the default `every` gives the contact sheet.
pub const MAX_DEFAULT_TILES: usize = 36;
/// File name of the contact sheet.
pub const CONTACT_SHEET: &str = "contact_sheet.png";
/// Role of the start and end G-code's extrusions (PrusaSlicer's and conduit's `;TYPE:Custom`).
pub const CUSTOM_ROLE: &str = "Custom";
/// Role name of extrusions before any role comment.
pub const UNNAMED_ROLE: &str = "Extrusion";
/// Colour of part outlines, boxes and names, RGB.
pub const PART_COLOUR: [u8; 3] = [0x1a, 0x1a, 0x1a];
/// Size of the longer side of the SVGs on screen, pixels (`width`/`height`; the view box stays
/// in millimetres).
pub const SCREEN_PX: f64 = 1000.0;

/// Options of [`render`].
#[derive(Debug, Clone, PartialEq)]
pub struct PreviewParams {
    /// Contact sheet: every Nth layer (layers 1, 1 + N, 1 + 2N…). `None`: the smallest N that
    /// keeps the sheet at [`MAX_DEFAULT_TILES`] tiles or fewer.
    pub every: Option<usize>,
    /// Contact sheet tile size, pixels (tiles are square). Default 256.
    pub tile_px: u32,
}

impl Default for PreviewParams {
    fn default() -> Self {
        Self {
            every: None,
            tile_px: 256,
        }
    }
}

/// Why a preview could not be made.
#[derive(Debug, thiserror::Error)]
pub enum PreviewError {
    /// Nothing extrudes, so there is no layer to draw.
    ///
    /// How to fix: check that the file is a print (E increases on moves with X or Y); a file
    /// of travels only has no layers.
    #[error("no extruding moves with known positions: nothing to preview")]
    NoExtrusion,
    /// `every` or `tile_px` is zero.
    #[error("invalid preview option: {0}")]
    InvalidParams(&'static str),
    /// The contact sheet would be too large for one image.
    #[error("contact sheet of {width}×{height} pixels is too large; use a smaller --tile")]
    SheetTooLarge {
        /// Pixels across.
        width: u64,
        /// Pixels down.
        height: u64,
    },
    /// PNG encoding failed.
    #[error("encoding the contact sheet as PNG")]
    Png(#[source] Box<dyn std::error::Error + Send + Sync>),
}

/// What one polyline draws.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StrokeKind {
    /// XY moves that do not extrude.
    Travel,
    /// Extruding moves.
    Extrusion {
        /// Index into [`Preview::roles`].
        role: usize,
        /// Tool number.
        tool: usize,
        /// Extrusion width, mm.
        width: f64,
    },
}

/// A run of consecutive moves of one kind: a polyline in mm.
#[derive(Debug, Clone, PartialEq)]
pub struct Stroke {
    /// Travel or extrusion (role, tool, width).
    pub kind: StrokeKind,
    /// Points [X, Y], mm; at least two.
    pub points: Vec<[f64; 2]>,
    /// Z of each point, mm (the layer's Z where the file leaves it unknown).
    pub z: Vec<f64>,
    /// A non-planar extrusion: some point lies off its layer's Z (curved top or curved layer).
    pub curved: bool,
}

/// The strokes of one printed layer, in file order.
#[derive(Debug, Clone, PartialEq)]
pub struct LayerStrokes {
    /// Layer height, mm.
    pub z: f64,
    /// Polylines.
    pub strokes: Vec<Stroke>,
}

/// Everything the SVG and PNG writers draw.
#[derive(Debug, Clone, PartialEq)]
pub struct Preview {
    /// One entry per printed layer (see [`Moves`] for how layers are numbered).
    pub layers: Vec<LayerStrokes>,
    /// Role names in order of first appearance ([`UNNAMED_ROLE`] for extrusions before any
    /// role comment).
    pub roles: Vec<String>,
    /// (role, tool) pairs that extrude anywhere, sorted: the legend.
    pub styles: Vec<(usize, usize)>,
    /// Extent of the extrusions of all layers: [min X, min Y, max X, max Y], mm.
    pub bounds: [f64; 4],
    /// The parts the file places, in file order (see [`placed_parts`]); none unless given with
    /// [`Preview::with_parts`].
    pub parts: Vec<PartMark>,
}

impl Preview {
    /// Groups `moves` into per-layer polylines. Moves from or to an unknown XY position and
    /// moves without X or Y (Z lifts, retractions) are not drawn.
    pub fn from_moves(moves: &Moves) -> Result<Self, PreviewError> {
        let mut layers: Vec<LayerStrokes> = moves
            .layer_z
            .iter()
            .map(|&z| LayerStrokes {
                z,
                strokes: Vec::new(),
            })
            .collect();
        let mut roles: Vec<String> = Vec::new();
        let mut styles = Vec::new();
        // The view frames the part: extrusions of the start/end G-code (role `Custom`, e.g. a
        // prime line at the bed's edge) are drawn but only frame the view when nothing else does.
        let mut bounds: Option<[f64; 4]> = None;
        let mut custom_bounds: Option<[f64; 4]> = None;
        for m in &moves.moves {
            if !m.has_xy {
                continue;
            }
            let Some(points) = m
                .path
                .iter()
                .map(|p| Some([p[0]?, p[1]?]))
                .collect::<Option<Vec<[f64; 2]>>>()
            else {
                continue;
            };
            let Some(layer) = layers.get_mut(m.layer) else {
                continue;
            };
            let z: Vec<f64> = m.path.iter().map(|p| p[2].unwrap_or(layer.z)).collect();
            // Off the layer's Z by more than the G-code's rounding.
            let curved = m.extruding && z.iter().any(|&v| (v - layer.z).abs() > 5e-4);
            let kind = if m.extruding {
                let name = m.role.as_deref().unwrap_or(UNNAMED_ROLE);
                let role = match roles.iter().position(|r| r == name) {
                    Some(i) => i,
                    None => {
                        roles.push(name.to_owned());
                        roles.len() - 1
                    }
                };
                if !styles.contains(&(role, m.tool)) {
                    styles.push((role, m.tool));
                }
                let frame = if name == CUSTOM_ROLE {
                    &mut custom_bounds
                } else {
                    &mut bounds
                };
                for p in &points {
                    let b = frame.get_or_insert([p[0], p[1], p[0], p[1]]);
                    *b = [
                        b[0].min(p[0]),
                        b[1].min(p[1]),
                        b[2].max(p[0]),
                        b[3].max(p[1]),
                    ];
                }
                StrokeKind::Extrusion {
                    role,
                    tool: m.tool,
                    width: m.width.unwrap_or(DEFAULT_WIDTH),
                }
            } else {
                StrokeKind::Travel
            };
            match layer.strokes.last_mut() {
                Some(s)
                    if s.kind == kind
                        && s.curved == curved
                        && s.points.last() == points.first()
                        && (kind == StrokeKind::Travel || s.z.last() == z.first()) =>
                {
                    s.points.extend_from_slice(&points[1..]);
                    s.z.extend_from_slice(&z[1..]);
                }
                _ => layer.strokes.push(Stroke {
                    kind,
                    points,
                    z,
                    curved,
                }),
            }
        }
        let bounds = bounds.or(custom_bounds).ok_or(PreviewError::NoExtrusion)?;
        styles.sort_unstable();
        Ok(Self {
            layers,
            roles,
            styles,
            bounds,
            parts: Vec::new(),
        })
    }

    /// The preview with `parts` to label: each drawn on its layer's view and tile and in the
    /// side views. Parts whose layer is not a layer of the preview are left out.
    pub fn with_parts(mut self, parts: &[PartMark]) -> Self {
        self.parts = parts
            .iter()
            .filter(|p| p.layer < self.layers.len())
            .cloned()
            .collect();
        self
    }

    /// The parts placed before layer `index` (0-based).
    pub fn parts_on(&self, index: usize) -> impl Iterator<Item = &PartMark> {
        self.parts.iter().filter(move |p| p.layer == index)
    }

    /// Whether any part has a position to draw (machine-placed parts).
    pub fn has_placed_parts(&self) -> bool {
        self.parts.iter().any(|p| p.position.is_some())
    }

    /// The legend's name of extrusions of `role` by `tool`: `External perimeter (T0)`.
    pub fn style_label(&self, role: usize, tool: usize) -> String {
        let name = self.roles.get(role).map_or(UNNAMED_ROLE, String::as_str);
        format!("{name} (T{tool})")
    }

    /// The colour of extrusions of `role` (an index into [`Preview::roles`]) by `tool`, RGB.
    pub fn colour(&self, role: usize, tool: usize) -> [u8; 3] {
        let name = self.roles.get(role).map_or(UNNAMED_ROLE, String::as_str);
        tint(role_colour(name, role), tool)
    }

    /// The contact sheet's `every` for `params`: the given one, or the smallest that keeps the
    /// sheet at [`MAX_DEFAULT_TILES`] tiles or fewer.
    pub fn every(&self, params: &PreviewParams) -> usize {
        params
            .every
            .unwrap_or_else(|| self.layers.len().div_ceil(MAX_DEFAULT_TILES))
            .max(1)
    }
}

/// Colour of conductive traces, RGB: a magenta no other role uses.
pub const TRACE_COLOUR: [u8; 3] = [0xff, 0x00, 0xcc];
/// Colour of conductive drops (dots of paste on pads), RGB: a darker tint of
/// [`TRACE_COLOUR`].
pub const TRACE_DROP_COLOUR: [u8; 3] = [0xa6, 0x00, 0x85];

/// The colour of a role, RGB: PrusaSlicer's preview colours for its roles and the matching
/// Cura and OrcaSlicer names (a darker yellow for perimeters, to show on white), conduit's own
/// roles, and a fixed palette by order of appearance for any other name.
pub fn role_colour(name: &str, index: usize) -> [u8; 3] {
    const PALETTE: [[u8; 3]; 8] = [
        [0x1f, 0x77, 0xb4],
        [0xd6, 0x27, 0x28],
        [0x2c, 0xa0, 0x2c],
        [0x94, 0x67, 0xbd],
        [0x8c, 0x56, 0x4b],
        [0xe3, 0x77, 0xc2],
        [0x7f, 0x7f, 0x7f],
        [0xbc, 0xbd, 0x22],
    ];
    match name.to_ascii_lowercase().as_str() {
        "external perimeter" | "wall-outer" | "outer wall" => [0xff, 0x7d, 0x38],
        "perimeter" | "wall-inner" | "inner wall" => [0xe6, 0xb8, 0x00],
        "overhang perimeter" | "overhang wall" => [0x1f, 0x1f, 0xff],
        "internal infill" | "fill" | "sparse infill" => [0xb0, 0x30, 0x29],
        "solid infill" | "skin" | "internal solid infill" | "bottom surface" => [0x96, 0x54, 0xcc],
        "top solid infill" | "top surface" => [0xf0, 0x40, 0x40],
        "bridge infill" | "bridge" | "internal bridge" => [0x4d, 0x80, 0xba],
        "gap fill" | "gap infill" => [0x3d, 0xb8, 0xb8],
        "skirt/brim" | "skirt" | "brim" => [0x00, 0x87, 0x6e],
        "support material" | "support" => [0x00, 0xc0, 0x00],
        "support material interface" | "support-interface" | "support interface" => {
            [0x00, 0x80, 0x00]
        }
        "wipe tower" | "prime-tower" | "prime tower" => [0xb3, 0xe3, 0xab],
        "ironing" => [0xff, 0x8c, 0x69],
        "custom" => [0x5e, 0xd1, 0x94],
        // Magenta: far from every other role here (and from the blue of bridges).
        "conductive trace" => TRACE_COLOUR,
        "conductive drop" => TRACE_DROP_COLOUR,
        "scaffold" => [0xa0, 0xa0, 0xa0],
        "buffer" => [0xc8, 0xa0, 0xc8],
        _ => PALETTE[index % PALETTE.len()],
    }
}

/// `rgb` tinted for `tool`: tool 0 as is, then darker, lighter, much darker, much lighter,
/// repeating every five tools.
pub fn tint(rgb: [u8; 3], tool: usize) -> [u8; 3] {
    // Positive: mix towards white; negative: towards black.
    let amount: f64 = match tool % 5 {
        0 => 0.0,
        1 => -0.35,
        2 => 0.4,
        3 => -0.6,
        _ => 0.65,
    };
    rgb.map(|c| {
        let c = f64::from(c);
        let v = if amount >= 0.0 {
            c + (255.0 - c) * amount
        } else {
            c * (1.0 + amount)
        };
        v.round().clamp(0.0, 255.0) as u8
    })
}

/// `moves` with printed layers numbered by the file's `;LAYER_CHANGE` markers (conduit's and
/// PrusaSlicer's) instead of by distinct extrusion heights, when the heights would give more
/// layers than the markers: non-planar extrusions (curved tops inside a layer, curved layers,
/// spiral vases) then stay in the layer they are printed in instead of each height becoming a
/// layer. A layer's Z is the `;Z:` value after its marker (else its first extrusion's Z);
/// markers without extrusions give no layer. Other files are returned unchanged.
pub fn layered_by_markers(gcode: &conduit_gcode::Gcode, moves: Moves) -> Moves {
    // (line number of the marker, its Z).
    let mut marks: Vec<(usize, Option<f64>)> = Vec::new();
    for line in &gcode.lines {
        let text = String::from_utf8_lossy(&line.text);
        let text = text.trim();
        if text.starts_with(";LAYER_CHANGE") {
            marks.push((line.number, None));
        } else if let (Some(z), Some(last)) = (text.strip_prefix(";Z:"), marks.last_mut()) {
            if last.1.is_none() {
                last.1 = z.trim().parse().ok();
            }
        }
    }
    if marks.is_empty() || moves.layer_z.len() <= marks.len() {
        return moves;
    }
    // Marker index of each move (moves before the first marker go with the first).
    let section = |line: usize| marks.partition_point(|&(l, _)| l <= line).saturating_sub(1);
    let mut used = vec![false; marks.len()];
    let mut first_z: Vec<Option<f64>> = vec![None; marks.len()];
    for m in moves.moves.iter().filter(|m| m.extruding) {
        let k = section(m.line);
        used[k] = true;
        if first_z[k].is_none() {
            first_z[k] = m.to[2];
        }
    }
    let mut index = vec![0; marks.len()];
    let mut layer_z = Vec::new();
    for k in 0..marks.len() {
        index[k] = layer_z.len().saturating_sub(1);
        if used[k] {
            index[k] = layer_z.len();
            layer_z.push(marks[k].1.or(first_z[k]).unwrap_or(0.0));
        }
    }
    let Moves { mut moves, .. } = moves;
    // Travels lead to the next extruding move's layer, as in `check::moves`.
    let mut next = layer_z.len().saturating_sub(1);
    for m in moves.iter_mut().rev() {
        if m.extruding {
            next = index[section(m.line)];
        }
        m.layer = next;
    }
    Moves { moves, layer_z }
}

/// File names of the side views: projections onto the XZ and YZ planes.
pub const SIDE_VIEWS: [&str; 4] = ["side_xz.svg", "side_yz.svg", "side_xz.png", "side_yz.png"];

/// Which vertical plane a side view projects onto.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SideAxis {
    /// X across, Z up (looking along +Y).
    X,
    /// Y across, Z up (looking along −X).
    Y,
}

impl SideAxis {
    /// The horizontal coordinate of a point [X, Y].
    pub fn across(self, p: [f64; 2]) -> f64 {
        match self {
            SideAxis::X => p[0],
            SideAxis::Y => p[1],
        }
    }

    /// The file name part: `xz` or `yz`.
    pub fn name(self) -> &'static str {
        match self {
            SideAxis::X => "xz",
            SideAxis::Y => "yz",
        }
    }
}

/// Colour of planar extrusions in the side views, RGB.
pub const SIDE_PLANAR_COLOUR: [u8; 3] = [0xb0, 0xb0, 0xb0];
/// Colour of non-planar (curved) extrusions in the side views, RGB.
pub const SIDE_CURVED_COLOUR: [u8; 3] = [0xd6, 0x27, 0x28];

impl Preview {
    /// Extent of the extrusions in a side view: [min across, min Z, max across, max Z], mm
    /// (`None` when nothing extrudes).
    /// As in the layer views, extrusions of the start and end G-code (role `Custom`) only frame
    /// the view when nothing else does.
    pub fn side_bounds(&self, axis: SideAxis) -> Option<[f64; 4]> {
        let mut part: Option<[f64; 4]> = None;
        let mut custom: Option<[f64; 4]> = None;
        for layer in &self.layers {
            for s in &layer.strokes {
                let StrokeKind::Extrusion { role, .. } = s.kind else {
                    continue;
                };
                let b = if self.roles.get(role).is_some_and(|r| r == CUSTOM_ROLE) {
                    &mut custom
                } else {
                    &mut part
                };
                for (p, &z) in s.points.iter().zip(&s.z) {
                    let a = axis.across(*p);
                    let v = b.get_or_insert([a, z, a, z]);
                    *v = [v[0].min(a), v[1].min(z), v[2].max(a), v[3].max(z)];
                }
            }
        }
        part.or(custom)
    }

    /// Number of curved (non-planar) extrusion strokes.
    pub fn curved_strokes(&self) -> usize {
        self.layers
            .iter()
            .flat_map(|l| &l.strokes)
            .filter(|s| s.curved)
            .count()
    }
}

/// Rows for labels spanning `spans` ([left, right] each, in order) so that labels in one row do
/// not overlap: each takes the lowest row (0 nearest its box) free over its span.
pub fn label_rows(spans: &[[f64; 2]]) -> Vec<usize> {
    let mut rows: Vec<usize> = Vec::with_capacity(spans.len());
    for (i, a) in spans.iter().enumerate() {
        let mut row = 0;
        while spans[..i]
            .iter()
            .zip(&rows)
            .any(|(b, &r)| r == row && a[0] < b[1] && b[0] < a[1])
        {
            row += 1;
        }
        rows.push(row);
    }
    rows
}

/// File name of layer `index` (0-based): `layer_0001.svg` for index 0.
pub fn layer_file_name(index: usize) -> String {
    format!("layer_{:04}.svg", index + 1)
}

/// Whether `name` is a layer view's file name as [`layer_file_name`] writes them: `layer_`,
/// four or more ASCII digits, `.svg` (exactly). The CLI removes such files that a run did not
/// write (left by an earlier run with more layers) and nothing else.
pub fn is_layer_file_name(name: &str) -> bool {
    name.strip_prefix("layer_")
        .and_then(|r| r.strip_suffix(".svg"))
        .is_some_and(|digits| digits.len() >= 4 && digits.bytes().all(|b| b.is_ascii_digit()))
}

/// The label of layer `index` (0-based) at height `z` on its contact-sheet tile:
/// `L12  z 2.400`.
pub fn tile_label(index: usize, z: f64) -> String {
    format!("L{}  z {}", index + 1, svg::num(z))
}

/// The heading of layer `index`'s (0-based) SVG, of `layers` layers, at height `z`:
/// `Layer 12 of 40, z 2.400 mm`.
pub fn layer_heading(index: usize, layers: usize, z: f64) -> String {
    format!("Layer {} of {layers}, z {} mm", index + 1, svg::num(z))
}

/// A round length for the scale bar of a drawing `extent` mm across: the longest 1, 2 or 5 ×
/// 10ⁿ mm that is at most a fifth of it (1 mm for an empty or invalid extent).
pub fn scale_bar_length(extent: f64) -> f64 {
    let target = extent / 5.0;
    if !(target.is_finite() && target > 0.0) {
        return 1.0;
    }
    let decade = 10f64.powi(target.log10().floor() as i32);
    [5.0, 2.0, 1.0]
        .into_iter()
        .map(|m| m * decade)
        .find(|&l| l <= target * (1.0 + 1e-9))
        .unwrap_or(decade)
}

/// The scale bar's label for `length` mm: `20 mm`, `0.5 mm` (no trailing zeros).
pub fn scale_bar_label(length: f64) -> String {
    let s = svg::num(length);
    let s = s.trim_end_matches('0').trim_end_matches('.');
    format!("{s} mm")
}

/// What [`render`] drew: every file of the preview, named, in the order they are written.
#[derive(Debug, Clone, PartialEq)]
pub struct PreviewFiles {
    /// `(file name, bytes)`: one SVG per layer in layer order, [`CONTACT_SHEET`], then the side
    /// views ([`SIDE_VIEWS`]).
    pub files: Vec<(String, Vec<u8>)>,
    /// Layers (one SVG each).
    pub layers: usize,
    /// Every how many layers the contact sheet shows.
    pub every: usize,
    /// Tiles on the contact sheet.
    pub tiles: usize,
}

/// Draws the preview of `moves` with `parts` labelled (see [`placed_parts`]; empty for none):
/// one SVG per layer ([`layer_file_name`]), [`CONTACT_SHEET`] and the side views
/// ([`SIDE_VIEWS`]), as named files for the caller to write.
pub fn render(
    moves: &Moves,
    parts: &[PartMark],
    params: &PreviewParams,
) -> Result<PreviewFiles, PreviewError> {
    if params.every == Some(0) {
        return Err(PreviewError::InvalidParams("every must be at least 1"));
    }
    if params.tile_px == 0 {
        return Err(PreviewError::InvalidParams(
            "tile size must be at least 1 pixel",
        ));
    }
    let preview = Preview::from_moves(moves)?.with_parts(parts);
    // Render the sheet first: a sheet that is too large fails before anything else is drawn.
    let every = preview.every(params);
    let sheet = png::contact_sheet(&preview, every, params.tile_px)?;
    let mut files = Vec::with_capacity(preview.layers.len() + 1 + SIDE_VIEWS.len());
    for i in 0..preview.layers.len() {
        files.push((layer_file_name(i), svg::layer(&preview, i).into_bytes()));
    }
    files.push((CONTACT_SHEET.to_owned(), sheet));
    for axis in [SideAxis::X, SideAxis::Y] {
        files.push((
            format!("side_{}.svg", axis.name()),
            svg::side(&preview, axis).into_bytes(),
        ));
    }
    for axis in [SideAxis::X, SideAxis::Y] {
        files.push((
            format!("side_{}.png", axis.name()),
            png::side(&preview, axis, params.tile_px * 4)?,
        ));
    }
    Ok(PreviewFiles {
        files,
        layers: preview.layers.len(),
        every,
        tiles: preview.layers.len().div_ceil(every),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use conduit_gcode::{Firmware, moves};

    /// Two layers: a 10 mm square (External perimeter, no width comment, tool 0) at Z 0.2
    /// after a travel from the origin, a travel out and back, then the same square (Perimeter,
    /// `;WIDTH:0.45`, tool 1) at Z 0.4.
    const TWO_LAYERS: &str = "M104 S210\nM109 S210\nG28\nG90\nM82\nG92 E0\nG1 Z0.2 F600\n\
        G1 X10 Y10 F6000\n;TYPE:External perimeter\n\
        G1 X20 Y10 E1 F1200\nG1 X20 Y20 E2\nG1 X10 Y20 E3\nG1 X10 Y10 E4\n\
        G1 E3 F2400\nG1 X30 Y30 F6000\nG1 Z0.4\nG1 X10 Y10\nT1\nG1 E4 F2400\n\
        ;TYPE:Perimeter\n;WIDTH:0.45\nG1 X20 Y10 E5 F1200\nG1 X20 Y20 E6\nG1 X10 Y20 E7\nG1 X10 Y10 E8\n";

    const SQUARE: &str =
        "10.000,-10.000 20.000,-10.000 20.000,-20.000 10.000,-20.000 10.000,-10.000";

    fn two_layers() -> Moves {
        match conduit_gcode::parse(TWO_LAYERS.as_bytes()) {
            Ok(g) => moves(&g, Firmware::Marlin),
            Err(e) => panic!("test G-code does not parse: {e}"),
        }
    }

    fn preview() -> Preview {
        Preview::from_moves(&two_layers()).expect("the test program extrudes")
    }

    fn polylines(svg: &str) -> Vec<&str> {
        svg.lines().filter(|l| l.starts_with("<polyline")).collect()
    }

    #[test]
    fn moves_are_grouped_into_layers_and_polylines() {
        let m = two_layers();
        assert_eq!(m.layer_z, vec![0.2, 0.4]);
        let p = preview();
        assert_eq!(p.bounds, [10.0, 10.0, 20.0, 20.0]);
        assert_eq!(p.roles, vec!["External perimeter", "Perimeter"]);
        assert_eq!(p.styles, vec![(0, 0), (1, 1)]);
        assert_eq!(p.layers.len(), 2);
        let kinds: Vec<StrokeKind> = p.layers[0].strokes.iter().map(|s| s.kind).collect();
        assert_eq!(
            kinds,
            vec![
                StrokeKind::Travel,
                StrokeKind::Extrusion {
                    role: 0,
                    tool: 0,
                    width: 0.4
                }
            ]
        );
        // The travel out and back leads to layer 2, so it is drawn there.
        assert_eq!(
            p.layers[1].strokes[0].points,
            vec![[10.0, 10.0], [30.0, 30.0], [10.0, 10.0]]
        );
        assert_eq!(p.every(&PreviewParams::default()), 1);
    }

    #[test]
    fn layer_svg_has_the_flipped_square_and_a_thin_travel() {
        let p = preview();
        let svg = svg::layer(&p, 0);
        let lines = polylines(&svg);
        assert_eq!(lines.len(), 2, "{svg}");
        assert_eq!(
            lines[0],
            format!(
                r#"<polyline data-role="External perimeter" data-tool="0" stroke="{}" stroke-width="0.400" points="{SQUARE}"/>"#,
                "#ff7d38"
            )
        );
        assert_eq!(
            lines[1],
            r#"<polyline points="0.000,0.000 10.000,-10.000"/>"#
        );
        assert!(
            svg.contains(
                r##"<g class="travels" fill="none" stroke="#999999" stroke-width="0.050""##
            )
        );
        // View box: extrusions (10..20 both ways, y flipped) plus the 2 mm margin, a heading
        // row above (1.5 rows of 14/30 mm: 0.7 mm), then the legend: 16.333 mm tall, drawn
        // 1000 px tall.
        assert!(
            svg.contains(r#"width="857" height="1000" viewBox="8.000 -22.700 14.000 16.333""#),
            "{svg}"
        );
        assert!(svg.contains(">Layer 1 of 2, z 0.200 mm</text>"), "{svg}");
        assert!(svg.contains("<title>layer 1 of 2, Z 0.200 mm</title>"));
        assert!(svg.contains(">External perimeter (T0)</text>"));
        assert!(svg.contains(">Perimeter (T1)</text>"));

        let svg2 = svg::layer(&p, 1);
        let lines = polylines(&svg2);
        assert_eq!(lines.len(), 2, "{svg2}");
        let tool1 = hex_of(tint(role_colour("Perimeter", 1), 1));
        assert_eq!(
            lines[0],
            format!(
                r#"<polyline data-role="Perimeter" data-tool="1" stroke="{tool1}" stroke-width="0.450" points="{SQUARE}"/>"#
            )
        );
        assert_ne!(tool1, "#e6b800");
        assert_eq!(
            lines[1],
            r#"<polyline points="10.000,-10.000 30.000,-30.000 10.000,-10.000"/>"#
        );
    }

    fn hex_of(c: [u8; 3]) -> String {
        format!("#{:02x}{:02x}{:02x}", c[0], c[1], c[2])
    }

    #[test]
    fn contact_sheet_shows_the_square_on_background() {
        let p = preview();
        let bytes = png::contact_sheet(&p, 1, 64).expect("the sheet renders");
        let img = tiny_skia::Pixmap::decode_png(&bytes).expect("the PNG decodes");
        // Two 64 px tiles, each with a 12 px label strip, and a legend (8 px font) of two
        // entries in one column, wider than the grid: a margin, the swatch (3 glyphs with its
        // gap), 23 characters and a gap, so 8 + 24 + 184 + 8 px wide; 2 · 12 + 8 px tall.
        assert_eq!((img.width(), img.height()), (224, 64 + 12 + 32));
        let rgb = |x: u32, y: u32| {
            let c = img.pixel(x, y).expect("inside the image").demultiply();
            [c.red(), c.green(), c.blue()]
        };
        // Scale 5.6 px/mm inside a 4 px padding: the square's edges run at 4 and 60 px.
        for tile in [0, 64] {
            for (x, y) in [(4, 32), (60, 32), (32, 4), (32, 60), (4, 4), (60, 60)] {
                assert_ne!(
                    rgb(tile + x, y),
                    png::BACKGROUND,
                    "edge at ({}, {y})",
                    tile + x
                );
            }
            for (x, y) in [(32, 32), (16, 16), (48, 40), (20, 12)] {
                assert_eq!(
                    rgb(tile + x, y),
                    png::BACKGROUND,
                    "inside at ({}, {y})",
                    tile + x
                );
            }
        }
        assert_eq!(rgb(4, 32), [0xff, 0x7d, 0x38]);
        assert_eq!(rgb(64 + 4, 32), tint(role_colour("Perimeter", 1), 1));
    }

    #[test]
    fn render_makes_one_svg_per_layer_and_a_sheet_deterministically() {
        let m = two_layers();
        let params = PreviewParams {
            every: None,
            tile_px: 64,
        };
        let runs = [render(&m, &[], &params), render(&m, &[], &params)]
            .map(|r| r.expect("the preview is drawn"));
        let files = &runs[0];
        assert_eq!(files.layers, 2);
        assert_eq!((files.every, files.tiles), (1, 2));
        let names: Vec<&str> = files.files.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(
            names,
            [
                "layer_0001.svg",
                "layer_0002.svg",
                "contact_sheet.png",
                "side_xz.svg",
                "side_yz.svg",
                "side_xz.png",
                "side_yz.png"
            ]
        );
        assert!(files.files.iter().all(|(_, bytes)| !bytes.is_empty()));
        assert_eq!(runs[0], runs[1]);
    }

    #[test]
    fn default_every_keeps_the_sheet_at_36_tiles() {
        let mut p = preview();
        let layer = p.layers[0].clone();
        p.layers = vec![layer; 100];
        assert_eq!(p.every(&PreviewParams::default()), 3);
        assert_eq!(100usize.div_ceil(3), 34);
        p.layers.truncate(36);
        assert_eq!(p.every(&PreviewParams::default()), 1);
        assert_eq!(png::grid(34), (6, 6));
        assert_eq!(png::grid(2), (2, 1));
        assert_eq!(png::grid(1), (1, 1));
    }

    #[test]
    fn travels_only_is_an_error() {
        let g = conduit_gcode::parse(b"G28\nG1 X10 Y10\n").expect("parses");
        assert!(matches!(
            Preview::from_moves(&moves(&g, Firmware::Marlin)),
            Err(PreviewError::NoExtrusion)
        ));
    }

    #[test]
    fn numbers_have_three_decimals_and_no_negative_zero() {
        assert_eq!(svg::num(-0.0001), "0.000");
        assert_eq!(svg::num(1.23456), "1.235");
        assert_eq!(svg::num(-20.0), "-20.000");
    }

    /// One planar layer at Z 0.2 with a curved block after it (a slope from Z 0.3 to 0.5), then
    /// a planar layer at Z 0.6.
    const CURVED: &str = ";LAYER_CHANGE\n;Z:0.2\nG1 Z0.2\nG1 X10 Y10\n;TYPE:Solid infill\n\
        G1 X20 Y10 E1\n; curved top layer 0 depth 0.000 (object 0)\nG1 X10 Y12 Z0.3\n\
        G1 X15 Y12 Z0.4 E2\nG1 X20 Y12 Z0.5 E3\n;LAYER_CHANGE\n;Z:0.6\nG1 Z0.6\n\
        G1 X10 Y14\nG1 X20 Y14 E4\n";

    #[test]
    fn curved_extrusions_stay_in_their_layer_and_are_highlighted_in_the_side_view() {
        let g = conduit_gcode::parse(CURVED.as_bytes()).expect("parses");
        let plain = moves(&g, Firmware::Marlin);
        // By heights: 0.2, 0.4, 0.5, 0.6.
        assert_eq!(plain.layer_z, vec![0.2, 0.4, 0.5, 0.6]);
        let m = layered_by_markers(&g, plain);
        assert_eq!(m.layer_z, vec![0.2, 0.6]);
        let p = Preview::from_moves(&m).expect("extrudes");
        let curved: Vec<&Stroke> = p.layers[0].strokes.iter().filter(|s| s.curved).collect();
        assert_eq!(curved.len(), 1);
        assert_eq!(
            curved[0].points,
            vec![[10.0, 12.0], [15.0, 12.0], [20.0, 12.0]]
        );
        assert_eq!(curved[0].z, vec![0.3, 0.4, 0.5]);
        assert_eq!(p.curved_strokes(), 1);
        assert_eq!(p.side_bounds(SideAxis::X), Some([10.0, 0.2, 20.0, 0.6]));
        let side = svg::side(&p, SideAxis::X);
        let lines: Vec<&str> = polylines(&side);
        assert_eq!(
            lines,
            vec![
                r#"<polyline data-layer="1" data-curved="false" data-role="Solid infill" points="10.000,-0.200 20.000,-0.200"/>"#,
                r#"<polyline data-layer="2" data-curved="false" data-role="Solid infill" points="10.000,-0.600 20.000,-0.600"/>"#,
                r#"<polyline data-layer="1" data-curved="true" data-role="Solid infill" points="10.000,-0.300 15.000,-0.400 20.000,-0.500"/>"#,
            ]
        );
        // A planar file keeps its layers.
        let planar = two_layers();
        let g = conduit_gcode::parse(TWO_LAYERS.as_bytes()).expect("parses");
        assert_eq!(layered_by_markers(&g, planar.clone()), planar);
        let png = png::side(&p, SideAxis::Y, 64).expect("renders");
        assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    }
    /// The contact sheet's pixel (x, y), RGB.
    fn pixel(img: &tiny_skia::Pixmap, x: u32, y: u32) -> [u8; 3] {
        let c = img.pixel(x, y).expect("inside the image").demultiply();
        [c.red(), c.green(), c.blue()]
    }

    #[test]
    fn layers_are_labelled_with_number_and_z_on_tiles_and_in_svgs() {
        let p = preview();
        assert_eq!(tile_label(1, p.layers[1].z), "L2  z 0.400");
        assert_eq!(layer_heading(1, 2, 0.4), "Layer 2 of 2, z 0.400 mm");
        let svg = svg::layer(&p, 1);
        assert!(
            svg.contains(r##"font-weight="bold" fill="#000000">Layer 2 of 2, z 0.400 mm</text>"##),
            "{svg}"
        );
        let bytes = png::contact_sheet(&p, 1, 64).expect("the sheet renders");
        let img = tiny_skia::Pixmap::decode_png(&bytes).expect("the PNG decodes");
        // Each tile's label strip (y 64..76) has text pixels; the drawing above its bottom
        // padding has none of the text colour.
        for tile in [0, 64] {
            let dark = (tile..tile + 64)
                .flat_map(|x| (64..76).map(move |y| (x, y)))
                .filter(|&(x, y)| pixel(&img, x, y) == png::TEXT)
                .count();
            assert!(dark > 30, "tile at {tile}: {dark} text pixels");
        }
        // Different labels: the two strips differ.
        let strip = |tile: u32| -> Vec<[u8; 3]> {
            (0..64)
                .flat_map(|x| (64..76).map(move |y| (x, y)))
                .map(|(x, y)| pixel(&img, tile + x, y))
                .collect()
        };
        assert_ne!(strip(0), strip(64));
    }

    #[test]
    fn contact_sheet_has_a_legend_of_roles_and_tools() {
        let p = preview();
        assert_eq!(p.style_label(0, 0), "External perimeter (T0)");
        let bytes = png::contact_sheet(&p, 1, 64).expect("the sheet renders");
        let img = tiny_skia::Pixmap::decode_png(&bytes).expect("the PNG decodes");
        // Legend under the 76 px row of tiles, from a 4 px half-gap: swatches 16 × 8 px at x 8,
        // one entry per 12 px row, labels from x 32.
        assert_eq!(pixel(&img, 12, 76 + 4 + 4), [0xff, 0x7d, 0x38]);
        assert_eq!(
            pixel(&img, 12, 76 + 4 + 12 + 4),
            tint(role_colour("Perimeter", 1), 1)
        );
        // A role name of any length keeps the sheet's size in bounds: labels are cut.
        let long = format!(
            "G1 Z0.2\nG1 X0 Y0\n;TYPE:{}\nG1 X10 Y0 E1\n",
            "x".repeat(100_000)
        );
        let g = conduit_gcode::parse(long.as_bytes()).expect("parses");
        let lp = Preview::from_moves(&moves(&g, Firmware::Marlin)).expect("extrudes");
        let sheet = png::contact_sheet(&lp, 1, 64).expect("the sheet renders");
        let sheet = tiny_skia::Pixmap::decode_png(&sheet).expect("decodes");
        // A margin, the swatch, 40 characters.
        assert_eq!(sheet.width(), 8 + 24 + 40 * 8 + 8);
        for row in [0, 12] {
            let text = (32..216)
                .flat_map(|x| (80 + row..88 + row).map(move |y| (x, y)))
                .filter(|&(x, y)| pixel(&img, x, y) == png::TEXT)
                .count();
            assert!(text > 50, "legend row {row}: {text} text pixels");
        }
    }

    #[test]
    fn traces_have_a_colour_no_other_role_has() {
        const NAMED: [&str; 16] = [
            "External perimeter",
            "Perimeter",
            "Overhang perimeter",
            "Internal infill",
            "Solid infill",
            "Top solid infill",
            "Bridge infill",
            "Gap fill",
            "Skirt/Brim",
            "Support material",
            "Support material interface",
            "Wipe tower",
            "Ironing",
            "Custom",
            "Scaffold",
            "Buffer",
        ];
        let distance = |a: [u8; 3], b: [u8; 3]| {
            a.iter()
                .zip(b)
                .map(|(&x, y)| (f64::from(x) - f64::from(y)).powi(2))
                .sum::<f64>()
                .sqrt()
        };
        let trace = role_colour("Conductive trace", 0);
        assert_eq!(trace, TRACE_COLOUR);
        assert_eq!(role_colour("conductive drop", 5), TRACE_DROP_COLOUR);
        for name in NAMED {
            let other = role_colour(name, 0);
            assert!(
                distance(trace, other) > 120.0,
                "{name}: {other:?} is {} from the trace colour",
                distance(trace, other)
            );
        }
        // The drop is a darker tint of the trace: the same hue, about two thirds as bright.
        assert_eq!(TRACE_DROP_COLOUR, tint(TRACE_COLOUR, 1));
        // In a layer view the trace is stroked in its colour.
        let g = conduit_gcode::parse(
            b"G1 Z0.2\nG1 X0 Y0\n;TYPE:Conductive trace\nG1 X10 Y0 E1\nG1 X10 Y5 E2\n",
        )
        .expect("parses");
        let p = Preview::from_moves(&moves(&g, Firmware::Marlin)).expect("extrudes");
        let svg = svg::layer(&p, 0);
        assert!(
            svg.contains(r##"data-role="Conductive trace" data-tool="0" stroke="#ff00cc""##),
            "{svg}"
        );
    }

    #[test]
    fn layer_file_names_are_recognised_exactly() {
        for name in ["layer_0001.svg", "layer_0009.svg", "layer_12345.svg"] {
            assert!(is_layer_file_name(name), "{name}");
        }
        for name in [
            "layer_001.svg",
            "layer_0001.svg.bak",
            "layer_00a1.svg",
            "Layer_0001.svg",
            "layer_0001.SVG",
            "notes.txt",
            "layer_.svg",
            "xlayer_0001.svg",
            "layer_+001.svg",
        ] {
            assert!(!is_layer_file_name(name), "{name}");
        }
        assert!(is_layer_file_name(&layer_file_name(41)));
    }

    #[test]
    fn scale_bars_have_round_lengths() {
        let cases = [
            (14.0, 2.0),
            (60.0, 10.0),
            (100.0, 20.0),
            (99.0, 10.0),
            (250.0, 50.0),
            (3.0, 0.5),
            (0.0, 1.0),
            (f64::NAN, 1.0),
        ];
        for (extent, length) in cases {
            assert!(
                (scale_bar_length(extent) - length).abs() < 1e-12,
                "{extent}: {}",
                scale_bar_length(extent)
            );
        }
        assert_eq!(scale_bar_label(20.0), "20 mm");
        assert_eq!(scale_bar_label(0.5), "0.5 mm");
        let p = preview();
        // 10 mm across: a 2 mm bar.
        let svg = svg::layer(&p, 0);
        assert!(svg.contains(r##"<g class="scale-bar" fill="#000000" data-length="2.000">"##));
        // Under the drawing (SVG y −8 is its bottom edge with the margin; 0.4 rows of 14/30 mm
        // lower), from its left edge, 0.2 rows thick.
        assert!(
            svg.contains(r#"<rect x="10.000" y="-7.813" width="2.000" height="0.093"/>"#),
            "{svg}"
        );
        assert!(svg.contains(">2 mm</text>"));
        let side = svg::side(&p, SideAxis::X);
        assert!(side.contains(r#"data-length="2.000""#), "{side}");
        assert!(side.contains(r#" width="1000" height=""#), "{side}");
    }

    /// A grey darker than the side views' planar grey: the part colour, anti-aliased.
    fn is_dark_grey(c: [u8; 3]) -> bool {
        let (lo, hi) = (c.iter().min(), c.iter().max());
        matches!((lo, hi), (Some(&lo), Some(&hi)) if hi < 0x90 && hi - lo < 8)
    }

    /// [`TWO_LAYERS`] with R1 placed before layer 2 (a 4 × 2 mm outline turned by 90° about
    /// (15, 15), 1 mm tall) and BAT1 inserted by hand before it.
    fn with_parts() -> (Preview, Vec<PartMark>) {
        let text = TWO_LAYERS.replace(
            "G1 Z0.4\n",
            "G1 Z0.4\n;PICK_AND_PLACE PART=R1 X=15 Y=15 Z=0.2 ROTATION=90\n;MANUAL_INSERT PART=BAT1\n",
        ) + ";<object name=\"o\">\n;<part id=\"1\" name=\"R1\">\n;  <size height=\"1\"/>\n\
            ;  <shape>\n;    <point x=\"-2\" y=\"-1\"/>\n;    <point x=\"2\" y=\"-1\"/>\n\
            ;    <point x=\"2\" y=\"1\"/>\n;    <point x=\"-2\" y=\"1\"/>\n;  </shape>\n\
            ;  <destination x=\"15\" y=\"15\" z=\"0.2\" orientation=\"90\"/>\n;</part>\n;</object>\n";
        let g = conduit_gcode::parse(text.as_bytes()).expect("parses");
        let m = moves(&g, Firmware::Marlin);
        let parts = placed_parts(&g, &m);
        let p = Preview::from_moves(&m)
            .expect("extrudes")
            .with_parts(&parts);
        (p, parts)
    }

    #[test]
    fn placed_parts_are_outlined_and_named_on_their_layer() {
        let (p, parts) = with_parts();
        assert_eq!(parts.len(), 2);
        assert_eq!((parts[0].name.as_str(), parts[0].layer), ("R1", 1));
        assert_eq!((parts[1].name.as_str(), parts[1].layer), ("BAT1", 1));
        let first = svg::layer(&p, 0);
        assert!(!first.contains("data-part"), "{first}");
        let second = svg::layer(&p, 1);
        assert!(
            second.contains(
                r#"<polygon data-part="R1" points="16.000,-13.000 16.000,-17.000 14.000,-17.000 14.000,-13.000"/>"#
            ),
            "{second}"
        );
        assert!(second.contains(r#"<text data-part="R1" x="15.000" y="-17.163">R1</text>"#));
        assert!(second.contains(">Inserted by hand before this layer: BAT1</text>"));
        assert!(second.contains(">Part outline</text>"));
        // Side view onto XZ: 14..16 across, from Z 0.2 up 1 mm.
        let side = svg::side(&p, SideAxis::X);
        assert!(
            side.contains(
                r#"<rect data-part="R1" data-layer="2" x="14.000" y="-1.200" width="2.000" height="1.000"/>"#
            ),
            "{side}"
        );
        assert!(side.contains(">R1</text>"));
        assert!(!side.contains("BAT1"));
        // On the second tile the outline (x 14 to 16 mm: 26.4 to 37.6 px) is drawn in the
        // part colour, anti-aliased: dark grey pixels the extrusions' colours never give; the
        // first tile has none.
        let bytes = png::contact_sheet(&p, 1, 64).expect("the sheet renders");
        let img = tiny_skia::Pixmap::decode_png(&bytes).expect("the PNG decodes");
        let part_pixels = |tile: u32| {
            (tile..tile + 64)
                .flat_map(|x| (0..64).map(move |y| (x, y)))
                .filter(|&(x, y)| is_dark_grey(pixel(&img, x, y)))
                .count()
        };
        assert_eq!(part_pixels(0), 0);
        assert!(part_pixels(64) > 20, "{}", part_pixels(64));
        let side_png = png::side(&p, SideAxis::X, 256).expect("renders");
        let side_img = tiny_skia::Pixmap::decode_png(&side_png).expect("decodes");
        let dark = (0..side_img.width())
            .flat_map(|x| (0..side_img.height()).map(move |y| (x, y)))
            .filter(|&(x, y)| is_dark_grey(pixel(&side_img, x, y)))
            .count();
        assert!(dark > 20, "{dark}");
    }
}
