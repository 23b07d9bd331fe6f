//! The objects part: PrusaSlicer's `Slic3r_PE_model.config` and OrcaSlicer's
//! `model_settings.config`, one XML layout with two spellings.

use std::borrow::Cow;

use quick_xml::events::BytesStart;

use super::{ObjectSettings, Setting, Volume, VolumeKind, VolumeMesh, error};
use crate::error::ThreeMfError;
use crate::xml::{Ev, Xml};
use crate::{Model, ObjectContent};

/// Volume metadata that describes the volume rather than setting anything.
const VOLUME_FACTS: &[&str] = &[
    "name",
    "volume_type",
    "modifier",
    "matrix",
    "source_file",
    "source_object_id",
    "source_volume_id",
    "source_offset_x",
    "source_offset_y",
    "source_offset_z",
    "source_in_inches",
    "source_in_meters",
    "source_is_builtin_volume",
    "mesh_shared",
];

/// Object metadata that describes the object rather than setting anything.
const OBJECT_FACTS: &[&str] = &["name", "module"];

/// Where the reader is inside `<config>`.
enum Scope {
    Object,
    /// A volume; `typed` once its type was stated (`volume_type` overrides the legacy
    /// `modifier` flag, whichever comes first).
    Volume {
        typed: bool,
    },
}

/// Reads the objects of the part `part`; unknown volume types are warned about in `warnings`.
pub(super) fn read(
    part: &str,
    bytes: &[u8],
    warnings: &mut Vec<String>,
) -> Result<Vec<ObjectSettings>, ThreeMfError> {
    let mut x = Xml::new(part, bytes)?;
    let mut objects: Vec<ObjectSettings> = Vec::new();
    let mut scope: Vec<Scope> = Vec::new();
    loop {
        let (e, empty) = match x.next()? {
            Ev::Start(e) => (e, false),
            Ev::Empty(e) => (e, true),
            Ev::End => {
                scope.pop();
                continue;
            }
            Ev::Text(_) => continue,
            Ev::Eof => break,
        };
        let line = x.loc().line as usize;
        let attrs = attributes(&x, &e)?;
        let get = |name: &str| attribute(&attrs, name);
        match (e.local_name().as_ref(), scope.last_mut()) {
            ("config", None) if !empty => continue,
            ("object", None) => {
                objects.push(ObjectSettings {
                    id: number(part, line, "object", "id", get("id"))?,
                    name: None,
                    settings: Vec::new(),
                    volumes: Vec::new(),
                    line,
                });
                if !empty {
                    scope.push(Scope::Object);
                }
                continue;
            }
            (local @ ("volume" | "part"), Some(Scope::Object)) => {
                let volume = volume(part, line, local == "part", &get, warnings)?;
                if let Some(object) = objects.last_mut() {
                    object.volumes.push(volume);
                }
                if !empty {
                    scope.push(Scope::Volume {
                        typed: get("subtype").is_some(),
                    });
                }
                continue;
            }
            ("metadata", Some(Scope::Object)) => {
                if let (Some(key), Some(object)) = (get("key"), objects.last_mut()) {
                    let value = get("value").unwrap_or_default();
                    if key == "name" {
                        object.name = Some(value.to_owned());
                    } else if !OBJECT_FACTS.contains(&key) {
                        object.settings.push(setting(key, value, line));
                    }
                }
            }
            ("metadata", Some(Scope::Volume { typed })) => {
                let volume = objects.last_mut().and_then(|o| o.volumes.last_mut());
                if let (Some(key), Some(volume)) = (get("key"), volume) {
                    let value = get("value").unwrap_or_default();
                    match key {
                        "name" => volume.name = Some(value.to_owned()),
                        "volume_type" => {
                            volume.kind = volume_kind(part, line, value, warnings);
                            *typed = true;
                        }
                        "modifier" if value == "1" && !*typed => {
                            volume.kind = VolumeKind::Modifier;
                        }
                        k if VOLUME_FACTS.contains(&k) => {}
                        k => volume.settings.push(setting(k, value, line)),
                    }
                }
            }
            _ => {}
        }
        if !empty {
            // Plates, assemblies, mesh statistics, text and shapes: not settings.
            x.skip()?;
        }
    }
    Ok(objects)
}

/// A `<volume firstid lastid>` (PrusaSlicer) or `<part id subtype>` (OrcaSlicer, `is_part`)
/// element with attributes `get`.
fn volume<'a>(
    part: &str,
    line: usize,
    is_part: bool,
    get: &impl Fn(&str) -> Option<&'a str>,
    warnings: &mut Vec<String>,
) -> Result<Volume, ThreeMfError> {
    let mesh = if is_part {
        VolumeMesh::Object(number(part, line, "part", "id", get("id"))?)
    } else {
        let first = number(part, line, "volume", "firstid", get("firstid"))?;
        let last = number(part, line, "volume", "lastid", get("lastid"))?;
        if last < first {
            return Err(error(
                part,
                line,
                format!("<volume> lastid {last} is before firstid {first}"),
            ));
        }
        VolumeMesh::Triangles { first, last }
    };
    let kind = match get("subtype") {
        Some(s) => volume_kind(part, line, s, warnings),
        None => VolumeKind::ModelPart,
    };
    Ok(Volume {
        mesh,
        kind,
        name: None,
        settings: Vec::new(),
        line,
    })
}

/// Checks that every triangle range lies inside its object's mesh, as PrusaSlicer does
/// before it splits the mesh into volumes. An object id the root model lacks is left to the
/// caller (its volumes describe nothing conduit prints).
pub(super) fn check_ranges(
    part: &str,
    objects: &[ObjectSettings],
    root: &Model,
) -> Result<(), ThreeMfError> {
    for o in objects {
        let Some(obj) = root.object(o.id) else {
            continue;
        };
        let count = match &obj.content {
            ObjectContent::Mesh(m) => m.triangles.len(),
            ObjectContent::Components(_) => 0,
        };
        for v in &o.volumes {
            if let VolumeMesh::Triangles { last, .. } = v.mesh
                && last as usize >= count
            {
                return Err(error(
                    part,
                    v.line,
                    format!(
                        "object {}: volume ends at triangle {last}, but the object's mesh has \
                         {count} triangles",
                        o.id
                    ),
                ));
            }
        }
    }
    Ok(())
}

fn setting(key: &str, value: &str, line: usize) -> Setting {
    Setting {
        key: key.to_owned(),
        value: value.to_owned(),
        line: Some(line),
    }
}

/// A volume type; one this reader does not know is a model part, with a warning.
fn volume_kind(part: &str, line: usize, name: &str, warnings: &mut Vec<String>) -> VolumeKind {
    VolumeKind::from_name(name).unwrap_or_else(|| {
        warnings.push(format!(
            "{part}:{line}: unknown volume type {name:?}, read as a model part"
        ));
        VolumeKind::ModelPart
    })
}

/// A required whole-number attribute.
pub(super) fn number(
    part: &str,
    line: usize,
    element: &str,
    attribute: &str,
    value: Option<&str>,
) -> Result<u32, ThreeMfError> {
    let v = value.ok_or_else(|| error(part, line, format!("<{element}> has no {attribute}")))?;
    v.trim().parse().map_err(|_| {
        error(
            part,
            line,
            format!("<{element}> {attribute}={v:?} is not a whole number"),
        )
    })
}

/// The value of the attribute `name` among `attrs` (from [`attributes`]).
pub(super) fn attribute<'a>(attrs: &'a [(String, String)], name: &str) -> Option<&'a str> {
    attrs
        .iter()
        .find(|(k, _)| k == name)
        .map(|(_, v)| v.as_str())
}

/// The attributes of `e` as (local name, value).
pub(super) fn attributes(
    x: &Xml<'_>,
    e: &BytesStart<'_>,
) -> Result<Vec<(String, String)>, ThreeMfError> {
    let mut out = Vec::new();
    x.attrs(e, |_, name, value: Cow<'_, str>| {
        out.push((name.to_owned(), value.into_owned()));
        Ok(())
    })?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    const PRUSA: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<config>
 <object id="1" instances_count="1">
  <metadata type="object" key="name" value="box"/>
  <metadata type="object" key="perimeters" value="4"/>
  <volume firstid="0" lastid="11">
   <metadata type="volume" key="name" value="box"/>
   <metadata type="volume" key="volume_type" value="ModelPart"/>
   <metadata type="volume" key="matrix" value="1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1"/>
   <mesh edges_fixed="0" degenerate_facets="0" facets_removed="0" facets_reversed="0" backwards_edges="0"/>
  </volume>
  <volume firstid="12" lastid="23">
   <metadata type="volume" key="name" value="dense"/>
   <metadata type="volume" key="modifier" value="1"/>
   <metadata type="volume" key="volume_type" value="ParameterModifier"/>
   <metadata type="volume" key="fill_density" value="80%"/>
  </volume>
  <volume firstid="24" lastid="35">
   <metadata type="volume" key="modifier" value="1"/>
  </volume>
 </object>
</config>
"#;

    #[test]
    fn prusa_volumes_types_and_settings() {
        let mut w = Vec::new();
        let objects = read("/m", PRUSA.as_bytes(), &mut w).unwrap();
        assert!(w.is_empty(), "{w:?}");
        let [o] = objects.as_slice() else {
            panic!("{objects:?}")
        };
        assert_eq!((o.id, o.name.as_deref(), o.line), (1, Some("box"), 3));
        assert_eq!(o.settings, [setting("perimeters", "4", 5)]);
        let kinds: Vec<_> = o.volumes.iter().map(|v| (v.mesh, v.kind)).collect();
        assert_eq!(
            kinds,
            [
                (
                    VolumeMesh::Triangles { first: 0, last: 11 },
                    VolumeKind::ModelPart
                ),
                (
                    VolumeMesh::Triangles {
                        first: 12,
                        last: 23
                    },
                    VolumeKind::Modifier
                ),
                // The legacy flag alone still makes a modifier.
                (
                    VolumeMesh::Triangles {
                        first: 24,
                        last: 35
                    },
                    VolumeKind::Modifier
                ),
            ]
        );
        assert_eq!(o.volumes[1].name.as_deref(), Some("dense"));
        assert_eq!(o.volumes[1].settings, [setting("fill_density", "80%", 16)]);
    }

    #[test]
    fn orca_parts_name_their_objects() {
        let src = r#"<?xml version="1.0" encoding="UTF-8"?>
<config>
  <object id="3">
    <metadata key="name" value="cube"/>
    <metadata key="wall_loops" value="5"/>
    <part id="1" subtype="normal_part">
      <metadata key="name" value="cube"/>
      <mesh_stat edges_fixed="0"/>
    </part>
    <part id="2" subtype="support_blocker"/>
    <part id="4" subtype="text_part"/>
  </object>
  <plate>
    <metadata key="plater_id" value="1"/>
  </plate>
</config>
"#;
        let mut w = Vec::new();
        let objects = read("/m", src.as_bytes(), &mut w).unwrap();
        assert_eq!(
            w,
            ["/m:11: unknown volume type \"text_part\", read as a model part"]
        );
        let o = &objects[0];
        assert_eq!(o.settings, [setting("wall_loops", "5", 5)]);
        let kinds: Vec<_> = o.volumes.iter().map(|v| (v.mesh, v.kind)).collect();
        assert_eq!(
            kinds,
            [
                (VolumeMesh::Object(1), VolumeKind::ModelPart),
                (VolumeMesh::Object(2), VolumeKind::SupportBlocker),
                (VolumeMesh::Object(4), VolumeKind::ModelPart),
            ]
        );
    }

    #[test]
    fn malformed_volumes_name_part_and_line() {
        let bad = |src: &str| {
            read("/m", src.as_bytes(), &mut Vec::new())
                .unwrap_err()
                .to_string()
        };
        assert_eq!(
            bad(
                "<config>\n<object id=\"1\">\n<volume firstid=\"5\" lastid=\"2\"/>\n</object>\n</config>"
            ),
            "/m:3: slicer settings: <volume> lastid 2 is before firstid 5"
        );
        assert_eq!(
            bad("<config>\n<object id=\"x\"/>\n</config>"),
            "/m:2: slicer settings: <object> id=\"x\" is not a whole number"
        );
        assert!(bad("<config><object id=\"1\">").starts_with("/m:1:"));
    }
}
