//! OBJ writing.

use std::io::{self, BufWriter, Write};

use crate::ObjObject;

fn invalid(message: String) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, message)
}

/// The name as [`read`](crate::read) will return it: one line, no comment start (`#` at the
/// start or after whitespace becomes `_`), no trailing backslash (becomes `_`), trimmed.
fn sanitize_name(name: &str) -> String {
    let mut out = String::with_capacity(name.len());
    for c in name.chars() {
        let c = match c {
            '\n' | '\r' => ' ',
            '#' if out.is_empty() || out.ends_with(char::is_whitespace) => '_',
            c => c,
        };
        out.push(c);
    }
    let mut name = out.trim().to_owned();
    // A trailing backslash would continue the line onto the next statement.
    if name.ends_with('\\') {
        name.pop();
        name.push('_');
    }
    name
}

/// Writes `objects` as OBJ: per object `o NAME`, its `v x y z` lines and `f a b c` lines with
/// 1-based indices that count vertices across the whole file.
///
/// Coordinates are written in Rust's shortest round-trip notation (`0.1`, `1e-7`), so
/// [`read`](crate::read) returns them bit for bit. Names are made safe: line breaks become
/// spaces, a `#` that would start a comment and a trailing backslash (line continuation) become
/// `_`, and surrounding whitespace is trimmed. An empty name gives a bare `o` line, which reads
/// back as an empty name. Reading the output back gives the same objects, provided each
/// object has triangles, uses all its vertices and lists them in order of first use (which is
/// what [`read`](crate::read) produces).
///
/// The writer is buffered internally; pass `w` unbuffered or buffered as convenient.
///
/// # Errors
///
/// The writer's I/O errors, and [`io::ErrorKind::InvalidInput`] for a coordinate that is not
/// finite or a triangle index outside its object's vertex list (nothing sensible could be
/// written for either).
pub fn write<W: Write>(w: &mut W, objects: &[ObjObject]) -> io::Result<()> {
    let mut out = BufWriter::new(w);
    writeln!(out, "# written by conduit")?;
    let mut first_index: u64 = 1;
    for object in objects {
        let name = sanitize_name(&object.name);
        if name.is_empty() {
            writeln!(out, "o")?;
        } else {
            writeln!(out, "o {name}")?;
        }
        for v in &object.vertices {
            if !v.iter().all(|c| c.is_finite()) {
                return Err(invalid(format!(
                    "object `{name}`: vertex {v:?} is not finite"
                )));
            }
            // `{:?}` is the shortest representation that parses back to the same f64.
            writeln!(out, "v {:?} {:?} {:?}", v[0], v[1], v[2])?;
        }
        let count = object.vertices.len();
        for t in &object.triangles {
            if t.iter().any(|&i| i as usize >= count) {
                return Err(invalid(format!(
                    "object `{name}`: triangle {t:?} refers past its {count} vertices"
                )));
            }
            let [a, b, c] = t.map(|i| first_index + u64::from(i));
            writeln!(out, "f {a} {b} {c}")?;
        }
        first_index += count as u64;
    }
    out.flush()
}
