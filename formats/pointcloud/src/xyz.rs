//! XYZ reader: one point per line, `x y z [extra columns...]`.
//!
//! Columns are separated by whitespace, commas or semicolons. Lines starting with `#` or `//` and
//! blank lines are skipped; so is a first line in which no column is a number (a column header
//! such as `X Y Z R G B`).
//!
//! # Extra columns
//!
//! Columns 4–6 (and, if present, 7–9) are looked at as triples over the whole file:
//!
//! * a triple is **colour** if on every point all three values are integers in 0..=255 and either
//!   some value is above 1 or every value is written as a plain integer (`0 0 1`, not
//!   `0.0 0.0 1.0`);
//! * otherwise it is a **normal** if on every point all three values lie in [-1, 1];
//! * otherwise it is ignored, as are all columns after the ninth and non-numeric extra columns.
//!
//! The first triple judged a colour becomes [`PointCloud::colors`], the first judged a normal
//! [`PointCloud::normals`]. So `x y z r g b`, `x y z nx ny nz`, `x y z nx ny nz r g b`,
//! `x y z r g b a` (CloudCompare) and `x y z r g b nx ny nz` are all understood. Floating-point
//! colours in 0..1 cannot be told from normals and are read as normals.

use crate::PointCloud;

/// Why an XYZ file could not be read. Lines are 1-based.
///
/// How to fix: every non-comment line must start with three numbers `x y z`; comment out or
/// remove the named line.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum XyzError {
    /// A point line with fewer than three columns.
    #[error("line {line}: expected at least 3 numbers (x y z), found {found}")]
    TooFewColumns {
        /// The line.
        line: usize,
        /// How many columns it has.
        found: usize,
    },
    /// One of the first three columns is not a finite number.
    #[error("line {line}: `{token}` is not a valid coordinate")]
    InvalidNumber {
        /// The line.
        line: usize,
        /// The column as found.
        token: String,
    },
}

/// Statistics of one triple of extra columns over all points.
#[derive(Clone)]
struct Triple {
    values: Vec<[f64; 3]>,
    /// Present (and numeric) on every point so far.
    complete: bool,
    all_byte_ints: bool,
    all_plain_ints: bool,
    any_above_one: bool,
    all_unit: bool,
}

impl Triple {
    fn new() -> Self {
        Triple {
            values: Vec::new(),
            complete: true,
            all_byte_ints: true,
            all_plain_ints: true,
            any_above_one: false,
            all_unit: true,
        }
    }

    fn push(&mut self, tokens: Option<[&str; 3]>) {
        if !self.complete {
            return;
        }
        let parsed = tokens.and_then(|t| {
            let v = [t[0].parse().ok()?, t[1].parse().ok()?, t[2].parse().ok()?];
            Some((t, v))
        });
        let Some((tokens, value)) = parsed else {
            self.complete = false;
            self.values = Vec::new();
            return;
        };
        for (token, v) in tokens.iter().zip(value) {
            let v: f64 = v;
            self.all_byte_ints &= (0.0..=255.0).contains(&v) && v.fract() == 0.0;
            self.all_plain_ints &= token.bytes().all(|b| b.is_ascii_digit() || b == b'+');
            self.any_above_one |= v > 1.0;
            self.all_unit &= (-1.0..=1.0).contains(&v);
        }
        self.values.push(value);
    }

    fn is_color(&self) -> bool {
        self.complete && self.all_byte_ints && (self.any_above_one || self.all_plain_ints)
    }

    fn is_normal(&self) -> bool {
        self.complete && !self.is_color() && self.all_unit
    }
}

fn is_separator(c: char) -> bool {
    c.is_whitespace() || c == ',' || c == ';'
}

/// Reads an XYZ point cloud. See the [module documentation](self) for the column rules.
///
/// [`PointCloud::triangles`] is always empty. A file with no points is read as an empty cloud.
///
/// # Errors
///
/// [`XyzError`] naming the line when a point line has fewer than three columns or one of its
/// first three columns is not a finite number.
pub fn read_xyz(bytes: &[u8]) -> Result<PointCloud, XyzError> {
    // A UTF-8 byte order mark, as some Windows tools write, is not part of the first line.
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let text = String::from_utf8_lossy(bytes);
    let mut points = Vec::new();
    let mut triples = [Triple::new(), Triple::new()];
    let mut first_data_line = true;
    for (index, line) in text.lines().enumerate() {
        let line_no = index + 1;
        let trimmed = line.trim();
        if trimmed.is_empty() || trimmed.starts_with('#') || trimmed.starts_with("//") {
            continue;
        }
        let columns: Vec<&str> = trimmed
            .split(is_separator)
            .filter(|c| !c.is_empty())
            .collect();
        if std::mem::take(&mut first_data_line) && columns.iter().all(|c| c.parse::<f64>().is_err())
        {
            continue; // a column header
        }
        if columns.len() < 3 {
            return Err(XyzError::TooFewColumns {
                line: line_no,
                found: columns.len(),
            });
        }
        let mut point = [0.0; 3];
        for (slot, token) in point.iter_mut().zip(&columns) {
            *slot = token
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| XyzError::InvalidNumber {
                    line: line_no,
                    token: (*token).to_owned(),
                })?;
        }
        points.push(point);
        for (i, triple) in triples.iter_mut().enumerate() {
            let start = 3 + 3 * i;
            triple.push(columns.get(start..start + 3).map(|c| [c[0], c[1], c[2]]));
        }
    }
    let colors = triples.iter().find(|t| t.is_color()).map(|t| {
        t.values
            .iter()
            // Exact: checked to be integers in 0..=255.
            .map(|v| v.map(|c| c as u8))
            .collect()
    });
    let normals = triples
        .iter()
        .find(|t| t.is_normal())
        .map(|t| t.values.clone());
    let has_points = !points.is_empty();
    Ok(PointCloud {
        points,
        normals: normals.filter(|_| has_points),
        colors: colors.filter(|_| has_points),
        triangles: Vec::new(),
    })
}
