//! 3MF (3D Manufacturing Format) core-spec reader and writer.
//!
//! Part of conduit's `formats/` layer: it describes the file and has no dependency on the
//! pipeline. [`read`] turns package bytes into a [`Package`] of [`Model`]s; [`Package::flatten`]
//! resolves the build into plain millimetre meshes ([`FlatMesh`]); [`write()`] produces a
//! single-part package that lib3mf reads without warnings (checked in strict mode with
//! `bench/lib3mf_check.py`). [`read_with`] and [`ReadOptions`] choose between the default mode,
//! which reads past harmless defects with a warning each, and the strict mode.
//!
//! # What is read
//! - **OPC**: `[Content_Types].xml`, `_rels/.rels` and the model parts' `.rels`; one
//!   3D model StartPart; 3MF relationships (model, thumbnail, print ticket, texture) must target
//!   existing parts inside the package; at most one print ticket per part; part names compare
//!   case-insensitively (and percent-decoded); model parts need the 3D model content type;
//!   relationship Ids are unique per `.rels` part.
//! - **XML**: UTF-8 only (no UTF-16, no other declared encoding), no DTD, one root element,
//!   namespaces resolved; duplicated attributes and `xml:space` are rejected; numbers are
//!   `xs:double` with `.` decimals (a comma, `NaN`, `INF` or text is an error).
//! - **Extensions** accepted in `requiredextensions` (others are errors naming the namespace):
//!   core, materials (`material/2015/02`, parsed and validated), production
//!   (`production/2015/06`: `p:path` to other model parts is followed), slice
//!   (`slice/2015/07`: stacks and `sliceref`s validated, slices skipped), beam lattice
//!   (`beamlattice/2017/02` and balls `2020/07`: skipped), and, recognised but not
//!   interpreted (a warning is recorded): secure content `2019/04`, the volumetric
//!   `2015/02` draft and triangle sets `2021/07`. The legacy 0.93 namespace (`2013/01`) is read
//!   as core with a warning.
//! - Markup in unknown namespaces is ignored, except in unknown namespaces under the 3MF URI
//!   spaces (`schemas.microsoft.com/3dmanufacturing/`, `schemas.3mf.io/3dmanufacturing/`) that
//!   are not declared `mc:Ignorable`, which are errors. Unknown elements in the core namespace
//!   are skipped with a warning.
//! - **Model rules**: unit, object types, metadata (name required, unique per scope,
//!   well-known or namespace-qualified: see the two modes below), one `<resources>` and (root
//!   part) one `<build>`; resource ids unique across all resource kinds;
//!   build items reference existing objects not of type `other`; vertex indices in range and
//!   distinct; `pid`/`pindex`/`p1..p3` resolve to property groups defined earlier and stay in
//!   range; colour groups, textures (content type `image/png`/`image/jpeg`, part present),
//!   texture groups, composite materials (on a basematerials group) and multiproperties (no
//!   multiproperties inside, at most one colour group and one base/composite group, blend
//!   methods) are validated; component cycles are errors; slice stacks referenced by a
//!   `sliceref` must not contain `sliceref`s themselves.
//! - **Warnings, not errors** ([`Package::warnings`], at most 1000 per package): unknown core
//!   elements, the legacy namespace, extensions recognised but not interpreted, thumbnails and textures
//!   without their relationship, beam-lattice attribute problems, and two defects found in the
//!   3MF Consortium's own must-pass files (`<multi>` written in the core namespace,
//!   multiproperties layers naming a `texture2d` or indexing out of range) are warnings in both
//!   modes.
//!
//! - **Slicer settings** ([`Package::slicer`], [`SlicerSettings`]): the profile, per-object
//!   settings and volume types PrusaSlicer (`Metadata/Slic3r_PE*.config`) and OrcaSlicer
//!   (`Metadata/project_settings.config`, `model_settings.config`) store beside the model,
//!   and the colour changes, pauses and custom G-code of their layer sliders;
//!   [`FlatMesh::triangle_sources`] ties each flattened triangle to its volume.
//!
//! # Two modes: default and strict
//! [`read`] (and [`read_with`] with [`ReadOptions::default`]) reads past *harmless defects*,
//! the ones lib3mf's lenient mode and PrusaSlicer accept, with one warning each naming the
//! defect, the part (and line) and what was kept; [`ReadOptions::strict`] makes each of them
//! an error, as the validation suite's MUSTFAIL files demand:
//! - a `<metadata>` without a name, or with an empty one (the entry is skipped);
//! - a metadata name used twice in one scope (the first entry is kept);
//! - a metadata name neither well-known nor qualified by a declared namespace prefix (kept;
//!   MUSTFAIL 3.4.1a. MUSTPASS 3.4.1c has the very same defect, so strict mode refuses it too,
//!   as lib3mf's strict mode does);
//! - a relationship Id used twice in one `.rels` part (the first is kept);
//! - more than one StartPart relationship: the first target is the root; a further one is
//!   ignored when it targets a part of the payload or a complete model part that reads without
//!   an error or a warning, and refused otherwise (MUSTFAIL 2.1.2's second part uses textures
//!   through the first part's relationships);
//! - a resource id used twice in one part when nothing references it (the first definition is
//!   kept; a referenced duplicate is refused in both modes, as either definition could be
//!   meant).
//!
//! # Writing
//! [`write()`] emits `[Content_Types].xml`, `_rels/.rels` and `/3D/3dmodel.model` with unit,
//! language, metadata, base materials, colour groups, objects (mesh or components, ordered so
//! components follow the objects they use) and the build. Bytes are deterministic. Numbers use
//! the shortest `f32` spelling for f32-exact values, else the shortest `f64` one, never an
//! exponent. The package is read back with [`read_with`] in strict mode before anything reaches
//! the sink, so an invalid model is refused with [`ThreeMfError::Unwritable`]; metadata names
//! must be well-known or namespace-qualified (lib3mf's strict mode rejects others); `path`s to
//! other parts are refused; only the materials extension can be required.
//!
//! # Limits
//! [`Limits`] bounds entries, inflated bytes (total, and compression ratio per part, counted
//! while inflating, never trusting ZIP headers), vertices, triangles, resources and component
//! depth; defaults are documented on each field. Nothing is allocated in proportion to a
//! count the file merely claims.
//!
//! # Example
//! ```
//! use conduit_3mf::{Model, Object, ObjectContent, Mesh, Triangle, BuildItem, read, write, Limits};
//! let mesh = Mesh {
//!     vertices: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
//!     triangles: [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]]
//!         .map(|v| Triangle { v, ..Default::default() })
//!         .to_vec(),
//! };
//! let model = Model {
//!     objects: vec![Object { id: 1, name: Some("tet".into()), kind: Default::default(),
//!                            pid: None, pindex: None, content: ObjectContent::Mesh(mesh) }],
//!     build: vec![BuildItem { object_id: 1, path: None, transform: None, part_number: None }],
//!     ..Model::default()
//! };
//! let mut bytes = std::io::Cursor::new(Vec::new());
//! write(&mut bytes, &model)?;
//! let package = read(bytes.get_ref(), &Limits::default())?;
//! assert_eq!(package.root(), &model);
//! assert_eq!(package.flatten()?[0].triangles.len(), 4);
//! # Ok::<(), conduit_3mf::ThreeMfError>(())
//! ```

mod error;
mod flatten;
mod limits;
mod model;
mod opc;
mod read;
mod slicer;
mod write;
mod xml;

#[cfg(test)]
mod corpus_tests;
#[cfg(test)]
mod tests;

pub use error::{Location, ThreeMfError, error_kind};
pub use flatten::{FlatMesh, apply as apply_transform, compose as compose_transforms};
pub use limits::{Limits, RATIO_CHECK_FLOOR};
pub use model::{
    BaseMaterial, BaseMaterials, BuildItem, ColorGroup, Component, IDENTITY, Mesh, Metadata, Model,
    Object, ObjectContent, ObjectType, Package, Triangle, Unit,
};
pub use read::{ReadOptions, read, read_with};
pub use slicer::{
    CustomGcode, CustomGcodeKind, CustomGcodes, Layout, ORCA_CUSTOM_GCODE_PART, ORCA_MODEL_PART,
    ORCA_PROFILE_PART, ObjectSettings, PRUSA_CUSTOM_GCODE_PART, PRUSA_MODEL_PART,
    PRUSA_PROFILE_PART, Profile, Setting, SlicerSettings, Volume, VolumeKind, VolumeMesh,
};
pub use write::{ROOT_MODEL_PATH, format_number, write};
