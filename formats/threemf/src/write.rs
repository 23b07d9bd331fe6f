//! The writer: one root model part, deterministic bytes, validated by the reader before any
//! byte reaches the sink.

use std::collections::{HashMap, HashSet};
use std::fmt::Write as _;
use std::io::{Cursor, Seek, Write};

use quick_xml::escape::escape;
use zip::write::SimpleFileOptions;
use zip::{CompressionMethod, DateTime, ZipWriter};

use crate::error::ThreeMfError;
use crate::model::{Mesh, Model, Object, ObjectContent};
use crate::opc;
use crate::xml::{NS_CORE, NS_CT, NS_MATERIAL, NS_RELS};
use crate::{Limits, ReadOptions, read_with};

/// Part name of the model the writer produces.
pub const ROOT_MODEL_PATH: &str = "/3D/3dmodel.model";

/// Writes `model` as a 3MF package with a single root model part.
///
/// The output is deterministic: fixed entry order, fixed timestamps (1980-01-01), fixed
/// compression. Coordinates and transform values are written so they read back exactly: the
/// shortest `f32` spelling when the value is an `f32`, else the shortest `f64` spelling, never
/// in exponent notation. `required_extensions` is honoured only for the materials extension,
/// the one whose markup the writer emits; other entries are dropped. Before anything is
/// written to `w`, the package is read back with [`read_with`] in strict mode; a model that
/// would produce an invalid file (dangling references, duplicate ids, out-of-range indices,
/// non-finite numbers, `path`s to other parts) is refused with [`ThreeMfError::Unwritable`]
/// and `w` is left untouched.
pub fn write<W: Write + Seek>(mut w: W, model: &Model) -> Result<(), ThreeMfError> {
    let xml = model_xml(model)?;
    let mut buf = Cursor::new(Vec::new());
    {
        let zerr = |e: zip::result::ZipError| ThreeMfError::Io {
            part: "<output>".into(),
            source: std::io::Error::other(e),
        };
        let mut zw = ZipWriter::new(&mut buf);
        let opts = SimpleFileOptions::default()
            .compression_method(CompressionMethod::Deflated)
            .last_modified_time(DateTime::DEFAULT)
            .unix_permissions(0o644);
        let files: [(&str, String); 3] = [
            ("[Content_Types].xml", content_types()),
            ("_rels/.rels", root_rels()),
            (&ROOT_MODEL_PATH[1..], xml),
        ];
        for (name, body) in files {
            zw.start_file(name, opts).map_err(zerr)?;
            zw.write_all(body.as_bytes())
                .map_err(|e| ThreeMfError::io(name, e))?;
        }
        zw.finish().map_err(zerr)?;
    }
    let bytes = buf.into_inner();
    let limits = Limits {
        max_uncompressed_bytes: u64::MAX,
        max_compression_ratio: u64::MAX,
        max_vertices: usize::MAX,
        max_triangles: usize::MAX,
        max_objects: usize::MAX,
        ..Limits::default()
    };
    if let Err(e) = read_with(&bytes, &limits, ReadOptions { strict: true }) {
        return Err(ThreeMfError::Unwritable {
            reason: format!("the written package would not be valid: {e}"),
        });
    }
    w.write_all(&bytes)
        .map_err(|e| ThreeMfError::io("<output>", e))?;
    w.flush().map_err(|e| ThreeMfError::io("<output>", e))
}

fn content_types() -> String {
    format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<Types xmlns=\"{NS_CT}\">\
         <Default Extension=\"rels\" ContentType=\"{}\"/>\
         <Default Extension=\"model\" ContentType=\"{}\"/></Types>\n",
        opc::CT_RELS,
        opc::CT_MODEL
    )
}

fn root_rels() -> String {
    format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<Relationships xmlns=\"{NS_RELS}\">\
         <Relationship Target=\"{ROOT_MODEL_PATH}\" Id=\"rel0\" Type=\"{}\"/></Relationships>\n",
        opc::REL_MODEL
    )
}

/// Writes a number so that it round-trips: the shortest `f32` spelling when the value is
/// exactly an `f32` (parsing it as `f32` gives the value back, as lib3mf does), else the
/// shortest `f64` spelling (parsing it as `f64` gives the value back). Note that an f32-exact
/// value such as `0.1f32 as f64` is written `0.1`, which an `f64` reader (this crate) reads as
/// `0.1f64`: within one f32 ulp, but not bit-identical. Rust's `Display`
/// for floats never uses exponent notation, which keeps every 3MF consumer happy.
pub fn format_number(v: f64, out: &mut String) {
    let f = v as f32;
    // Ignoring the fmt::Result: writing to a String cannot fail.
    if f64::from(f) == v {
        let _ = write!(out, "{f}");
    } else {
        let _ = write!(out, "{v}");
    }
}

fn unwritable(reason: impl Into<String>) -> ThreeMfError {
    ThreeMfError::Unwritable {
        reason: reason.into(),
    }
}

fn check_path(path: &Option<String>, what: &str) -> Result<(), ThreeMfError> {
    match path {
        Some(p) if opc::key(p) != opc::key(ROOT_MODEL_PATH) => Err(unwritable(format!(
            "{what} references part {p}; the writer produces a single model part"
        ))),
        _ => Ok(()),
    }
}

fn matrix(m: &[f64; 12], out: &mut String) -> Result<(), ThreeMfError> {
    for (i, v) in m.iter().enumerate() {
        if !v.is_finite() {
            return Err(unwritable("transform with a non-finite value"));
        }
        if i > 0 {
            out.push(' ');
        }
        format_number(*v, out);
    }
    Ok(())
}

fn color(c: [u8; 4]) -> String {
    format!("#{:02X}{:02X}{:02X}{:02X}", c[0], c[1], c[2], c[3])
}

/// Objects in an order where every component's object comes before its user.
fn object_order(model: &Model) -> Result<Vec<usize>, ThreeMfError> {
    let by_id: HashMap<u32, usize> = model
        .objects
        .iter()
        .enumerate()
        .map(|(i, o)| (o.id, i))
        .collect();
    let mut done = vec![false; model.objects.len()];
    let mut on_stack = vec![false; model.objects.len()];
    let mut order = Vec::with_capacity(model.objects.len());
    for start in 0..model.objects.len() {
        let mut stack: Vec<(usize, usize)> = vec![(start, 0)];
        while let Some(&mut (i, ref mut next)) = stack.last_mut() {
            if done[i] {
                stack.pop();
                continue;
            }
            on_stack[i] = true;
            let deps: &[crate::Component] = match &model.objects[i].content {
                ObjectContent::Components(c) => c,
                ObjectContent::Mesh(_) => &[],
            };
            if *next < deps.len() {
                let id = deps[*next].object_id;
                *next += 1;
                if let Some(&j) = by_id.get(&id) {
                    if on_stack[j] && !done[j] {
                        return Err(unwritable(format!(
                            "object {} contains itself through its components",
                            model.objects[j].id
                        )));
                    }
                    if !done[j] {
                        stack.push((j, 0));
                    }
                }
            } else {
                done[i] = true;
                on_stack[i] = false;
                order.push(i);
                stack.pop();
            }
        }
    }
    Ok(order)
}

/// Serialises the model part.
fn model_xml(model: &Model) -> Result<String, ThreeMfError> {
    let nverts: usize = model
        .objects
        .iter()
        .map(|o| match &o.content {
            ObjectContent::Mesh(m) => m.vertices.len() + m.triangles.len(),
            ObjectContent::Components(c) => c.len(),
        })
        .sum();
    let mut s = String::with_capacity(1024 + nverts.min(1 << 24) * 64);
    s.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    model_start_tag(model, &mut s);
    metadata_xml(model, &mut s)?;
    s.push_str(" <resources>\n");
    materials_xml(model, &mut s);
    for i in object_order(model)? {
        object_xml(&model.objects[i], &mut s)?;
    }
    s.push_str(" </resources>\n");
    build_xml(model, &mut s)?;
    s.push_str("</model>\n");
    Ok(s)
}

/// Writes the `<model>` start tag: unit, language, the namespaces the content uses and the
/// required extensions.
fn model_start_tag(model: &Model, s: &mut String) {
    let mut prefixes: Vec<(String, &str)> = Vec::new(); // (prefix, uri)
    let mut required = Vec::new();
    // Only extensions whose markup this writer emits can be required: the materials extension.
    // Others (production, slice, beam lattice, ...) are dropped, since their content is not
    // written; requiring production without its UUIDs would even make the file invalid.
    if model.required_extensions.iter().any(|u| u == NS_MATERIAL) {
        prefixes.push(("m".into(), NS_MATERIAL));
        required.push("m".to_string());
    }
    if !model.color_groups.is_empty() && !prefixes.iter().any(|(p, _)| p == "m") {
        prefixes.push(("m".into(), NS_MATERIAL));
    }
    // Namespace-qualified metadata names need their prefix declared.
    let mut meta_ns: Vec<String> = Vec::new();
    for m in &model.metadata {
        if let Some((prefix, _)) = m.name.split_once(':')
            && !prefix.is_empty()
            && !prefixes.iter().any(|(p, _)| p == prefix)
            && !meta_ns.iter().any(|p| p == prefix)
        {
            meta_ns.push(prefix.to_string());
        }
    }
    let _ = write!(s, "<model unit=\"{}\"", model.unit.as_str());
    if let Some(lang) = &model.language {
        let _ = write!(s, " xml:lang=\"{}\"", escape(lang.as_str()));
    }
    let _ = write!(s, " xmlns=\"{NS_CORE}\"");
    for (p, uri) in &prefixes {
        let _ = write!(s, " xmlns:{p}=\"{}\"", escape(*uri));
    }
    for p in &meta_ns {
        let _ = write!(
            s,
            " xmlns:{p}=\"urn:conduit:metadata:{}\"",
            escape(p.as_str())
        );
    }
    if !required.is_empty() {
        let _ = write!(s, " requiredextensions=\"{}\"", required.join(" "));
    }
    s.push_str(">\n");
}

/// Writes the `<metadata>` elements; names must be unique and well-known or
/// namespace-qualified.
fn metadata_xml(model: &Model, s: &mut String) -> Result<(), ThreeMfError> {
    let mut names = HashSet::new();
    for m in &model.metadata {
        if !names.insert(m.name.as_str()) {
            return Err(unwritable(format!("duplicated metadata name {:?}", m.name)));
        }
        if !m.name.contains(':') && !crate::read::WELL_KNOWN_METADATA.contains(&m.name.as_str()) {
            return Err(unwritable(format!(
                "metadata name {:?} is neither a well-known 3MF name nor namespace-qualified \
                 (lib3mf rejects it in strict mode); qualify it, e.g. \"vendor:{}\"",
                m.name, m.name
            )));
        }
        let _ = writeln!(
            s,
            " <metadata name=\"{}\">{}</metadata>",
            escape(m.name.as_str()),
            escape(m.value.as_str())
        );
    }
    Ok(())
}

/// Writes the base material groups and the colour groups.
fn materials_xml(model: &Model, s: &mut String) {
    for b in &model.base_materials {
        let _ = writeln!(s, "  <basematerials id=\"{}\">", b.id);
        for m in &b.materials {
            let _ = writeln!(
                s,
                "   <base name=\"{}\" displaycolor=\"{}\"/>",
                escape(m.name.as_str()),
                color(m.display_color)
            );
        }
        s.push_str("  </basematerials>\n");
    }
    for g in &model.color_groups {
        let _ = writeln!(s, "  <m:colorgroup id=\"{}\">", g.id);
        for c in &g.colors {
            let _ = writeln!(s, "   <m:color color=\"{}\"/>", color(*c));
        }
        s.push_str("  </m:colorgroup>\n");
    }
}

/// Writes one `<object>` with its mesh or components.
fn object_xml(o: &Object, s: &mut String) -> Result<(), ThreeMfError> {
    let _ = write!(s, "  <object id=\"{}\" type=\"{}\"", o.id, o.kind.as_str());
    if let Some(n) = &o.name {
        let _ = write!(s, " name=\"{}\"", escape(n.as_str()));
    }
    if let Some(p) = o.pid {
        let _ = write!(s, " pid=\"{p}\"");
    }
    if let Some(p) = o.pindex {
        let _ = write!(s, " pindex=\"{p}\"");
    }
    s.push_str(">\n");
    match &o.content {
        ObjectContent::Mesh(m) => mesh_xml(o.id, m, s)?,
        ObjectContent::Components(cs) => {
            s.push_str("   <components>\n");
            for c in cs {
                check_path(&c.path, "a component")?;
                let _ = write!(s, "    <component objectid=\"{}\"", c.object_id);
                if let Some(t) = &c.transform {
                    s.push_str(" transform=\"");
                    matrix(t, s)?;
                    s.push('"');
                }
                s.push_str("/>\n");
            }
            s.push_str("   </components>\n");
        }
    }
    s.push_str("  </object>\n");
    Ok(())
}

/// Writes the `<mesh>` of object `id`: its vertices (all coordinates finite) and triangles.
fn mesh_xml(id: u32, m: &Mesh, s: &mut String) -> Result<(), ThreeMfError> {
    s.push_str("   <mesh>\n    <vertices>\n");
    for v in &m.vertices {
        if !v.iter().all(|c| c.is_finite()) {
            return Err(unwritable(format!(
                "object {id}: vertex with a non-finite coordinate"
            )));
        }
        s.push_str("     <vertex x=\"");
        format_number(v[0], s);
        s.push_str("\" y=\"");
        format_number(v[1], s);
        s.push_str("\" z=\"");
        format_number(v[2], s);
        s.push_str("\"/>\n");
    }
    s.push_str("    </vertices>\n    <triangles>\n");
    for t in &m.triangles {
        let _ = write!(
            s,
            "     <triangle v1=\"{}\" v2=\"{}\" v3=\"{}\"",
            t.v[0], t.v[1], t.v[2]
        );
        if let Some(p) = t.pid {
            let _ = write!(s, " pid=\"{p}\"");
        }
        for (k, p) in t.p.iter().enumerate() {
            if let Some(p) = p {
                let _ = write!(s, " p{}=\"{p}\"", k + 1);
            }
        }
        s.push_str("/>\n");
    }
    s.push_str("    </triangles>\n   </mesh>\n");
    Ok(())
}

/// Writes the `<build>` element with its items.
fn build_xml(model: &Model, s: &mut String) -> Result<(), ThreeMfError> {
    s.push_str(" <build>\n");
    for item in &model.build {
        check_path(&item.path, "a build item")?;
        let _ = write!(s, "  <item objectid=\"{}\"", item.object_id);
        if let Some(t) = &item.transform {
            s.push_str(" transform=\"");
            matrix(t, s)?;
            s.push('"');
        }
        if let Some(pn) = &item.part_number {
            let _ = write!(s, " partnumber=\"{}\"", escape(pn.as_str()));
        }
        s.push_str("/>\n");
    }
    s.push_str(" </build>\n");
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_round_trip_without_exponent() {
        for v in [
            0.0,
            -0.0,
            1.0,
            0.1,
            0.1f32 as f64,
            25.4,
            1e-7,
            123456789.123,
            -3.0e12,
            f64::from(f32::MAX),
            1.0 / 3.0,
        ] {
            let mut s = String::new();
            format_number(v, &mut s);
            assert!(!s.contains('e') && !s.contains('E'), "{s}");
            // f32-exact values round-trip through an f32 reader (lib3mf stores floats),
            // everything else through an f64 reader.
            if f64::from(v as f32) == v {
                let back: f32 = s.parse().unwrap_or(f32::NAN);
                assert_eq!(f64::from(back).to_bits(), v.to_bits(), "{v} -> {s}");
            } else {
                let back: f64 = s.parse().unwrap_or(f64::NAN);
                assert_eq!(back.to_bits(), v.to_bits(), "{v} -> {s}");
            }
        }
        let mut s = String::new();
        format_number(0.1f32 as f64, &mut s);
        assert_eq!(s, "0.1");
    }
}
