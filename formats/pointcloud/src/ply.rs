//! PLY (Stanford polygon file format) reader: ASCII, binary little-endian and binary big-endian.
//!
//! A small hand-written parser (ply-rs is unmaintained). The header is parsed first; the body
//! is then walked element by element, so unknown elements and properties, including lists, are
//! skipped by their declared types. Every read is bounds-checked and no buffer is sized from a
//! count that the file length does not confirm.
//!
//! ASCII bodies are read one record per line: values after the declared properties are ignored
//! (VCGLIB writes some), and `comment` lines between records are skipped, as other readers do.
//! Type names may be the classic (`float`, `uchar`, ...) or the sized ones (`float32`,
//! `uint8`, ...). Header lines may end in `\r\n`.

use crate::PointCloud;

/// Where in the file a body error was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Location {
    /// 1-based line number (ASCII body and header).
    Line(usize),
    /// Byte offset from the start of the file (binary body).
    Offset(usize),
}

impl std::fmt::Display for Location {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Location::Line(line) => write!(f, "line {line}"),
            Location::Offset(offset) => write!(f, "byte offset {offset}"),
        }
    }
}

/// Why a PLY file could not be read.
///
/// How to fix: these describe problems of the file; re-export it (MeshLab, CloudCompare and
/// Blender write valid PLY) or repair the named header line, element or record.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PlyError {
    /// The file does not start with the `ply` magic line.
    #[error("not a PLY file: missing `ply` on the first line")]
    NotPly,
    /// The header has no `format` line.
    #[error("PLY header has no `format` line")]
    MissingFormat,
    /// The header never ends.
    #[error("PLY header has no `end_header` line")]
    MissingEndHeader,
    /// An unknown format, e.g. `binary_middle_endian`.
    #[error("line {line}: unsupported PLY format `{format}`")]
    UnsupportedFormat {
        /// Header line.
        line: usize,
        /// The format named.
        format: String,
    },
    /// A property of an unknown scalar type.
    #[error("line {line}: unknown PLY property type `{type_name}`")]
    UnknownType {
        /// Header line.
        line: usize,
        /// The type named.
        type_name: String,
    },
    /// A header line that is not `format`, `comment`, `obj_info`, `element`, `property` or
    /// `end_header`, or one of those with the wrong number of words.
    #[error("line {line}: invalid PLY header line `{text}`")]
    InvalidHeaderLine {
        /// Header line.
        line: usize,
        /// Its text.
        text: String,
    },
    /// The file has no `vertex` element.
    #[error("PLY file has no `vertex` element")]
    NoVertexElement,
    /// A required property is not declared.
    #[error("PLY element `{element}` has no `{property}` property")]
    MissingProperty {
        /// The element.
        element: String,
        /// The missing property.
        property: &'static str,
    },
    /// More vertices than 32-bit indices can address.
    #[error("{count} vertices declared; at most 4294967296 are supported")]
    TooManyVertices {
        /// Declared vertex count.
        count: usize,
    },
    /// The body ends before every declared element record has been read.
    #[error(
        "file truncated in element `{element}`, record {record} of {count} (property `{property}`)"
    )]
    Truncated {
        /// Element being read.
        element: String,
        /// 0-based record index.
        record: usize,
        /// Declared record count.
        count: usize,
        /// Property being read.
        property: String,
    },
    /// An ASCII record line that ends before all properties are read.
    #[error("{location}: record {record} of element `{element}` ends before property `{property}`")]
    ShortRecord {
        /// Where.
        location: Location,
        /// Element being read.
        element: String,
        /// 0-based record index.
        record: usize,
        /// Property that is missing.
        property: String,
    },
    /// An ASCII value that is not a number, or a coordinate that is not finite.
    #[error("{location}: invalid value `{token}` for property `{property}` of element `{element}`")]
    InvalidValue {
        /// Where.
        location: Location,
        /// Element being read.
        element: String,
        /// Property being read.
        property: String,
        /// The value as found.
        token: String,
    },
    /// A list length that is negative or not an integer.
    #[error("{location}: invalid list length {value} for property `{property}`")]
    InvalidListLength {
        /// Where.
        location: Location,
        /// Property being read.
        property: String,
        /// The length as read.
        value: f64,
    },
    /// A face refers to a vertex that does not exist.
    #[error("{location}: face {face} refers to vertex {index}, but the file has {vertex_count}")]
    IndexOutOfRange {
        /// Where.
        location: Location,
        /// 0-based face record.
        face: usize,
        /// The index as read.
        index: f64,
        /// Declared vertex count.
        vertex_count: usize,
    },
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(name: &str) -> Option<Scalar> {
        Some(match name {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Scalar(Scalar),
    List { len: Scalar, item: Scalar },
}

#[derive(Debug, Clone)]
struct Property {
    name: String,
    kind: Kind,
}

#[derive(Debug, Clone)]
struct Element {
    name: String,
    count: usize,
    properties: Vec<Property>,
}

impl Element {
    /// Smallest number of body bytes one record can take, to bound preallocation.
    fn min_record_bytes(&self, format: Format) -> usize {
        let sum: usize = self
            .properties
            .iter()
            .map(|p| match (format, p.kind) {
                (Format::Ascii, _) => 2,
                (_, Kind::Scalar(s)) => s.size(),
                (_, Kind::List { len, .. }) => len.size(),
            })
            .sum();
        sum.max(1)
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Format {
    Ascii,
    BinaryLe,
    BinaryBe,
}

struct Header {
    format: Format,
    elements: Vec<Element>,
    /// Byte offset of the body.
    body_offset: usize,
    /// 1-based line number of the first body line.
    body_line: usize,
}

fn parse_header(bytes: &[u8]) -> Result<Header, PlyError> {
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    let mut offset = 0;
    let mut line_no = 0;
    while offset < bytes.len() {
        let end = bytes[offset..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(bytes.len(), |p| offset + p);
        let raw = &bytes[offset..end];
        offset = (end + 1).min(bytes.len());
        line_no += 1;
        let text = String::from_utf8_lossy(raw);
        let mut words = text.split_whitespace();
        let invalid = || PlyError::InvalidHeaderLine {
            line: line_no,
            text: text.trim().to_owned(),
        };
        if line_no == 1 {
            if text.trim() != "ply" {
                return Err(PlyError::NotPly);
            }
            continue;
        }
        match words.next() {
            None | Some("comment" | "obj_info") => {}
            Some("format") => {
                let name = words.next().ok_or_else(invalid)?;
                format = Some(match name {
                    "ascii" => Format::Ascii,
                    "binary_little_endian" => Format::BinaryLe,
                    "binary_big_endian" => Format::BinaryBe,
                    _ => {
                        return Err(PlyError::UnsupportedFormat {
                            line: line_no,
                            format: name.to_owned(),
                        });
                    }
                });
            }
            Some("element") => {
                let (Some(name), Some(count), None) = (words.next(), words.next(), words.next())
                else {
                    return Err(invalid());
                };
                elements.push(Element {
                    name: name.to_owned(),
                    count: count.parse().map_err(|_| invalid())?,
                    properties: Vec::new(),
                });
            }
            Some("property") => {
                let element = elements.last_mut().ok_or_else(invalid)?;
                let scalar = |name: &str| {
                    Scalar::parse(name).ok_or_else(|| PlyError::UnknownType {
                        line: line_no,
                        type_name: name.to_owned(),
                    })
                };
                let property = match (words.next(), words.next(), words.next(), words.next()) {
                    (Some("list"), Some(len), Some(item), Some(name)) => Property {
                        name: name.to_owned(),
                        kind: Kind::List {
                            len: scalar(len)?,
                            item: scalar(item)?,
                        },
                    },
                    (Some(ty), Some(name), None, None) if ty != "list" => Property {
                        name: name.to_owned(),
                        kind: Kind::Scalar(scalar(ty)?),
                    },
                    _ => return Err(invalid()),
                };
                element.properties.push(property);
            }
            Some("end_header") => {
                return Ok(Header {
                    format: format.ok_or(PlyError::MissingFormat)?,
                    elements,
                    body_offset: offset,
                    body_line: line_no + 1,
                });
            }
            Some(_) => return Err(invalid()),
        }
    }
    if line_no == 0 {
        return Err(PlyError::NotPly);
    }
    Err(PlyError::MissingEndHeader)
}

/// A failed read of one value from the body.
enum Fail {
    /// End of data.
    Eof,
    /// End of an ASCII line in the middle of a record.
    EndOfLine,
    /// An ASCII token that is not a number.
    Invalid(String),
}

/// A source of typed values: the ASCII lines or a binary cursor.
trait Body {
    /// Moves to the start of the next record (the next line, for ASCII).
    fn begin_record(&mut self) {}
    /// Reads one value of type `ty`.
    fn value(&mut self, ty: Scalar) -> Result<f64, Fail>;
    /// Skips `n` values of type `ty`.
    fn skip(&mut self, ty: Scalar, n: usize) -> Result<(), Fail>;
    /// Where the last value read (or attempted) starts.
    fn location(&self) -> Location;
}

struct Ascii<'a> {
    bytes: &'a [u8],
    pos: usize,
    /// Line of `pos`.
    line: usize,
    /// Line of the last token read, for error locations.
    token_line: usize,
    /// No token has been read yet on the current line.
    line_start: bool,
}

impl Ascii<'_> {
    /// Skips whitespace and, as some writers put them in the body, `comment` lines.
    fn skip_blank(&mut self) {
        loop {
            while let Some(&b) = self.bytes.get(self.pos) {
                if !b.is_ascii_whitespace() {
                    break;
                }
                if b == b'\n' {
                    self.line += 1;
                    self.line_start = true;
                }
                self.pos += 1;
            }
            let rest = &self.bytes[self.pos..];
            let is_comment =
                rest.starts_with(b"comment") && rest.get(7).is_none_or(|b| b.is_ascii_whitespace());
            if !(self.line_start && is_comment) {
                return;
            }
            self.pos += rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
        }
    }
}

impl Body for Ascii<'_> {
    fn begin_record(&mut self) {
        if !self.line_start {
            // The rest of the previous record's line is ignored: some writers (VCGLIB) put
            // more values on a line than the header declares.
            let rest = &self.bytes[self.pos..];
            self.pos += rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
        }
        self.skip_blank();
    }

    fn value(&mut self, _ty: Scalar) -> Result<f64, Fail> {
        while self
            .bytes
            .get(self.pos)
            .is_some_and(|&b| b != b'\n' && b.is_ascii_whitespace())
        {
            self.pos += 1;
        }
        self.token_line = self.line;
        match self.bytes.get(self.pos) {
            None => return Err(Fail::Eof),
            Some(b'\n') => return Err(Fail::EndOfLine),
            Some(_) => {}
        }
        self.line_start = false;
        let start = self.pos;
        while self
            .bytes
            .get(self.pos)
            .is_some_and(|b| !b.is_ascii_whitespace())
        {
            self.pos += 1;
        }
        let token = &self.bytes[start..self.pos];
        let text = String::from_utf8_lossy(token);
        text.parse::<f64>()
            .map_err(|_| Fail::Invalid(text.into_owned()))
    }

    fn skip(&mut self, ty: Scalar, n: usize) -> Result<(), Fail> {
        // Bounded by the tokens present: stops at the end of the data.
        for _ in 0..n {
            self.value(ty)?;
        }
        Ok(())
    }

    fn location(&self) -> Location {
        Location::Line(self.token_line)
    }
}

struct Binary<'a> {
    bytes: &'a [u8],
    pos: usize,
    /// Start of the last value read, for error locations.
    last: usize,
    /// Offset of `bytes` in the file, for error locations.
    base: usize,
    big_endian: bool,
}

impl Binary<'_> {
    fn take<const N: usize>(&mut self) -> Result<[u8; N], Fail> {
        let slice = self.bytes.get(self.pos..self.pos + N).ok_or(Fail::Eof)?;
        self.last = self.pos;
        self.pos += N;
        let mut out = [0; N];
        out.copy_from_slice(slice);
        if self.big_endian {
            out.reverse();
        }
        Ok(out)
    }
}

impl Body for Binary<'_> {
    fn value(&mut self, ty: Scalar) -> Result<f64, Fail> {
        // Bytes are put in little-endian order by `take`.
        Ok(match ty {
            Scalar::I8 => f64::from(i8::from_le_bytes(self.take()?)),
            Scalar::U8 => f64::from(u8::from_le_bytes(self.take()?)),
            Scalar::I16 => f64::from(i16::from_le_bytes(self.take()?)),
            Scalar::U16 => f64::from(u16::from_le_bytes(self.take()?)),
            Scalar::I32 => f64::from(i32::from_le_bytes(self.take()?)),
            Scalar::U32 => f64::from(u32::from_le_bytes(self.take()?)),
            Scalar::F32 => f64::from(f32::from_le_bytes(self.take()?)),
            Scalar::F64 => f64::from_le_bytes(self.take()?),
        })
    }

    fn skip(&mut self, ty: Scalar, n: usize) -> Result<(), Fail> {
        let len = n.checked_mul(ty.size()).ok_or(Fail::Eof)?;
        if self.bytes.len() - self.pos < len {
            self.pos = self.bytes.len();
            return Err(Fail::Eof);
        }
        self.pos += len;
        Ok(())
    }

    fn location(&self) -> Location {
        Location::Offset(self.base + self.last)
    }
}

/// What a vertex property means to us.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Role {
    Coord(usize),
    Normal(usize),
    Color(usize),
    Other,
}

fn vertex_role(name: &str) -> Role {
    match name {
        "x" => Role::Coord(0),
        "y" => Role::Coord(1),
        "z" => Role::Coord(2),
        "nx" => Role::Normal(0),
        "ny" => Role::Normal(1),
        "nz" => Role::Normal(2),
        "red" | "diffuse_red" => Role::Color(0),
        "green" | "diffuse_green" => Role::Color(1),
        "blue" | "diffuse_blue" => Role::Color(2),
        _ => Role::Other,
    }
}

/// Converts a colour channel to 0..=255: floating-point channels are taken as 0..1, 16-bit
/// channels are scaled down, everything else is clamped.
fn color_channel(value: f64, ty: Scalar) -> u8 {
    let scaled = match ty {
        Scalar::F32 | Scalar::F64 => value * 255.0,
        Scalar::U16 => value / 257.0,
        _ => value,
    };
    // `as` saturates and maps NaN to 0, which is the clamp we want.
    scaled.round().clamp(0.0, 255.0) as u8
}

/// Reads a PLY file (ASCII, binary little-endian or binary big-endian).
///
/// Reads element `vertex` (`x`, `y`, `z` of any numeric type; optional `nx`/`ny`/`nz` and
/// `red`/`green`/`blue`) and element `face` (list `vertex_indices` or `vertex_index` of any
/// count and index type; polygons fan-triangulated, faces with fewer than 3 vertices skipped).
/// Everything else is skipped. Normals and colours are `Some` only when all three components are
/// declared. Floating-point colour channels are taken as 0..1 and scaled to 0..=255.
///
/// # Errors
///
/// [`PlyError`] for a malformed or incomplete header, a missing `vertex` element or `x`/`y`/`z`
/// property, a truncated body (naming the element, record and property), an invalid ASCII value,
/// a non-finite coordinate, or a face index outside the vertex list.
pub fn read_ply(bytes: &[u8]) -> Result<PointCloud, PlyError> {
    let header = parse_header(bytes)?;
    let body = bytes.get(header.body_offset..).unwrap_or_default();
    match header.format {
        Format::Ascii => read_body(
            &header,
            body.len(),
            Ascii {
                bytes: body,
                pos: 0,
                line: header.body_line,
                token_line: header.body_line,
                line_start: true,
            },
        ),
        Format::BinaryLe | Format::BinaryBe => read_body(
            &header,
            body.len(),
            Binary {
                bytes: body,
                pos: 0,
                last: 0,
                base: header.body_offset,
                big_endian: header.format == Format::BinaryBe,
            },
        ),
    }
}

fn read_body(
    header: &Header,
    body_len: usize,
    mut body: impl Body,
) -> Result<PointCloud, PlyError> {
    let layout = Layout::of(header)?;
    let mut records = Records::new(layout);
    let mut vertex_done = false;
    for (element_index, element) in header.elements.iter().enumerate() {
        if element.properties.is_empty() {
            continue; // records of zero bytes: nothing to read, however large the count
        }
        let is_vertex = !vertex_done && element.name == "vertex";
        let is_face = records.layout.face_element == Some(element_index);
        if is_vertex {
            vertex_done = true;
            // The count is untrusted: reserve no more records than the body can hold.
            let cap = records
                .layout
                .vertex_count
                .min(body_len / element.min_record_bytes(header.format));
            records.reserve(cap);
        }
        for record in 0..element.count {
            records.read(&mut body, element, record, is_vertex, is_face)?;
        }
    }
    Ok(records.finish())
}

/// What the body reader takes from the header: what each vertex property means and where the
/// faces' vertex indices are.
struct Layout {
    /// The role of each property of the `vertex` element, by index.
    roles: Vec<Role>,
    has_normals: bool,
    has_colors: bool,
    vertex_count: usize,
    /// Index of the `face` element, if any.
    face_element: Option<usize>,
    /// Index of the face element's `vertex_indices` list property.
    face_list: Option<usize>,
}

impl Layout {
    /// Checks that the header declares a `vertex` element with `x`, `y` and `z`, no more
    /// vertices than `u32` indices reach, and a vertex index list on its `face` element.
    fn of(header: &Header) -> Result<Layout, PlyError> {
        let vertex = header
            .elements
            .iter()
            .find(|e| e.name == "vertex")
            .ok_or(PlyError::NoVertexElement)?;
        let roles: Vec<Role> = vertex
            .properties
            .iter()
            .map(|p| match p.kind {
                Kind::Scalar(_) => vertex_role(&p.name),
                Kind::List { .. } => Role::Other,
            })
            .collect();
        for (axis, name) in ["x", "y", "z"].into_iter().enumerate() {
            if !roles.contains(&Role::Coord(axis)) {
                return Err(PlyError::MissingProperty {
                    element: vertex.name.clone(),
                    property: name,
                });
            }
        }
        let has_all = |f: fn(usize) -> Role| (0..3).all(|i| roles.contains(&f(i)));
        let has_normals = has_all(Role::Normal);
        let has_colors = has_all(Role::Color);
        let vertex_count = vertex.count;
        if u32::try_from(vertex_count.saturating_sub(1)).is_err() {
            return Err(PlyError::TooManyVertices {
                count: vertex_count,
            });
        }
        let face_element = header.elements.iter().position(|e| e.name == "face");
        let face_list = match face_element.map(|i| &header.elements[i]) {
            Some(face) => Some(
                face.properties
                    .iter()
                    .position(|p| {
                        matches!(p.kind, Kind::List { .. })
                            && (p.name == "vertex_indices" || p.name == "vertex_index")
                    })
                    .ok_or_else(|| PlyError::MissingProperty {
                        element: face.name.clone(),
                        property: "vertex_indices",
                    })?,
            ),
            None => None,
        };
        Ok(Layout {
            roles,
            has_normals,
            has_colors,
            vertex_count,
            face_element,
            face_list,
        })
    }
}

/// The property being read, to name it in errors.
#[derive(Clone, Copy)]
struct At<'a> {
    element: &'a Element,
    record: usize,
    property: &'a Property,
}

impl At<'_> {
    /// The error for a failed read of this property at `location`.
    fn error(self, fail: Fail, location: Location) -> PlyError {
        match fail {
            Fail::Eof => PlyError::Truncated {
                element: self.element.name.clone(),
                record: self.record,
                count: self.element.count,
                property: self.property.name.clone(),
            },
            Fail::EndOfLine => PlyError::ShortRecord {
                location,
                element: self.element.name.clone(),
                record: self.record,
                property: self.property.name.clone(),
            },
            Fail::Invalid(token) => PlyError::InvalidValue {
                location,
                element: self.element.name.clone(),
                property: self.property.name.clone(),
                token,
            },
        }
    }
}

/// One vertex record's values.
#[derive(Default)]
struct Vertex {
    point: [f64; 3],
    normal: [f64; 3],
    color: [u8; 3],
}

/// The cloud read so far.
struct Records {
    layout: Layout,
    cloud: PointCloud,
    normals: Vec<[f64; 3]>,
    colors: Vec<[u8; 3]>,
    /// The vertex indices of the face being read.
    face: Vec<u32>,
}

impl Records {
    fn new(layout: Layout) -> Records {
        Records {
            layout,
            cloud: PointCloud::default(),
            normals: Vec::new(),
            colors: Vec::new(),
            face: Vec::new(),
        }
    }

    /// Reserves room for `cap` vertices.
    fn reserve(&mut self, cap: usize) {
        self.cloud.points.reserve(cap);
        if self.layout.has_normals {
            self.normals.reserve(cap);
        }
        if self.layout.has_colors {
            self.colors.reserve(cap);
        }
    }

    /// Reads record `record` of `element`, keeping it when it is a vertex or a face and
    /// skipping it otherwise.
    fn read(
        &mut self,
        body: &mut impl Body,
        element: &Element,
        record: usize,
        is_vertex: bool,
        is_face: bool,
    ) -> Result<(), PlyError> {
        body.begin_record();
        let mut vertex = Vertex::default();
        for (index, property) in element.properties.iter().enumerate() {
            let at = At {
                element,
                record,
                property,
            };
            match property.kind {
                Kind::Scalar(ty) => {
                    let value = body.value(ty).map_err(|f| at.error(f, body.location()))?;
                    if is_vertex {
                        self.set(&mut vertex, index, value, ty, body.location(), at)?;
                    }
                }
                Kind::List { len, item } => {
                    let n = body.value(len).map_err(|f| at.error(f, body.location()))?;
                    let location = body.location();
                    if !(n >= 0.0 && n.fract() == 0.0 && n <= usize::MAX as f64) {
                        return Err(PlyError::InvalidListLength {
                            location,
                            property: property.name.clone(),
                            value: n,
                        });
                    }
                    // Exact: `n` is a non-negative integer no larger than usize::MAX.
                    let n = n as usize;
                    if is_face && Some(index) == self.layout.face_list {
                        self.read_face(body, item, n, at)?;
                    } else {
                        body.skip(item, n)
                            .map_err(|f| at.error(f, body.location()))?;
                    }
                }
            }
        }
        if is_vertex {
            self.cloud.points.push(vertex.point);
            if self.layout.has_normals {
                self.normals.push(vertex.normal);
            }
            if self.layout.has_colors {
                self.colors.push(vertex.color);
            }
        }
        Ok(())
    }

    /// Puts the value of vertex property `index` (of type `ty`, read at `location`) in its
    /// place in `vertex`; a coordinate must be finite.
    fn set(
        &self,
        vertex: &mut Vertex,
        index: usize,
        value: f64,
        ty: Scalar,
        location: Location,
        at: At,
    ) -> Result<(), PlyError> {
        match self.layout.roles[index] {
            Role::Coord(axis) => {
                if !value.is_finite() {
                    return Err(PlyError::InvalidValue {
                        location,
                        element: at.element.name.clone(),
                        property: at.property.name.clone(),
                        token: value.to_string(),
                    });
                }
                vertex.point[axis] = value;
            }
            Role::Normal(axis) => vertex.normal[axis] = value,
            Role::Color(channel) => vertex.color[channel] = color_channel(value, ty),
            Role::Other => {}
        }
        Ok(())
    }

    /// Reads a face's `n` vertex indices of type `item` and fans it into triangles.
    fn read_face(
        &mut self,
        body: &mut impl Body,
        item: Scalar,
        n: usize,
        at: At,
    ) -> Result<(), PlyError> {
        let vertex_count = self.layout.vertex_count;
        self.face.clear();
        // Bounded by the data: every iteration consumes input or fails.
        for _ in 0..n {
            let value = body.value(item).map_err(|f| at.error(f, body.location()))?;
            let location = body.location();
            let valid = value >= 0.0 && value.fract() == 0.0 && value < vertex_count as f64;
            if !valid {
                return Err(PlyError::IndexOutOfRange {
                    location,
                    face: at.record,
                    index: value,
                    vertex_count,
                });
            }
            // Exact: checked integral and below vertex_count <= 2^32.
            self.face.push(value as u32);
        }
        if let Some((&first, rest)) = self.face.split_first() {
            for pair in rest.windows(2) {
                self.cloud.triangles.push([first, pair[0], pair[1]]);
            }
        }
        Ok(())
    }

    /// The cloud, with normals and colours when the vertices declare all three components.
    fn finish(mut self) -> PointCloud {
        self.cloud.normals = self.layout.has_normals.then_some(self.normals);
        self.cloud.colors = self.layout.has_colors.then_some(self.colors);
        self.cloud
    }
}
