//! Wavefront OBJ reader (via tobj) and writer.
//!
//! Part of conduit's `formats/` layer: it describes the file and has no dependency on the pipeline.
//!
//! # Reading ([`read()`])
//!
//! Polygonal geometry only: `v` positions and `f` faces, grouped by `o` and `g` statements into
//! [`ObjObject`]s, each with its own vertex list (the vertices its faces use, in order of first
//! use) and 0-based triangles. Supported:
//!
//! * absolute and negative (relative) face indices, `v/vt/vn` index triples (only `v` is used),
//!   faces referring forward to vertices defined later in the file;
//! * polygons of any size, fan-triangulated (`v0 vi vi+1`, exact for convex polygons);
//! * `#` comments (whole lines, and inline from a `#` at the start of a word), blank lines,
//!   `\r\n` line ends,
//!   backslash line continuation, non-UTF-8 bytes in comments and names;
//! * `mtllib` material libraries, looked up in `base_dir` through tobj's loader so that a missing
//!   or broken `.mtl` only adds a warning. Materials are not part of the result: conduit assigns
//!   tools per object.
//!
//! Ignored, with a warning: faces with fewer than three vertices, line (`l`) and point (`p`)
//! elements, free-form curves and surfaces, unknown statements. Objects and groups without faces
//! are dropped, so a file with no faces reads as zero objects. `vt`, `vn`, `s`, `usemtl` and
//! material statements embedded in the OBJ are ignored silently; so are the `w` coordinate of
//! `v` and vertex colours.
//!
//! Errors carry the 1-based line: a coordinate or index that is not a number, a zero index, or a
//! face referring to a vertex that does not exist.
//!
//! tobj does the grouping, re-indexing, triangulation and `.mtl` parsing. It reports no line
//! numbers and can overflow on hostile indices, so every line is first validated and rewritten
//! into a minimal canonical form (`v x y z`, `f` with absolute indices, `o`/`g`, `mtllib`) that
//! tobj is then guaranteed to accept. Coordinates are passed through as written and parsed as
//! `f64` (tobj's `use_f64` feature), so no precision is lost.
//!
//! # Writing ([`write()`])
//!
//! `o NAME`, `v x y z` and `f a b c` with 1-based indices that are global across the file.
//! Coordinates are written in Rust's shortest round-trip form, so [`read`] gives back every
//! coordinate bit for bit.
//!
//! ```
//! let obj = conduit_obj::read(b"o quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n", None)?;
//! assert_eq!(obj.objects[0].name, "quad");
//! assert_eq!(obj.objects[0].triangles, vec![[0, 1, 2], [0, 2, 3]]);
//! let mut out = Vec::new();
//! conduit_obj::write(&mut out, &obj.objects)?;
//! assert_eq!(conduit_obj::read(&out, None)?.objects, obj.objects);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod read;
mod write;

pub use read::{looks_like_obj, read};
pub use write::write;

/// One object or group of an OBJ file, as an indexed triangle mesh.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ObjObject {
    /// Name from the `o` or `g` statement (trimmed, inline comment removed); empty for faces
    /// before any such statement or after one without a name.
    pub name: String,
    /// Vertex positions in file units: the vertices the faces use, in order of first use.
    pub vertices: Vec<[f64; 3]>,
    /// Triangles as 0-based indices into [`ObjObject::vertices`].
    pub triangles: Vec<[u32; 3]>,
}

/// The geometry of an OBJ file.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Obj {
    /// Objects and groups with at least one face, in file order.
    pub objects: Vec<ObjObject>,
    /// Things that were ignored or could not be loaded (missing `.mtl`, line elements, ...),
    /// each naming its line where it has one.
    pub warnings: Vec<String>,
}

/// Why an OBJ file could not be read. Lines are 1-based.
///
/// How to fix: these are problems of the file; repair the named line or re-export the model.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ObjError {
    /// A `v` statement with fewer than three coordinates.
    #[error("line {line}: vertex needs 3 coordinates, found {found}")]
    TooFewCoordinates {
        /// The line.
        line: usize,
        /// How many coordinates it has.
        found: usize,
    },
    /// A vertex coordinate that is not a finite number.
    #[error("line {line}: `{token}` is not a valid coordinate")]
    InvalidNumber {
        /// The line.
        line: usize,
        /// The coordinate as written.
        token: String,
    },
    /// A face vertex whose position index is missing, zero or not an integer.
    #[error("line {line}: `{token}` is not a valid face vertex index")]
    InvalidIndex {
        /// The line.
        line: usize,
        /// The face vertex as written (`v`, `v/vt`, `v//vn` or `v/vt/vn`).
        token: String,
    },
    /// A face refers to a vertex that does not exist.
    #[error("line {line}: face refers to vertex {index}, but {available} vertices are defined")]
    IndexOutOfRange {
        /// The line.
        line: usize,
        /// The index as written (1-based, or negative for relative).
        index: i64,
        /// Vertices available: those before the face for a negative index, all for a positive.
        available: usize,
    },
    /// The file has more vertices than 32-bit indices can address.
    #[error("more than 4294967296 vertices")]
    TooManyVertices,
    /// tobj rejected input that the validation accepted: a bug in this crate, please report it
    /// with the file.
    #[error("internal error: tobj rejected validated OBJ data ({0}); please report this")]
    Internal(String),
}

#[cfg(test)]
mod tests;
