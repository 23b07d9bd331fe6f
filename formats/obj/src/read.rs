//! OBJ reading: a validating pre-pass with line numbers, then tobj on the canonical text.

use std::cell::RefCell;
use std::fmt::Write as _;
use std::path::Path;

use crate::{Obj, ObjError, ObjObject};

/// At most this many warnings are kept; the rest are counted in a last one.
const MAX_WARNINGS: usize = 50;

/// Statements that describe free-form geometry, which is not read.
const FREE_FORM: &[&str] = &[
    "cstype", "deg", "bmat", "step", "curv", "curv2", "surf", "parm", "trim", "hole", "scrv", "sp",
    "end", "con",
];

/// Statements that carry nothing conduit uses; dropped without a warning.
const SILENT: &[&str] = &[
    "vt",
    "vn",
    "vp",
    "s",
    "usemtl",
    "mg",
    "lod",
    "bevel",
    "c_interp",
    "d_interp",
    "shadow_obj",
    "trace_obj",
    "ctech",
    "stech",
    "maplib",
    "usemap",
    "call",
    "csh",
];

/// OBJ statements, for sniffing.
const OBJ_KEYWORDS: &[&str] = &[
    "v", "vn", "vt", "vp", "f", "l", "p", "o", "g", "s", "mtllib", "usemtl",
];

/// Material statements, which some files embed in the OBJ itself; dropped without a warning.
fn is_mtl_keyword(keyword: &str) -> bool {
    const MTL: &[&str] = &[
        "newmtl",
        "Ka",
        "Kd",
        "Ks",
        "Ke",
        "Ns",
        "Ni",
        "d",
        "Tr",
        "Tf",
        "illum",
        "bump",
        "disp",
        "decal",
        "refl",
        "norm",
        "Pr",
        "Pm",
        "Ps",
        "Pc",
        "Pcr",
        "aniso",
        "anisor",
        "sharpness",
    ];
    MTL.contains(&keyword) || keyword.starts_with("map_")
}

#[derive(Default)]
struct Warnings {
    list: Vec<String>,
    dropped: usize,
}

impl Warnings {
    fn push(&mut self, message: String) {
        if self.list.len() < MAX_WARNINGS {
            self.list.push(message);
        } else {
            self.dropped += 1;
        }
    }

    fn finish(mut self) -> Vec<String> {
        if self.dropped > 0 {
            self.list
                .push(format!("{} more warnings not shown", self.dropped));
        }
        self.list
    }
}

/// The validated file, rewritten for tobj.
#[derive(Default)]
struct Canonical {
    /// All `v` lines first, so that forward references resolve for tobj too.
    vertices: String,
    /// `f`, `o`, `g` and `mtllib` lines in file order.
    body: String,
    /// Whether the file names a material library.
    has_mtllib: bool,
    /// The name of each model tobj will return, in order. tobj starts a model at every `o`/`g`
    /// that follows a face, and once more at the end; it names nameless ones `unnamed_object`,
    /// which the names here (empty instead) replace.
    names: Vec<String>,
}

/// Logical lines (backslash continuations joined) with the number of their first physical line.
///
/// Comment lines are never continued: a comment ending in a backslash (a Windows path, say) must
/// not swallow the statement after it.
fn logical_lines(bytes: &[u8]) -> impl Iterator<Item = (usize, String)> + '_ {
    let mut physical = bytes.split(|&b| b == b'\n').enumerate();
    std::iter::from_fn(move || {
        let (index, first) = physical.next()?;
        let mut line = String::from_utf8_lossy(first).into_owned();
        if line.trim_start().starts_with('#') {
            return Some((index + 1, line));
        }
        loop {
            let trimmed = line.trim_end();
            let Some(joined) = trimmed.strip_suffix('\\') else {
                break;
            };
            let joined_len = joined.len();
            line.truncate(joined_len);
            match physical.next() {
                Some((_, next)) => {
                    line.push(' ');
                    line.push_str(&String::from_utf8_lossy(next));
                }
                None => break,
            }
        }
        Some((index + 1, line))
    })
}

/// Removes an inline `#` comment (a `#` at the start or after whitespace).
fn strip_comment(line: &str) -> &str {
    let bytes = line.as_bytes();
    for (i, &b) in bytes.iter().enumerate() {
        if b == b'#' && (i == 0 || bytes[i - 1].is_ascii_whitespace()) {
            return &line[..i];
        }
    }
    line
}

/// `bytes` without a leading UTF-8 byte order mark.
fn strip_bom(bytes: &[u8]) -> &[u8] {
    bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes)
}

fn validate(bytes: &[u8], warnings: &mut Warnings) -> Result<Canonical, ObjError> {
    let mut v = Validator::default();
    for (line_no, line) in logical_lines(bytes) {
        let trimmed = line.trim_start();
        let Some(keyword) = trimmed.split_whitespace().next() else {
            continue;
        };
        if keyword.starts_with('#') {
            continue;
        }
        let rest = strip_comment(&trimmed[keyword.len()..]).trim();
        v.statement(line_no, keyword, rest, warnings)?;
    }
    v.finish(warnings)
}

/// The validating pre-pass's state: the canonical text written so far and what it has seen.
#[derive(Default)]
struct Validator {
    out: Canonical,
    /// Name of the current `o`/`g` model.
    name: String,
    faces_in_model: usize,
    vertex_count: usize,
    /// (line, 1-based index) of faces that refer to vertices defined later in the file.
    forward: Vec<(usize, i64)>,
    /// The absolute vertex indices of the face being read.
    face: Vec<i64>,
    skipped_elements: usize,
    first_skipped_element: usize,
    /// Line of the first free-form statement.
    free_form: Option<usize>,
    /// Unknown keywords warned about (at most ten).
    unknown: Vec<String>,
}

impl Validator {
    /// Checks and rewrites one statement (`keyword` with the text `rest` after it).
    fn statement(
        &mut self,
        line_no: usize,
        keyword: &str,
        rest: &str,
        warnings: &mut Warnings,
    ) -> Result<(), ObjError> {
        match keyword {
            "v" => self.vertex(line_no, rest)?,
            "f" | "fo" => self.face(line_no, rest, warnings)?,
            "o" | "g" => {
                if self.faces_in_model > 0 {
                    self.out.names.push(std::mem::take(&mut self.name));
                    self.faces_in_model = 0;
                }
                self.name = rest.to_owned();
                let _ = writeln!(self.out.body, "{keyword} {rest}");
            }
            "mtllib" => {
                self.out.has_mtllib = true;
                let _ = writeln!(self.out.body, "mtllib {rest}");
            }
            "l" | "p" => {
                if self.skipped_elements == 0 {
                    self.first_skipped_element = line_no;
                }
                self.skipped_elements += 1;
            }
            k if SILENT.contains(&k) || is_mtl_keyword(k) => {}
            k if FREE_FORM.contains(&k) => {
                self.free_form.get_or_insert(line_no);
            }
            k => {
                if self.unknown.len() < 10 && !self.unknown.iter().any(|u| u == k) {
                    self.unknown.push(k.to_owned());
                    warnings.push(format!("line {line_no}: unknown statement `{k}` ignored"));
                }
            }
        }
        Ok(())
    }

    /// A `v` statement: three finite coordinates, passed on as written.
    fn vertex(&mut self, line_no: usize, rest: &str) -> Result<(), ObjError> {
        let mut coords = rest.split_whitespace();
        self.out.vertices.push('v');
        for found in 0..3 {
            let Some(token) = coords.next() else {
                return Err(ObjError::TooFewCoordinates {
                    line: line_no,
                    found,
                });
            };
            if !token.parse::<f64>().is_ok_and(f64::is_finite) {
                return Err(ObjError::InvalidNumber {
                    line: line_no,
                    token: token.to_owned(),
                });
            }
            // Passed on as written: tobj parses the same text with the same `f64`
            // parser, so the value is exact.
            self.out.vertices.push(' ');
            self.out.vertices.push_str(token);
        }
        self.out.vertices.push('\n');
        self.vertex_count += 1;
        Ok(())
    }

    /// An `f` statement: its vertex indices made absolute (forward references are checked at
    /// the end); a face of fewer than three vertices is dropped with a warning.
    fn face(
        &mut self,
        line_no: usize,
        rest: &str,
        warnings: &mut Warnings,
    ) -> Result<(), ObjError> {
        self.face.clear();
        for token in rest.split_whitespace() {
            let absolute = self.face_index(line_no, token)?;
            self.face.push(absolute);
        }
        if self.face.len() < 3 {
            warnings.push(format!(
                "line {line_no}: face with {} vertices ignored",
                self.face.len()
            ));
            return Ok(());
        }
        self.out.body.push('f');
        for index in &self.face {
            let _ = write!(self.out.body, " {index}");
        }
        self.out.body.push('\n');
        self.faces_in_model += 1;
        Ok(())
    }

    /// The absolute 1-based vertex index of one face vertex `token` (`v`, `v/vt`, `v//vn` or
    /// `v/vt/vn`; negative indices count back from the last vertex read).
    fn face_index(&mut self, line_no: usize, token: &str) -> Result<i64, ObjError> {
        let position = token.split('/').next().unwrap_or_default();
        let index = match position.parse::<i64>() {
            Ok(index) if index != 0 => index,
            _ => {
                return Err(ObjError::InvalidIndex {
                    line: line_no,
                    token: token.to_owned(),
                });
            }
        };
        if index < 0 {
            let resolved = i64::try_from(self.vertex_count)
                .ok()
                .and_then(|count| count.checked_add(index))
                .filter(|&r| r >= 0);
            let Some(resolved) = resolved else {
                return Err(ObjError::IndexOutOfRange {
                    line: line_no,
                    index,
                    available: self.vertex_count,
                });
            };
            Ok(resolved + 1)
        } else {
            if usize::try_from(index).map_or(true, |i| i > self.vertex_count) {
                self.forward.push((line_no, index));
            }
            Ok(index)
        }
    }

    /// Checks the forward references and the vertex count once all vertices are known, and
    /// adds the summary warnings.
    fn finish(mut self, warnings: &mut Warnings) -> Result<Canonical, ObjError> {
        let vertex_count = self.vertex_count;
        self.out.names.push(self.name);
        if let Some(&(line, index)) = self
            .forward
            .iter()
            .find(|&&(_, index)| usize::try_from(index).map_or(true, |i| i > vertex_count))
        {
            return Err(ObjError::IndexOutOfRange {
                line,
                index,
                available: vertex_count,
            });
        }
        if u32::try_from(vertex_count.saturating_sub(1)).is_err() {
            return Err(ObjError::TooManyVertices);
        }
        if self.skipped_elements > 0 {
            warnings.push(format!(
                "{} line/point elements (`l`, `p`) ignored, the first on line {}",
                self.skipped_elements, self.first_skipped_element
            ));
        }
        if let Some(line) = self.free_form {
            warnings.push(format!(
                "line {line}: free-form curves and surfaces are not supported and were ignored"
            ));
        }
        Ok(self.out)
    }
}

/// Rewrites an MTL file so that tobj cannot panic on it: tobj unwraps the parse of a colour
/// statement (`Kd r g b`) with fewer than three numbers. A single number stands for grey, as the
/// MTL format defines; other short colours (and `spectral`/`xyz` forms) are dropped.
fn sanitize_mtl(bytes: &[u8]) -> String {
    let text = String::from_utf8_lossy(bytes);
    let mut out = String::with_capacity(text.len());
    for line in text.lines() {
        let mut words = line.split_whitespace();
        if let Some(keyword @ ("Ka" | "Kd" | "Ks" | "Ke")) = words.next() {
            let values: Vec<&str> = words.collect();
            let numeric = values.iter().all(|v| v.parse::<f64>().is_ok());
            match values.as_slice() {
                [grey] if numeric => {
                    let _ = writeln!(out, "{keyword} {grey} {grey} {grey}");
                }
                [_, _, _, ..] if numeric => {
                    out.push_str(line);
                    out.push('\n');
                }
                _ => {}
            }
            continue;
        }
        out.push_str(line);
        out.push('\n');
    }
    out
}

/// Loads the material libraries named by one `mtllib` statement from `base_dir`.
///
/// The statement's argument is tried first as one file name (names may contain spaces), then as
/// a whitespace-separated list. Failures become warnings; the result is always `Ok`, so tobj
/// never fails on materials.
fn load_materials(base_dir: &Path, named: &Path, warnings: &mut Warnings) -> tobj::MTLLoadResult {
    Ok(collect_materials(base_dir, named, warnings))
}

/// [`load_materials`], generic over the map so that tobj's hasher choice needs no naming.
fn collect_materials<M>(
    base_dir: &Path,
    named: &Path,
    warnings: &mut Warnings,
) -> (Vec<tobj::Material>, M)
where
    M: Default + Extend<(String, usize)>,
{
    let mut materials = Vec::new();
    let mut by_name = M::default();
    let whole = named.to_string_lossy();
    let files: Vec<&str> = if base_dir.join(named).is_file() {
        vec![whole.as_ref()]
    } else {
        whole.split_whitespace().collect()
    };
    for file in files {
        let path = base_dir.join(file);
        let loaded = match std::fs::read(&path) {
            Ok(bytes) => tobj::load_mtl_buf(&mut sanitize_mtl(&bytes).as_bytes()),
            Err(_) => Err(tobj::LoadError::OpenFileFailed),
        };
        match loaded {
            Ok((loaded, map)) => {
                let offset = materials.len();
                materials.extend(loaded);
                by_name.extend(map.into_iter().map(|(name, i)| (name, i + offset)));
            }
            Err(error) => warnings.push(format!(
                "material library `{file}` could not be loaded from `{}` ({error}); materials \
                 ignored",
                base_dir.display()
            )),
        }
    }
    (materials, by_name)
}

/// Reads an OBJ file. See the [crate documentation](crate) for what is supported.
///
/// `base_dir` is where `mtllib` files are looked up; `None` means materials are not loaded (one
/// warning says so if the file names a library).
///
/// # Errors
///
/// [`ObjError`] naming the line for a malformed vertex, an invalid face index or a face referring
/// to a vertex that does not exist.
pub fn read(bytes: &[u8], base_dir: Option<&Path>) -> Result<Obj, ObjError> {
    let mut warnings = Warnings::default();
    let canonical = validate(strip_bom(bytes), &mut warnings)?;
    if canonical.has_mtllib && base_dir.is_none() {
        warnings.push("the file names material libraries, which were not loaded".to_owned());
    }
    let canonical_names = canonical.names;
    let mut text = canonical.vertices;
    text.push_str(&canonical.body);

    // `..Default::default()` is needed when another crate enables tobj's `merging` or
    // `reordering` features, which add fields.
    #[allow(clippy::needless_update)]
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
        ..Default::default()
    };
    let warnings = RefCell::new(warnings);
    let load = || {
        tobj::load_obj_buf(&mut text.as_bytes(), &options, |named| match base_dir {
            Some(dir) => load_materials(dir, named, &mut warnings.borrow_mut()),
            None => Ok(Default::default()),
        })
    };
    // The input is validated so that tobj accepts it; should tobj still panic, the caller gets
    // an error instead of a crash (with `panic = "abort"` this guard does nothing).
    let loaded = std::panic::catch_unwind(std::panic::AssertUnwindSafe(load))
        .map_err(|_| ObjError::Internal("tobj panicked".to_owned()))?;
    let (models, _materials) = loaded.map_err(|e| ObjError::Internal(e.to_string()))?;

    debug_assert_eq!(models.len(), canonical_names.len(), "tobj model count");
    // Fall back to tobj's names should the counts ever disagree.
    let own_names = if models.len() == canonical_names.len() {
        canonical_names
    } else {
        Vec::new()
    };
    let mut own_names = own_names.into_iter();
    let mut objects = Vec::with_capacity(models.len());
    for model in models {
        let name = own_names.next().unwrap_or(model.name);
        let mesh = model.mesh;
        if mesh.indices.is_empty() {
            continue;
        }
        let vertices = mesh
            .positions
            .chunks_exact(3)
            .map(|p| [p[0], p[1], p[2]])
            .collect();
        let triangles = mesh
            .indices
            .chunks_exact(3)
            .map(|t| [t[0], t[1], t[2]])
            .collect();
        objects.push(ObjObject {
            name,
            vertices,
            triangles,
        });
    }
    Ok(Obj {
        objects,
        warnings: warnings.into_inner().finish(),
    })
}

/// Whether `bytes` look like an OBJ file, for files without a telling extension.
///
/// True when the file is text, its first statements (not comments or blank lines) all start with
/// an OBJ keyword (`v`, `vn`, `vt`, `f`, `o`, `g`, `mtllib`, `usemtl`, `s`, ...) or a material
/// keyword (some files embed their materials), and at least one is an OBJ keyword. Up to 8 OBJ
/// statements (and at most 64 statements) are looked at. STL (`solid`), PLY (`ply`), OFF
/// (`OFF`), 3MF (zip), G-code (`G1`, `;`), `.mtl` files and binary data give false.
pub fn looks_like_obj(bytes: &[u8]) -> bool {
    let bytes = strip_bom(bytes);
    let head = &bytes[..bytes.len().min(64 * 1024)];
    if head.contains(&0) {
        return false;
    }
    // The last line of the window may be cut: only whole lines are judged.
    let whole = if head.len() < bytes.len() {
        &head[..head.iter().rposition(|&b| b == b'\n').unwrap_or(0)]
    } else {
        head
    };
    let (mut obj_statements, mut statements) = (0, 0);
    for line in whole.split(|&b| b == b'\n') {
        let line = String::from_utf8_lossy(line);
        let Some(keyword) = line.split_whitespace().next() else {
            continue;
        };
        if keyword.starts_with('#') {
            continue;
        }
        if OBJ_KEYWORDS.contains(&keyword) {
            obj_statements += 1;
        } else if !is_mtl_keyword(keyword) {
            return false;
        }
        statements += 1;
        if obj_statements == 8 || statements == 64 {
            break;
        }
    }
    obj_statements > 0
}
