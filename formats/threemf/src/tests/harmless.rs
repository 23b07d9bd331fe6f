//! The two reading modes: one test per harmless defect kind, each showing that the default mode
//! loads the package with one warning naming the defect and the part, and strict mode refuses
//! it with a one-line error.

use super::*;

/// A root model with one tetrahedron (object 1) built once, `head` inserted before
/// `<resources>` and `resources` before the object.
fn model_with(head: &str, resources: &str) -> String {
    model_xml(
        "",
        &format!(r#"{resources}<object id="1">{TET}</object>"#),
        r#"<item objectid="1"/>"#,
    )
    .replacen("<resources>", &format!("{head}<resources>"), 1)
}

/// Asserts that the default mode reads `bytes` with exactly one warning containing `warning`
/// and strict mode refuses it with an error containing `error`; returns the package read.
fn harmless(bytes: &[u8], warning: &str, error: &str) -> Package {
    let package = match read(bytes, &Limits::default()) {
        Ok(p) => p,
        Err(e) => panic!("the default mode refused a harmless defect: {e}"),
    };
    assert_eq!(
        package.warnings.len(),
        1,
        "one warning expected: {:?}",
        package.warnings
    );
    assert!(
        package.warnings[0].contains(warning),
        "{:?} does not name {warning:?}",
        package.warnings[0]
    );
    let e = err_strict(bytes);
    assert!(e.contains(error), "strict: {e:?} does not name {error:?}");
    assert!(!e.contains('\n'), "one line: {e:?}");
    package
}

#[test]
fn duplicated_metadata_name_keeps_the_first() {
    let xml = model_with(
        r#"<metadata name="Title">first</metadata><metadata name="Title">second</metadata>"#,
        "",
    );
    let p = harmless(
        &pkg(&xml),
        r#"/3D/3dmodel.model:3:40: metadata name "Title" appears twice; the first is kept"#,
        r#"/3D/3dmodel.model:3:40: duplicated metadata name "Title""#,
    );
    assert_eq!(
        p.root().metadata,
        vec![Metadata {
            name: "Title".into(),
            value: "first".into()
        }]
    );
}

#[test]
fn duplicated_metadata_in_a_build_item_group_keeps_the_first() {
    let xml = model_xml(
        "",
        &format!(r#"<object id="1">{TET}</object>"#),
        r#"<item objectid="1"><metadatagroup><metadata name="Title">a</metadata><metadata name="Title">b</metadata></metadatagroup></item>"#,
    );
    harmless(
        &pkg(&xml),
        r#"metadata name "Title" appears twice; the first is kept"#,
        r#"duplicated metadata name "Title""#,
    );
}

#[test]
fn metadata_without_a_name_is_skipped() {
    let xml = model_with(
        r#"<metadata>orphan</metadata><metadata name="Title">t</metadata>"#,
        "",
    );
    let p = harmless(
        &pkg(&xml),
        "/3D/3dmodel.model:3:1: <metadata> has no name attribute; the entry is skipped",
        r#"/3D/3dmodel.model:3:1: <metadata> is missing required attribute "name""#,
    );
    let names: Vec<&str> = p.root().metadata.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["Title"]);
}

#[test]
fn empty_metadata_name_is_skipped() {
    let xml = model_with(r#"<metadata name=" ">x</metadata>"#, "");
    let p = harmless(
        &pkg(&xml),
        "metadata name is empty; the entry is skipped",
        "metadata name must not be empty",
    );
    assert!(p.root().metadata.is_empty());
}

#[test]
fn undefined_metadata_name_is_kept() {
    let undefined = "is neither a well-known name nor qualified by a declared namespace prefix";
    // Without a prefix (the validation suite's MUSTFAIL 3.4.1a and MUSTPASS 3.4.1c) ...
    let xml = model_with(r#"<metadata name="Undefined">x</metadata>"#, "");
    let p = harmless(
        &pkg(&xml),
        &format!(r#"metadata name "Undefined" {undefined}; the entry is kept"#),
        &format!(r#"<metadata> attribute name="Undefined": {undefined}"#),
    );
    assert_eq!(p.root().metadata[0].value, "x");
    // ... and with a prefix that no namespace declaration binds.
    let xml = model_with(r#"<metadata name="vendor:Key">x</metadata>"#, "");
    harmless(
        &pkg(&xml),
        &format!(r#"metadata name "vendor:Key" {undefined}"#),
        r#"attribute name="vendor:Key""#,
    );
    // A declared prefix is fine in both modes.
    let xml = model_xml(
        r#"xmlns:vendor="http://example.com/v""#,
        &format!(r#"<object id="1">{TET}</object>"#),
        r#"<item objectid="1"/>"#,
    )
    .replacen(
        "<resources>",
        r#"<metadata name="vendor:Key">x</metadata><resources>"#,
        1,
    );
    assert_eq!(err_strict(&pkg(&xml)), "Ok");
}

#[test]
fn duplicated_relationship_id_keeps_the_first() {
    let rels = RELS.replace(
        "</Relationships>",
        r#"<Relationship Target="/Metadata/t.png" Id="rel0" Type="http://schemas.openxmlformats.org/package/2006/relationships/metadata/thumbnail"/></Relationships>"#,
    );
    let xml = model_with("", "");
    let bytes = zip_of(&[
        ("[Content_Types].xml", CT.as_bytes()),
        ("_rels/.rels", rels.as_bytes()),
        ("3D/3dmodel.model", xml.as_bytes()),
        ("Metadata/t.png", b"\x89PNG"),
    ]);
    let p = harmless(
        &bytes,
        r#"/_rels/.rels: relationship Id "rel0" is used twice (the second targets /Metadata/t.png); the first is kept"#,
        r#"/_rels/.rels: relationship "rel0" to "/Metadata/t.png": relationship Id is used twice in this part"#,
    );
    assert_eq!(p.root_path, "/3D/3dmodel.model");
}

/// A package whose `.rels` has a second StartPart to `/3D/b.model`, holding `b`.
fn two_starts(b: &str, extra: &[(&str, &[u8])]) -> Vec<u8> {
    let rels = RELS.replace(
        "</Relationships>",
        r#"<Relationship Target="/3D/b.model" Id="rel1" Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/></Relationships>"#,
    );
    let root = model_with("", "");
    let mut entries: Vec<(&str, &[u8])> = vec![
        ("[Content_Types].xml", CT.as_bytes()),
        ("_rels/.rels", rels.as_bytes()),
        ("3D/3dmodel.model", root.as_bytes()),
        ("3D/b.model", b.as_bytes()),
    ];
    entries.extend_from_slice(extra);
    zip_of(&entries)
}

#[test]
fn second_start_part_to_a_complete_model_is_ignored() {
    let b = model_xml(
        "",
        &format!(r#"<object id="1" name="other">{TET}</object>"#),
        r#"<item objectid="1"/>"#,
    );
    let p = harmless(
        &two_starts(&b, &[]),
        r#"/_rels/.rels: 2 StartPart relationships of type 3dmodel; /3D/3dmodel.model is read and /3D/b.model (relationship "rel1") is ignored"#,
        "/_rels/.rels: 2 StartPart relationships of type 3dmodel (exactly one is required): /3D/3dmodel.model, /3D/b.model",
    );
    assert_eq!(p.models.len(), 1);
    assert_eq!(p.root().objects[0].name, None);
}

#[test]
fn second_start_part_that_is_not_a_complete_model_is_refused_in_both_modes() {
    // A texture used without a relationship of its own (MUSTFAIL 2.1.2's second part).
    let b = model_xml(
        "",
        &format!(
            r#"<m:texture2d id="5" path="/3D/t.png" contenttype="image/png"/><object id="1">{TET}</object>"#
        ),
        r#"<item objectid="1"/>"#,
    );
    let bytes = two_starts(&b, &[("3D/t.png", b"\x89PNG")]);
    for e in [err_of(&bytes), err_strict(&bytes)] {
        assert!(e.contains("2 StartPart relationships"), "{e}");
    }
    // A broken second model.
    let bytes = two_starts("<model/>", &[]);
    assert!(err_of(&bytes).contains("2 StartPart relationships"));
}

#[test]
fn unreferenced_duplicate_resource_id_keeps_the_first() {
    let xml = model_with(
        "",
        r##"<m:colorgroup id="7"><m:color color="#FF0000"/></m:colorgroup><m:colorgroup id="7"><m:color color="#00FF00"/><m:color color="#0000FF"/></m:colorgroup>"##,
    );
    let p = harmless(
        &pkg(&xml),
        "resource id 7 is already used by another resource in this part; nothing references it, the first definition is kept",
        "resource id 7 is already used by another resource in this part",
    );
    assert_eq!(p.root().color_groups.len(), 1);
    assert_eq!(p.root().color_groups[0].colors.len(), 1);
    // A duplicated object id is dropped the same way.
    let xml = model_with(
        "",
        &format!(r#"<object id="9">{TET}</object><object id="9">{TET}</object>"#),
    );
    let p = harmless(&pkg(&xml), "resource id 9", "resource id 9");
    assert_eq!(p.root().objects.len(), 2);
}

#[test]
fn referenced_duplicate_resource_id_is_refused_in_both_modes() {
    // The object's pid could mean either colour group.
    let xml = model_xml(
        "",
        &format!(
            r##"<m:colorgroup id="7"><m:color color="#FF0000"/></m:colorgroup><m:colorgroup id="7"><m:color color="#00FF00"/></m:colorgroup><object id="1" pid="7" pindex="0">{TET}</object>"##
        ),
        r#"<item objectid="1"/>"#,
    );
    for e in [err_of(&pkg(&xml)), err_strict(&pkg(&xml))] {
        assert!(
            e.contains("resource id 7 is already used by another resource in this part"),
            "{e}"
        );
        assert!(!e.contains("nothing references it"), "{e}");
    }
    // An object id used by a build item, likewise.
    let xml = model_xml(
        "",
        &format!(r#"<object id="1">{TET}</object><object id="1">{TET}</object>"#),
        r#"<item objectid="1"/>"#,
    );
    assert!(err_of(&pkg(&xml)).contains("resource id 1 is already used"));
}

#[test]
fn repeated_start_part_relationship_is_ignored() {
    let rels = RELS.replace(
        "</Relationships>",
        r#"<Relationship Target="/3D/3dmodel.model" Id="rel1" Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/></Relationships>"#,
    );
    let root = model_with("", "");
    let bytes = zip_of(&[
        ("[Content_Types].xml", CT.as_bytes()),
        ("_rels/.rels", rels.as_bytes()),
        ("3D/3dmodel.model", root.as_bytes()),
    ]);
    let p = harmless(
        &bytes,
        r#"/3D/3dmodel.model is read and /3D/3dmodel.model (relationship "rel1") is ignored"#,
        "2 StartPart relationships of type 3dmodel (exactly one is required)",
    );
    assert_eq!(p.models.len(), 1);
}
