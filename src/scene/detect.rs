//! Which reader a file needs: by extension when it names a known format, otherwise by content.

use std::path::Path;

/// The file families conduit reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum FileKind {
    /// STL, ASCII or binary.
    Stl,
    /// 3MF package.
    #[serde(rename = "3mf")]
    ThreeMf,
    /// Wavefront OBJ.
    Obj,
    /// Object File Format.
    Off,
    /// PLY point cloud or mesh.
    Ply,
    /// XYZ point cloud.
    Xyz,
    /// EAGLE schematic or board.
    Eagle,
    /// KiCad board, schematic or netlist export.
    Kicad,
    /// G-code (text, or binary which is refused).
    Gcode,
    /// SVG 2D design.
    Svg,
}

impl FileKind {
    /// The kind named by a file's extension (case-insensitive), if any.
    pub fn from_extension(path: &Path) -> Option<FileKind> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        Some(match ext.as_str() {
            "stl" => FileKind::Stl,
            "3mf" => FileKind::ThreeMf,
            "obj" => FileKind::Obj,
            "off" => FileKind::Off,
            "ply" => FileKind::Ply,
            "xyz" | "pts" => FileKind::Xyz,
            "sch" | "brd" | "lbr" => FileKind::Eagle,
            "kicad_pcb" | "kicad_sch" | "net" => FileKind::Kicad,
            "gcode" | "gco" | "g" | "nc" | "bgcode" => FileKind::Gcode,
            "svg" => FileKind::Svg,
            _ => return None,
        })
    }

    /// The kind a file's first bytes show, if they are distinctive.
    pub fn sniff(bytes: &[u8]) -> Option<FileKind> {
        let head = &bytes[..bytes.len().min(1024)];
        let text = String::from_utf8_lossy(head);
        let trimmed = text.trim_start_matches('\u{feff}').trim_start();
        let first_word = trimmed.split_ascii_whitespace().next().unwrap_or("");
        if head.starts_with(b"PK\x03\x04") {
            Some(FileKind::ThreeMf)
        } else if head.starts_with(b"GCDE") {
            Some(FileKind::Gcode)
        } else if conduit_kicad::sniff(head).is_some() {
            Some(FileKind::Kicad)
        } else if text.contains("<eagle") {
            Some(FileKind::Eagle)
        } else if text.contains("<svg") {
            Some(FileKind::Svg)
        } else if first_word == "ply" {
            Some(FileKind::Ply)
        } else if matches!(
            first_word,
            "OFF" | "COFF" | "NOFF" | "CNOFF" | "STOFF" | "4OFF"
        ) {
            Some(FileKind::Off)
        } else if first_word.eq_ignore_ascii_case("solid") || binary_stl_size_matches(bytes) {
            Some(FileKind::Stl)
        } else if conduit_obj::looks_like_obj(bytes) {
            Some(FileKind::Obj)
        } else if looks_like_gcode(&text) {
            Some(FileKind::Gcode)
        } else {
            None
        }
    }

    /// The kind of a file: its extension when known, else its content.
    pub fn detect(path: &Path, bytes: &[u8]) -> Option<FileKind> {
        Self::from_extension(path).or_else(|| Self::sniff(bytes))
    }

    /// Whether this kind holds a triangle mesh that `convert` can write out.
    pub fn is_mesh(self) -> bool {
        matches!(
            self,
            FileKind::Stl | FileKind::ThreeMf | FileKind::Obj | FileKind::Off | FileKind::Ply
        )
    }
}

/// A binary STL is 84 header bytes plus 50 bytes per triangle, with the count at offset 80.
fn binary_stl_size_matches(bytes: &[u8]) -> bool {
    match bytes.get(80..84) {
        Some(c) => {
            let count = u32::from_le_bytes([c[0], c[1], c[2], c[3]]) as u64;
            count > 0 && 84 + 50 * count == bytes.len() as u64
        }
        None => false,
    }
}

/// Most lines are G/M/T commands or `;` comments.
fn looks_like_gcode(text: &str) -> bool {
    let mut lines = 0;
    let mut gcode = 0;
    for line in text.lines().take(20) {
        let l = line.trim();
        if l.is_empty() {
            continue;
        }
        lines += 1;
        let first = l.as_bytes()[0].to_ascii_uppercase();
        if matches!(first, b';' | b'G' | b'M' | b'T' | b'N' | b'(') {
            gcode += 1;
        }
    }
    lines > 0 && gcode * 10 >= lines * 8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extension_wins_and_is_case_insensitive() {
        assert_eq!(
            FileKind::from_extension(Path::new("a/B.STL")),
            Some(FileKind::Stl)
        );
        assert_eq!(
            FileKind::from_extension(Path::new("x.3MF")),
            Some(FileKind::ThreeMf)
        );
        assert_eq!(FileKind::from_extension(Path::new("noext")), None);
    }

    #[test]
    fn content_sniffing() {
        assert_eq!(
            FileKind::sniff(b"solid x\nendsolid x\n"),
            Some(FileKind::Stl)
        );
        assert_eq!(
            FileKind::sniff(b"ply\nformat ascii 1.0\n"),
            Some(FileKind::Ply)
        );
        assert_eq!(FileKind::sniff(b"OFF\n3 1 0\n"), Some(FileKind::Off));
        assert_eq!(FileKind::sniff(b"PK\x03\x04rest"), Some(FileKind::ThreeMf));
        assert_eq!(
            FileKind::sniff(b";LAYER:0\nG1 X1 Y2\nG1 X2\n"),
            Some(FileKind::Gcode)
        );
        let mut bin = vec![0u8; 84 + 50];
        bin[80] = 1;
        assert_eq!(FileKind::sniff(&bin), Some(FileKind::Stl));
        assert_eq!(FileKind::sniff(b"\x00\x01 random"), None);
    }
}
