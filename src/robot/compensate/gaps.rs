//! Measured gap tables: sensor readings along a path, interpolated onto the path's points.
//!
//! Place in the pipeline: the input of a compensation pass ([`super::compensate_pass`]). A
//! table (CSV, [`conduit_poses::Table`]) has a `reading` column (the sensor's reading, mm) and
//! says where along the path each reading was taken by one of:
//!
//! - `index`: the 0-based number of the pose (integers, increasing);
//! - `s`: the arc length along the path's tips from the first pose, mm (increasing);
//! - neither: one reading per pose, in order (the row count must equal the pose count).
//!
//! `index` wins when both are present. Between two readings the value is linear in arc
//! length; poses before the first or after the last reading take that reading (and are
//! counted, so a short measurement is visible in the report).

use conduit_poses::{Table, TableError};
use serde::Serialize;

/// Why a gap table was refused.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum GapsError {
    /// The table could not be read.
    #[error(transparent)]
    Table(#[from] TableError),
    /// The table has no readings.
    ///
    /// How to fix: add at least one data line.
    #[error("no readings")]
    Empty,
    /// Neither `index` nor `s`, and not one reading per pose.
    ///
    /// How to fix: add an `index` or `s` column, or give exactly one reading per pose.
    #[error(
        "{readings} reading(s) for {poses} pose(s): without an `index` or `s` column the table needs one reading per pose"
    )]
    Count {
        /// Rows in the table.
        readings: usize,
        /// Poses in the path.
        poses: usize,
    },
    /// An `index` is not a pose number of the path.
    ///
    /// How to fix: indices are whole numbers from 0 to the pose count − 1.
    #[error("line {line}: index {value} is not a pose of the path (0 to {last})")]
    Index {
        /// 1-based line number.
        line: usize,
        /// The value read.
        value: f64,
        /// The last pose index.
        last: usize,
    },
    /// The positions do not increase.
    ///
    /// How to fix: sort the table along the path and remove repeated positions.
    #[error("line {line}: `{column}` {value} does not increase from the line before")]
    Order {
        /// 1-based line number.
        line: usize,
        /// `index` or `s`.
        column: &'static str,
        /// The value read.
        value: f64,
    },
}

/// How the readings were placed on the path.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Key {
    /// By pose index.
    Index,
    /// By arc length.
    S,
    /// One reading per pose.
    Row,
}

/// Readings on the path's points.
#[derive(Debug, Clone, PartialEq)]
pub struct OnPath {
    /// One reading per pose, mm.
    pub readings: Vec<f64>,
    /// How the table placed them.
    pub key: Key,
    /// Rows read.
    pub rows: usize,
    /// Poses outside the measured stretch (they took the nearest reading).
    pub outside: usize,
}

/// Reads `text` and puts its readings on the poses at arc lengths `s` (one per pose).
pub fn read(text: &str, s: &[f64]) -> Result<OnPath, GapsError> {
    let t = Table::parse(text)?;
    let [reading] = t.require(&["reading"])?[..] else {
        return Err(GapsError::Empty);
    };
    if t.rows.is_empty() {
        return Err(GapsError::Empty);
    }
    let values: Vec<f64> = t.rows.iter().map(|r| r[reading]).collect();
    let n = s.len();
    let (key, at) = if let Some(c) = t.column("index") {
        let last = n.saturating_sub(1);
        let mut at = Vec::with_capacity(t.rows.len());
        for (r, &line) in t.rows.iter().zip(&t.lines) {
            let v = r[c];
            if v.fract() != 0.0 || v < 0.0 || v > last as f64 || n == 0 {
                return Err(GapsError::Index {
                    line,
                    value: v,
                    last,
                });
            }
            at.push(s[v as usize]);
        }
        (Key::Index, at)
    } else if let Some(c) = t.column("s") {
        (Key::S, t.rows.iter().map(|r| r[c]).collect())
    } else {
        if t.rows.len() != n {
            return Err(GapsError::Count {
                readings: t.rows.len(),
                poses: n,
            });
        }
        return Ok(OnPath {
            readings: values,
            key: Key::Row,
            rows: n,
            outside: 0,
        });
    };
    let (column, col) = match key {
        Key::Index => ("index", t.column("index")),
        _ => ("s", t.column("s")),
    };
    let raw: Vec<f64> = t.rows.iter().map(|r| col.map_or(0.0, |c| r[c])).collect();
    for k in 1..raw.len() {
        if raw[k] <= raw[k - 1] {
            return Err(GapsError::Order {
                line: t.lines[k],
                column,
                value: raw[k],
            });
        }
    }
    let mut outside = 0;
    let mut j = 0;
    let readings = s
        .iter()
        .map(|&si| {
            if si < at[0] || si > at[at.len() - 1] {
                outside += 1;
            }
            while j + 1 < at.len() && at[j + 1] < si {
                j += 1;
            }
            interpolate(&at, &values, j, si)
        })
        .collect();
    Ok(OnPath {
        readings,
        key,
        rows: values.len(),
        outside,
    })
}

/// The value at `x` on the polyline (`at`, `values`) from segment `j` on, clamped at the ends.
fn interpolate(at: &[f64], values: &[f64], j: usize, x: f64) -> f64 {
    let last = at.len() - 1;
    if x <= at[0] {
        return values[0];
    }
    if x >= at[last] {
        return values[last];
    }
    let (a, b) = (at[j], at[j + 1]);
    if b <= a {
        return values[j + 1];
    }
    let u = (x - a) / (b - a);
    values[j] + u * (values[j + 1] - values[j])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn readings_by_arc_length_are_linear_between_samples_and_clamped_outside() {
        let s = [0.0, 1.0, 2.0, 3.0, 4.0];
        let g = read("s,reading\n0.5,0.10\n2.5,0.30\n", &s).expect("reads");
        assert_eq!(g.key, Key::S);
        assert_eq!(g.outside, 3);
        let want = [0.10, 0.15, 0.25, 0.30, 0.30];
        for (a, b) in g.readings.iter().zip(want) {
            assert!((a - b).abs() < 1e-12, "{a} vs {b}");
        }
        let g = read("index,reading\n1,0.2\n3,0.4\n", &[0.0, 1.0, 1.5, 3.0, 4.0]).expect("reads");
        assert!((g.readings[2] - 0.25).abs() < 1e-12);
    }

    #[test]
    fn bad_tables_name_the_line() {
        let s = [0.0, 1.0, 2.0];
        assert_eq!(
            read("index,reading\n0,1\n3,1\n", &s),
            Err(GapsError::Index {
                line: 3,
                value: 3.0,
                last: 2
            })
        );
        assert_eq!(
            read("s,reading\n1,1\n0.5,1\n", &s),
            Err(GapsError::Order {
                line: 3,
                column: "s",
                value: 0.5
            })
        );
        assert_eq!(
            read("reading\n1\n2\n", &s),
            Err(GapsError::Count {
                readings: 2,
                poses: 3
            })
        );
        assert_eq!(
            read("s,gap\n1,1\n", &s),
            Err(GapsError::Table(TableError::MissingColumn(
                "reading".into()
            )))
        );
    }
}
