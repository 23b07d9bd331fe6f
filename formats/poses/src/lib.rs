//! Pose and measurement tables as CSV: robot poses (position + quaternion), measured points,
//! joint angles, gap readings.
//!
//! Part of conduit's `formats/` layer, used by the robot commands: `conduit conform --output
//! poses-csv` writes poses, `conduit calibrate` reads flange poses and point pairs, `conduit
//! compensate` reads a path of poses and a table of measured gaps. The crate only describes
//! the files and has no dependency on the pipeline.
//!
//! A table is plain CSV: lines starting with `#` and blank lines are skipped, the first other
//! line names the columns, every later line holds one number per column (commas between
//! fields, spaces around them ignored). Readers never panic; errors name the line and column.
//!
//! Poses ([`read_poses`], [`write_poses`]) use the columns `x,y,z,qw,qx,qy,qz` (mm, unit
//! quaternion of the tool frame in the table's frame) and an optional `dispense` (0 or 1).
//! Output is deterministic: positions with 4 decimals, quaternion components with 9, `\n`
//! line endings, each quaternion with `qw ≥ 0`.
//!
//! ```
//! use conduit_poses::{Pose, read_poses, write_poses};
//! let p = Pose { position: [1.0, 2.0, 3.0], quaternion: [1.0, 0.0, 0.0, 0.0], dispense: true };
//! let mut csv = Vec::new();
//! write_poses(&[p], &mut csv)?;
//! let text = String::from_utf8_lossy(&csv);
//! assert_eq!(text, "x,y,z,qw,qx,qy,qz,dispense\n\
//!                   1.0000,2.0000,3.0000,1.000000000,0.000000000,0.000000000,0.000000000,1\n");
//! assert_eq!(read_poses(&text)?, vec![p]);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::io;

/// Why a table could not be read.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum TableError {
    /// No header line.
    ///
    /// How to fix: the first line that is not a comment must name the columns.
    #[error("no header line naming the columns")]
    NoHeader,
    /// A column name is empty or repeated.
    ///
    /// How to fix: name every column once.
    #[error("line {line}: column {column} of the header is {problem}")]
    BadHeader {
        /// 1-based line number.
        line: usize,
        /// 1-based column number.
        column: usize,
        /// "empty" or "repeated".
        problem: &'static str,
    },
    /// A line has the wrong number of fields.
    ///
    /// How to fix: one value per header column.
    #[error("line {line}: {found} field(s), the header names {expected}")]
    Width {
        /// 1-based line number.
        line: usize,
        /// Fields the header names.
        expected: usize,
        /// Fields found.
        found: usize,
    },
    /// A field is not a finite number.
    ///
    /// How to fix: write a decimal number (`1.5`, `-2e-3`).
    #[error("line {line}, column `{column}`: `{text}` is not a finite number")]
    Number {
        /// 1-based line number.
        line: usize,
        /// The column's name.
        column: String,
        /// The field as written.
        text: String,
    },
    /// A required column is absent.
    ///
    /// How to fix: add the column (names are case-insensitive).
    #[error("no `{0}` column")]
    MissingColumn(String),
    /// A quaternion has (near) zero length.
    ///
    /// How to fix: write a unit quaternion `qw,qx,qy,qz`.
    #[error("line {line}: the quaternion has zero length")]
    ZeroQuaternion {
        /// 1-based line number.
        line: usize,
    },
    /// A pose's quaternion is so long that its length is not a finite number.
    ///
    /// How to fix: write a unit quaternion `qw,qx,qy,qz`.
    #[error(
        "line {line}: the quaternion's length is not a finite number (write a unit quaternion)"
    )]
    QuaternionLength {
        /// 1-based line number.
        line: usize,
    },
    /// A pose's position is farther than [`MAX_POSITION`] from the origin along an axis.
    ///
    /// How to fix: write positions in millimetres; remove the stray row.
    #[error(
        "line {line}, column `{column}`: {value:e} mm is beyond the {MAX_POSITION} mm working extent"
    )]
    Position {
        /// 1-based line number.
        line: usize,
        /// The column's name.
        column: &'static str,
        /// The value read.
        value: f64,
    },
    /// A `dispense` field is not 0 or 1.
    ///
    /// How to fix: write 0 (off) or 1 (on).
    #[error("line {line}: dispense must be 0 or 1, got {value}")]
    Dispense {
        /// 1-based line number.
        line: usize,
        /// The value read.
        value: f64,
    },
}

/// A CSV table of numbers with named columns.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    /// Column names as written (trimmed).
    pub columns: Vec<String>,
    /// One row per data line, one value per column.
    pub rows: Vec<Vec<f64>>,
    /// The 1-based line number of each row in the file.
    pub lines: Vec<usize>,
}

impl Table {
    /// Reads a table from CSV text.
    pub fn parse(text: &str) -> Result<Self, TableError> {
        let mut columns: Option<Vec<String>> = None;
        let mut rows = Vec::new();
        let mut lines = Vec::new();
        for (i, raw) in text.lines().enumerate() {
            let line = i + 1;
            let l = raw.trim();
            if l.is_empty() || l.starts_with('#') {
                continue;
            }
            let fields: Vec<&str> = l.split(',').map(str::trim).collect();
            let Some(cols) = &columns else {
                for (c, f) in fields.iter().enumerate() {
                    let problem = if f.is_empty() {
                        Some("empty")
                    } else if fields[..c].iter().any(|g| g.eq_ignore_ascii_case(f)) {
                        Some("repeated")
                    } else {
                        None
                    };
                    if let Some(problem) = problem {
                        return Err(TableError::BadHeader {
                            line,
                            column: c + 1,
                            problem,
                        });
                    }
                }
                columns = Some(fields.iter().map(|f| f.to_string()).collect());
                continue;
            };
            if fields.len() != cols.len() {
                return Err(TableError::Width {
                    line,
                    expected: cols.len(),
                    found: fields.len(),
                });
            }
            let row = fields
                .iter()
                .zip(cols)
                .map(|(f, name)| match f.parse::<f64>() {
                    Ok(v) if v.is_finite() => Ok(v),
                    _ => Err(TableError::Number {
                        line,
                        column: name.clone(),
                        text: (*f).to_string(),
                    }),
                })
                .collect::<Result<Vec<f64>, _>>()?;
            rows.push(row);
            lines.push(line);
        }
        let columns = columns.ok_or(TableError::NoHeader)?;
        Ok(Self {
            columns,
            rows,
            lines,
        })
    }

    /// Index of the column named `name` (case-insensitive).
    pub fn column(&self, name: &str) -> Option<usize> {
        self.columns
            .iter()
            .position(|c| c.eq_ignore_ascii_case(name))
    }

    /// Indices of the columns named `names`, or the first one missing.
    pub fn require(&self, names: &[&str]) -> Result<Vec<usize>, TableError> {
        names
            .iter()
            .map(|n| {
                self.column(n)
                    .ok_or_else(|| TableError::MissingColumn((*n).to_string()))
            })
            .collect()
    }
}

/// Writes a table: the header, then each row with `decimals` decimals per value. Refuses NaN
/// and infinite values and rows of the wrong width with [`io::ErrorKind::InvalidInput`].
pub fn write_table(
    columns: &[&str],
    rows: &[Vec<f64>],
    decimals: usize,
    out: &mut impl io::Write,
) -> io::Result<()> {
    writeln!(out, "{}", columns.join(","))?;
    for (i, row) in rows.iter().enumerate() {
        if row.len() != columns.len() || row.iter().any(|v| !v.is_finite()) {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!("row {i}: {} finite values expected", columns.len()),
            ));
        }
        let fields: Vec<String> = row.iter().map(|v| fixed(*v, decimals)).collect();
        writeln!(out, "{}", fields.join(","))?;
    }
    Ok(())
}

/// `v` with `decimals` decimals, without a negative zero.
fn fixed(v: f64, decimals: usize) -> String {
    let s = format!("{v:.decimals$}");
    if s.starts_with('-') && s[1..].chars().all(|c| c == '0' || c == '.') {
        s[1..].to_string()
    } else {
        s
    }
}

/// One pose of a tool: where its centre point is and how it is turned.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// Position, mm.
    pub position: [f64; 3],
    /// Unit quaternion `[w, x, y, z]` of the tool frame.
    pub quaternion: [f64; 4],
    /// Whether material is dispensed on the move to this pose.
    pub dispense: bool,
}

/// The pose columns, in the order [`write_poses`] writes them.
pub const POSE_COLUMNS: [&str; 8] = ["x", "y", "z", "qw", "qx", "qy", "qz", "dispense"];

/// Largest pose coordinate (absolute, per axis), mm: 10 m, beyond the reach of any robot cell
/// this format serves; a larger value is a stray or a file in other units, and would carry
/// hundreds of digits into the results.
pub const MAX_POSITION: f64 = 10_000.0;

/// Reads poses from CSV text with the columns `x,y,z,qw,qx,qy,qz` (any order, other columns
/// ignored) and an optional `dispense` (default 1). Quaternions are normalised.
pub fn read_poses(text: &str) -> Result<Vec<Pose>, TableError> {
    let t = Table::parse(text)?;
    let idx = t.require(&POSE_COLUMNS[..7])?;
    let dispense = t.column("dispense");
    t.rows
        .iter()
        .zip(&t.lines)
        .map(|(r, &line)| {
            let q = [r[idx[3]], r[idx[4]], r[idx[5]], r[idx[6]]];
            let n = q.iter().map(|c| c * c).sum::<f64>().sqrt();
            if !n.is_finite() {
                return Err(TableError::QuaternionLength { line });
            }
            if n < 1e-9 {
                return Err(TableError::ZeroQuaternion { line });
            }
            for (k, column) in POSE_COLUMNS[..3].iter().enumerate() {
                let value = r[idx[k]];
                if value.abs() > MAX_POSITION {
                    return Err(TableError::Position {
                        line,
                        column,
                        value,
                    });
                }
            }
            let on = match dispense.map(|c| r[c]) {
                None => true,
                Some(0.0) => false,
                Some(1.0) => true,
                Some(value) => return Err(TableError::Dispense { line, value }),
            };
            Ok(Pose {
                position: [r[idx[0]], r[idx[1]], r[idx[2]]],
                quaternion: q.map(|c| c / n),
                dispense: on,
            })
        })
        .collect()
}

/// Writes poses as CSV ([`POSE_COLUMNS`]); each quaternion is normalised, the first turned to
/// `qw ≥ 0` and each later one to the sign nearest its predecessor (q and −q are the same
/// rotation; a sign that flips between neighbours makes some controllers interpolate the long
/// way round).
pub fn write_poses(poses: &[Pose], out: &mut impl io::Write) -> io::Result<()> {
    writeln!(out, "{}", POSE_COLUMNS.join(","))?;
    let mut previous: Option<[f64; 4]> = None;
    for (i, p) in poses.iter().enumerate() {
        let q = p.quaternion;
        let n = q.iter().map(|c| c * c).sum::<f64>().sqrt();
        if !(n.is_finite() && n > 1e-9) || p.position.iter().any(|v| !v.is_finite()) {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!("pose {i}: not finite or zero quaternion"),
            ));
        }
        let reference = previous.unwrap_or([1.0, 0.0, 0.0, 0.0]);
        let dot: f64 = (0..4).map(|k| q[k] * reference[k]).sum();
        let sign = if dot < 0.0 { -1.0 } else { 1.0 };
        let q = q.map(|c| sign * c / n);
        previous = Some(q);
        let pos: Vec<String> = p.position.iter().map(|v| fixed(*v, 4)).collect();
        let quat: Vec<String> = q.iter().map(|v| fixed(*v, 9)).collect();
        writeln!(
            out,
            "{},{},{}",
            pos.join(","),
            quat.join(","),
            u8::from(p.dispense)
        )?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn huge_positions_and_overflowing_quaternions_are_refused_by_line() {
        let head = "x,y,z,qw,qx,qy,qz\n1,2,3,1,0,0,0\n";
        let far = format!("{head}1e308,0,0,1,0,0,0\n");
        assert!(matches!(
            read_poses(&far),
            Err(TableError::Position {
                line: 3,
                column: "x",
                ..
            })
        ));
        let long = format!("{head}1,2,3,-0.2,-1e308,0.4,0.1\n");
        assert_eq!(
            read_poses(&long),
            Err(TableError::QuaternionLength { line: 3 })
        );
    }

    #[test]
    fn comments_blank_lines_and_spaces_are_skipped_and_columns_found_by_name() {
        let t = Table::parse("# measured\n\n Gap , s\n0.05, 1\n0.06 ,2\n").expect("parses");
        assert_eq!(t.columns, vec!["Gap", "s"]);
        assert_eq!(t.rows, vec![vec![0.05, 1.0], vec![0.06, 2.0]]);
        assert_eq!(t.lines, vec![4, 5]);
        assert_eq!(t.column("gap"), Some(0));
        assert_eq!(
            t.require(&["s", "x"]),
            Err(TableError::MissingColumn("x".into()))
        );
    }

    #[test]
    fn bad_tables_name_the_line_and_column() {
        assert_eq!(Table::parse("# only\n"), Err(TableError::NoHeader));
        assert_eq!(
            Table::parse("a,b\n1\n"),
            Err(TableError::Width {
                line: 2,
                expected: 2,
                found: 1
            })
        );
        assert_eq!(
            Table::parse("a,b\n1,nan\n"),
            Err(TableError::Number {
                line: 2,
                column: "b".into(),
                text: "nan".into()
            })
        );
        assert_eq!(
            Table::parse("a,A\n"),
            Err(TableError::BadHeader {
                line: 1,
                column: 2,
                problem: "repeated"
            })
        );
        assert_eq!(
            read_poses("x,y,z,qw,qx,qy,qz\n0,0,0,0,0,0,0\n"),
            Err(TableError::ZeroQuaternion { line: 2 })
        );
        assert_eq!(
            read_poses("x,y,z,qw,qx,qy,qz,dispense\n0,0,0,1,0,0,0,2\n"),
            Err(TableError::Dispense {
                line: 2,
                value: 2.0
            })
        );
    }

    #[test]
    fn poses_round_trip_within_their_decimals() {
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let poses = vec![
            Pose {
                position: [12.345678, -0.00001, 300.0],
                quaternion: [-h, 0.0, -h, 0.0],
                dispense: false,
            },
            Pose {
                position: [1.0, 2.0, 3.0],
                quaternion: [0.5, 0.5, 0.5, 0.5],
                dispense: true,
            },
        ];
        let mut out = Vec::new();
        write_poses(&poses, &mut out).expect("writes");
        let text = String::from_utf8(out).expect("utf-8");
        assert!(text.contains("12.3457,0.0000,300.0000,0.707106781,0.000000000,0.707106781"));
        // Nearly half turns about x written one after the other keep one sign (qw changes sign
        // with the rotation, not from pose to pose).
        let turn = |a: f64| Pose {
            position: [0.0; 3],
            quaternion: [(a / 2.0).cos(), (a / 2.0).sin(), 0.0, 0.0],
            dispense: true,
        };
        let flips: Vec<Pose> = [179.0f64, 181.0, 179.5]
            .iter()
            .map(|d| {
                let mut p = turn(d.to_radians());
                p.quaternion = p.quaternion.map(|c| -c);
                p
            })
            .collect();
        let mut out = Vec::new();
        write_poses(&flips, &mut out).expect("writes");
        let back = read_poses(&String::from_utf8_lossy(&out)).expect("reads");
        for w in back.windows(2) {
            let dot: f64 = (0..4)
                .map(|k| w[0].quaternion[k] * w[1].quaternion[k])
                .sum();
            assert!(dot > 0.99, "{back:?}");
        }
        let back = read_poses(&text).expect("reads");
        assert_eq!(back.len(), 2);
        assert!(!back[0].dispense && back[1].dispense);
        for (a, b) in poses.iter().zip(&back) {
            for k in 0..3 {
                assert!((a.position[k] - b.position[k]).abs() <= 0.5e-4);
            }
            // Same rotation: q and −q.
            let dot: f64 = (0..4).map(|k| a.quaternion[k] * b.quaternion[k]).sum();
            assert!((dot.abs() - 1.0).abs() < 1e-8);
        }
    }

    #[test]
    fn writers_refuse_non_finite_values() {
        let p = Pose {
            position: [f64::NAN, 0.0, 0.0],
            quaternion: [1.0, 0.0, 0.0, 0.0],
            dispense: true,
        };
        assert!(write_poses(&[p], &mut Vec::new()).is_err());
        assert!(write_table(&["a"], &[vec![f64::INFINITY]], 3, &mut Vec::new()).is_err());
        let mut out = Vec::new();
        write_table(&["a", "b"], &[vec![-0.0001, 2.0]], 3, &mut out).expect("writes");
        assert_eq!(String::from_utf8_lossy(&out), "a,b\n0.000,2.000\n");
    }
}
