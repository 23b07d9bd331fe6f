//! OPC (Open Packaging Conventions) layer: the ZIP container with size limits enforced while
//! inflating, case-insensitive part names, `[Content_Types].xml` and `.rels` parts.

use std::collections::HashMap;
use std::io::{Cursor, Read};

use zip::ZipArchive;

use crate::Limits;
use crate::error::ThreeMfError;
use crate::limits::RATIO_CHECK_FLOOR;
use crate::xml::{Ev, Ns, Xml};

/// Content type of 3D model parts.
pub const CT_MODEL: &str = "application/vnd.ms-package.3dmanufacturing-3dmodel+xml";
/// Content type of relationship parts.
pub const CT_RELS: &str = "application/vnd.openxmlformats-package.relationships+xml";
/// StartPart relationship type of the 3D model.
pub const REL_MODEL: &str = "http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel";
/// Package or object thumbnail relationship type.
pub const REL_THUMBNAIL: &str =
    "http://schemas.openxmlformats.org/package/2006/relationships/metadata/thumbnail";
/// Print ticket relationship type.
pub const REL_PRINTTICKET: &str =
    "http://schemas.microsoft.com/3dmanufacturing/2013/01/printticket";
/// Texture relationship type.
pub const REL_TEXTURE: &str = "http://schemas.microsoft.com/3dmanufacturing/2013/01/3dtexture";

/// One `<Relationship>`.
#[derive(Debug, Clone)]
pub struct Relationship {
    /// `Id`.
    pub id: String,
    /// `Type`.
    pub kind: String,
    /// `Target` as written.
    pub target: String,
    /// Resolved absolute part name (`None` for external targets).
    pub part: Option<String>,
}

/// The opened package.
pub struct Archive<'a> {
    zip: ZipArchive<Cursor<&'a [u8]>>,
    /// Normalised (decoded, lower-case, no leading `/`) name -> zip index.
    index: HashMap<String, usize>,
    limits: &'a Limits,
    inflated: u64,
    total_len: u64,
    defaults: HashMap<String, String>,
    overrides: HashMap<String, String>,
}

/// Percent-decodes an OPC part name or URI path (invalid escapes are kept literally).
pub fn percent_decode(s: &str) -> String {
    if !s.contains('%') {
        return s.to_string();
    }
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' && i + 2 < b.len() {
            let hex = std::str::from_utf8(&b[i + 1..i + 3]).ok();
            if let Some(v) = hex.and_then(|h| u8::from_str_radix(h, 16).ok()) {
                out.push(v);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8(out).unwrap_or_else(|_| s.to_string())
}

/// Lookup key of a part name: decoded, without leading `/`, ASCII-lower-cased (OPC part names
/// compare case-insensitively).
pub fn key(part: &str) -> String {
    percent_decode(part.trim_start_matches('/')).to_lowercase()
}

/// Resolves a relationship target against the source part (`/` for package relationships).
/// Returns `None` for targets that are absolute URIs (external).
pub fn resolve_target(source_part: &str, target: &str) -> Option<String> {
    let t = target.split(['#', '?']).next().unwrap_or("");
    // A scheme (`http:`, `file:`, a drive letter `C:`) before any '/' makes it an absolute URI.
    if let Some(colon) = t.find(':')
        && !t[..colon].contains('/')
    {
        return None;
    }
    let base_dir = match source_part.rfind('/') {
        Some(i) => &source_part[..i],
        None => "",
    };
    let joined = if t.starts_with('/') {
        t.to_string()
    } else {
        format!("{base_dir}/{t}")
    };
    let mut segs: Vec<&str> = Vec::new();
    for seg in joined.split('/') {
        match seg {
            "" | "." => {}
            ".." => {
                segs.pop()?;
            }
            s => segs.push(s),
        }
    }
    Some(format!("/{}", segs.join("/")))
}

/// The `.rels` part holding the relationships of `part` (`/` for the package).
pub fn rels_part_of(part: &str) -> String {
    if part == "/" {
        return "/_rels/.rels".to_string();
    }
    match part.rfind('/') {
        Some(i) => format!("{}/_rels/{}.rels", &part[..i], &part[i + 1..]),
        None => format!("/_rels/{part}.rels"),
    }
}

impl<'a> Archive<'a> {
    /// Opens the ZIP container and reads `[Content_Types].xml`.
    pub fn open(bytes: &'a [u8], limits: &'a Limits) -> Result<Archive<'a>, ThreeMfError> {
        let zip =
            ZipArchive::new(Cursor::new(bytes)).map_err(|source| ThreeMfError::Zip { source })?;
        if zip.len() > limits.max_archive_entries {
            return Err(ThreeMfError::LimitExceeded {
                part: "/".into(),
                limit: "max_archive_entries",
                max: limits.max_archive_entries as u64,
                found: zip.len() as u64,
            });
        }
        let mut index = HashMap::new();
        for i in 0..zip.len() {
            let Some(name) = zip.name_for_index(i) else {
                continue;
            };
            let name = name.map_err(|source| ThreeMfError::Zip { source })?;
            if name.ends_with('/') {
                continue; // folder entry
            }
            if index.insert(key(&name), i).is_some() {
                return Err(ThreeMfError::PartName {
                    part: format!("/{name}"),
                    reason: "two ZIP entries name the same part (part names are case-insensitive)",
                });
            }
        }
        let mut a = Archive {
            zip,
            index,
            limits,
            inflated: 0,
            total_len: bytes.len() as u64,
            defaults: HashMap::new(),
            overrides: HashMap::new(),
        };
        a.read_content_types()?;
        Ok(a)
    }

    /// Whether a part exists.
    pub fn exists(&self, part: &str) -> bool {
        self.index.contains_key(&key(part))
    }

    /// The content type of a part (override, else default by extension).
    pub fn content_type(&self, part: &str) -> Option<&str> {
        let k = key(part);
        if let Some(ct) = self.overrides.get(&k) {
            return Some(ct);
        }
        let ext = k.rsplit_once('.').map(|(_, e)| e)?;
        if ext.contains('/') {
            return None;
        }
        self.defaults.get(ext).map(String::as_str)
    }

    /// Inflates a part, enforcing the total-size and compression-ratio limits on the bytes
    /// actually produced. Returns `Ok(None)` if the part does not exist.
    pub fn read(&mut self, part: &str) -> Result<Option<Vec<u8>>, ThreeMfError> {
        let Some(&i) = self.index.get(&key(part)) else {
            return Ok(None);
        };
        let limits = self.limits;
        let mut f = self
            .zip
            .by_index(i)
            .map_err(|source| ThreeMfError::Zip { source })?;
        // The header's compressed size bounds what the decoder may consume; it can not exceed the
        // archive itself.
        let compressed = f.compressed_size().min(self.total_len).max(1);
        let budget = limits.max_uncompressed_bytes.saturating_sub(self.inflated);
        let mut limited = (&mut f).take(budget.saturating_add(1));
        let mut out = Vec::new();
        let mut chunk = [0u8; 64 * 1024];
        loop {
            let n = match limited.read(&mut chunk) {
                Ok(0) => break,
                Ok(n) => n,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                Err(e) => return Err(ThreeMfError::io(part, e)),
            };
            out.extend_from_slice(&chunk[..n]);
            let produced = out.len() as u64;
            if produced > budget {
                return Err(ThreeMfError::LimitExceeded {
                    part: part.to_string(),
                    limit: "max_uncompressed_bytes",
                    max: limits.max_uncompressed_bytes,
                    found: self.inflated + produced,
                });
            }
            if produced > RATIO_CHECK_FLOOR && produced / compressed > limits.max_compression_ratio
            {
                return Err(ThreeMfError::CompressionRatio {
                    part: part.to_string(),
                    compressed,
                    inflated: produced,
                    max_ratio: limits.max_compression_ratio,
                });
            }
        }
        self.inflated += out.len() as u64;
        Ok(Some(out))
    }

    fn read_content_types(&mut self) -> Result<(), ThreeMfError> {
        let part = "/[Content_Types].xml";
        let Some(bytes) = self.read(part)? else {
            return Err(ThreeMfError::MissingPart {
                part: part.into(),
                needed_for: "every OPC package declares its content types".into(),
            });
        };
        let mut x = Xml::new(part, &bytes)?;
        let mut first = true;
        loop {
            let e = match x.next()? {
                Ev::Start(e) | Ev::Empty(e) => e,
                Ev::Eof => break,
                _ => continue,
            };
            let local = e.local_name();
            if first {
                first = false;
                if local.as_ref() != "Types" {
                    return Err(x.xml_err("root element of [Content_Types].xml must be <Types>"));
                }
                continue;
            }
            if !matches!(local.as_ref(), "Default" | "Override") {
                continue;
            }
            let mut name = None;
            let mut ct = None;
            x.attrs(&e, |ns, l, v| {
                if ns == Ns::None {
                    match l {
                        "Extension" | "PartName" => name = Some(v.into_owned()),
                        "ContentType" => ct = Some(v.into_owned()),
                        _ => {}
                    }
                }
                Ok(())
            })?;
            let (Some(name), Some(ct)) = (name, ct) else {
                return Err(
                    x.xml_err("<Default>/<Override> needs Extension/PartName and ContentType")
                );
            };
            let ct = ct.trim().to_ascii_lowercase();
            if local.as_ref() == "Default" {
                self.defaults.insert(name.to_lowercase(), ct);
            } else {
                self.overrides.insert(key(&name), ct);
            }
        }
        Ok(())
    }

    /// Reads the relationships of `source` (`/` for the package). A missing `.rels` part gives
    /// an empty list. Duplicate ids are rejected.
    pub fn relationships(&mut self, source: &str) -> Result<Vec<Relationship>, ThreeMfError> {
        let rels_part = rels_part_of(source);
        let Some(bytes) = self.read(&rels_part)? else {
            return Ok(Vec::new());
        };
        let mut x = Xml::new(&rels_part, &bytes)?;
        let mut out: Vec<Relationship> = Vec::new();
        loop {
            let (e, empty) = match x.next()? {
                Ev::Start(e) => (e, false),
                Ev::Empty(e) => (e, true),
                Ev::Eof => break,
                _ => continue,
            };
            if e.local_name().as_ref() != "Relationship" {
                continue;
            }
            let (mut id, mut kind, mut target, mut external) = (None, None, None, false);
            x.attrs(&e, |ns, l, v| {
                if ns == Ns::None {
                    match l {
                        "Id" => id = Some(v.into_owned()),
                        "Type" => kind = Some(v.into_owned()),
                        "Target" => target = Some(v.into_owned()),
                        "TargetMode" => external = v.eq_ignore_ascii_case("external"),
                        _ => {}
                    }
                }
                Ok(())
            })?;
            let (Some(id), Some(kind), Some(target)) = (id, kind, target) else {
                return Err(x.xml_err("<Relationship> needs Id, Type and Target"));
            };
            let part = if external {
                None
            } else {
                resolve_target(source, &target)
            };
            out.push(Relationship {
                id,
                kind,
                target,
                part,
            });
            if !empty {
                x.skip()?;
            }
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn targets() {
        assert_eq!(
            resolve_target("/3D/3dmodel.model", "../Metadata/a.png").as_deref(),
            Some("/Metadata/a.png")
        );
        assert_eq!(
            resolve_target("/", "/3D/3dmodel.model").as_deref(),
            Some("/3D/3dmodel.model")
        );
        assert_eq!(resolve_target("/3D/x.model", "C:/Metadata/t.png"), None);
        assert_eq!(resolve_target("/", "http://x/y"), None);
        assert_eq!(
            rels_part_of("/3D/3dmodel.model"),
            "/3D/_rels/3dmodel.model.rels"
        );
        assert_eq!(key("/3D/Textures/A%20b.PNG"), "3d/textures/a b.png");
    }
}
