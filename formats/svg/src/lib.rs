//! SVG path reader for 2D designs: shapes, transforms and curves flattened to polylines in
//! millimetres.
//!
//! Part of conduit's `formats/` layer: it describes the file and has no dependency on the
//! pipeline. `conform` and `jet` take the [`Design`] it returns (plain polylines) as their
//! design input.
//!
//! # What is read
//!
//! - `path` (`d` with every command: `M m L l H h V v C c S s Q q T t A a Z z`), `line`,
//!   `polyline`, `polygon`, `rect` (with `rx`/`ry` rounded corners), `circle`, `ellipse`.
//!   Every subpath becomes its own [`DesignPath`], closed when it ends with `Z` (polygons,
//!   rectangles, circles and ellipses are closed).
//! - Containers `g`, `a`, `switch` (its first child without `requiredExtensions`) and nested
//!   `svg` viewports, with `transform` lists
//!   (`matrix`, `translate`, `scale`, `rotate` with or without centre, `skewX`, `skewY`) composed
//!   from the root down, and `use` (`href` or `xlink:href` to `#id`, plus its `x`/`y`; a `symbol`
//!   target draws its children).
//! - Not drawn: `defs`, `clipPath`, `mask`, `pattern`, `marker`, `symbol` (except through `use`),
//!   `text`, `style`, metadata, and elements with `display="none"` (attribute or `style`).
//!   Fill, stroke and stroke width are not read: a design is centre lines.
//!
//! # Units and axes
//!
//! Output coordinates are millimetres with **+y up** and the origin at the **bottom-left corner
//! of the document's viewport** (the viewBox, when its aspect ratio matches the page):
//! `y_mm = height_mm − y_down_mm`, where `y_down_mm` is SVG's own y axis scaled to millimetres.
//!
//! User units map to millimetres from the root element:
//! - `width`/`height` in `mm`, `cm`, `in`, `pt` (1/72 in), `pc` (1/6 in), `px` or no unit
//!   (1 px = 1/96 in = 25.4/96 mm, CSS) give the page size ([`Design::width_mm`],
//!   [`Design::height_mm`]); percentages and values that are not positive are ignored.
//! - With a `viewBox`, the viewBox is fitted to the page per `preserveAspectRatio` (default
//!   `xMidYMid meet`: uniform scale, centred). `width="100mm" viewBox="0 0 1000 1000"` gives
//!   0.1 mm per user unit. A missing `width` or `height` follows from the viewBox's aspect
//!   ratio; with neither, the viewBox is taken in px.
//! - Without a `viewBox`, one user unit is one px (25.4/96 mm). Without a `height` either, there
//!   is no page to flip within, so `y_mm = −y·25.4/96` (the origin stays at SVG's top-left).
//! - Lengths on shapes (`r="5mm"`) are converted to user units at 96 px per inch; percentages
//!   refer to the nearest viewport.
//!
//! # Flattening
//!
//! Curves are flattened after the transform to millimetres, so the distance between each curve
//! and its polyline (both ways) is at most `tolerance_mm` whatever the document's scale:
//! - Bézier curves (`C`, `S`, `Q`, `T`) are subdivided until a provable bound on each piece's
//!   distance from its chord holds; their vertices lie on the curve.
//! - Elliptical arcs (`A`, rounded `rect` corners) are sampled analytically, with vertices on
//!   the curve and the end points exact.
//! - Whole `circle`s and `ellipse`s have no end points to keep, so their vertices sit slightly
//!   outside the curve and each chord dips the same distance inside: the deviation stays within
//!   the tolerance with fewer points, and the enclosed area is nearly exact (relative error
//!   about `(tol/r)²`, where an inscribed polygon loses `4·tol/(3r)`).
//!
//! Closed paths do not repeat their first point at the end; consecutive duplicate points are
//! removed, and subpaths with fewer than two distinct points are dropped.
//!
//! # Example
//!
//! ```
//! let svg = br#"<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="50mm" viewBox="0 0 200 100">
//!   <g transform="translate(10,10)"><rect id="r" width="20" height="10"/></g>
//!   <circle cx="100" cy="50" r="20"/>
//! </svg>"#;
//! let design = conduit_svg::read(svg, 0.01)?;
//! assert_eq!(design.width_mm, Some(100.0));
//! let rect = &design.paths[0];
//! assert_eq!(rect.id.as_deref(), Some("r"));
//! assert!(rect.closed);
//! // Top-left corner in SVG (10,10) user units = (5, 45) mm with y up.
//! assert_eq!(rect.points[0], [5.0, 45.0]);
//! # Ok::<(), conduit_svg::SvgError>(())
//! ```

mod error;
mod flatten;
mod reader;

pub use error::{AttributeError, SvgError};

/// Millimetres per CSS pixel (1/96 inch): the size of one user unit without a `viewBox`.
pub const MM_PER_PX: f64 = 25.4 / 96.0;

/// Smallest flattening tolerance accepted, in millimetres (1 nm, conduit's integer grid).
pub const MIN_TOLERANCE_MM: f64 = 1e-6;

/// Most points a document may flatten to; beyond it [`read`] fails with
/// [`SvgError::TooManyPoints`] instead of exhausting memory.
pub const MAX_POINTS: usize = 10_000_000;

/// Deepest element nesting accepted; keeps recursion on hostile input off the stack limit.
pub const MAX_DEPTH: usize = 256;

/// Deepest chain of `<use>` references followed (a `use` that reaches itself is a cycle).
pub const MAX_USE_DEPTH: usize = 32;

/// One polyline of a design: a subpath of an SVG shape, in millimetres, y up.
#[derive(Debug, Clone, PartialEq)]
pub struct DesignPath {
    /// The `id` of the SVG element it came from (shared by all subpaths of that element).
    pub id: Option<String>,
    /// Vertices in millimetres, y up. A closed path does not repeat its first point.
    pub points: Vec<[f64; 2]>,
    /// Whether the path closes back to its first point (`Z`, `polygon`, `rect`, `circle`,
    /// `ellipse`).
    pub closed: bool,
}

/// A 2D design read from SVG: its page size and its paths in document order.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Design {
    /// Page width in millimetres, when the root gives `width` or a `viewBox`.
    pub width_mm: Option<f64>,
    /// Page height in millimetres, when the root gives `height` or a `viewBox`. The y axis is
    /// flipped within this height.
    pub height_mm: Option<f64>,
    /// The paths, in document order.
    pub paths: Vec<DesignPath>,
}

/// Reads an SVG document into polylines in millimetres (y up), flattening curves so that no
/// point of a curve is farther than `tolerance_mm` from its polyline.
///
/// Errors: a tolerance that is not finite or below [`MIN_TOLERANCE_MM`], text that is not UTF-8,
/// malformed XML, a root that is not `<svg>`, and malformed attributes (path data, transforms,
/// lengths, `viewBox`, `points`), reported with the element, its `id`, byte offset and line.
pub fn read(bytes: &[u8], tolerance_mm: f64) -> Result<Design, SvgError> {
    if !(tolerance_mm.is_finite() && tolerance_mm >= MIN_TOLERANCE_MM) {
        return Err(SvgError::InvalidTolerance { tolerance_mm });
    }
    let root = parse(bytes)?;
    reader::read(bytes, &root, tolerance_mm)
}

/// How SVG files are parsed: names without their namespace prefix (`svg:path` is `path`),
/// attribute values that do not decode kept as written (Illustrator's `&ns_svg;`), and an
/// element's attributes read before the depth limit is checked.
const XML_OPTIONS: conduit_xml::Options = conduit_xml::Options {
    names: conduit_xml::Names::Local,
    entities: conduit_xml::Entities::KeepRaw,
    depth_check: conduit_xml::DepthCheck::AfterAttributes,
    max_depth: MAX_DEPTH,
};

/// Parses `bytes` (UTF-8, optional BOM) into its root element, which must be `<svg>`.
fn parse(bytes: &[u8]) -> Result<conduit_xml::Node, SvgError> {
    let root = conduit_xml::parse(bytes, &XML_OPTIONS)
        .map_err(|e| SvgError::from_xml(bytes, e))?
        .ok_or(SvgError::NotSvg {
            root: String::new(),
        })?;
    if root.name != "svg" {
        return Err(SvgError::NotSvg { root: root.name });
    }
    Ok(root)
}

#[cfg(test)]
mod tests;
