//! The reader: OPC structure, then every reachable model part, then cross-part validation.

use std::borrow::Cow;
use std::collections::{BTreeMap, HashMap, HashSet, VecDeque};

use quick_xml::events::BytesStart;

use crate::error::{Location, ThreeMfError};
use crate::model::*;
use crate::opc::{self, Archive, Relationship};
use crate::xml::{self, Ev, Ns, Xml, clip, parse_color, parse_f64, parse_matrix, parse_u32};
use crate::{Limits, Package};

mod core;
mod extensions;
mod materials;
mod validate;

use validate::{check_component_graph, check_duplicate_ids, validate_cross_part};

/// Well-known metadata names of the core specification.
pub(crate) const WELL_KNOWN_METADATA: &[&str] = &[
    "Title",
    "Designer",
    "Description",
    "Copyright",
    "LicenseTerms",
    "Rating",
    "CreationDate",
    "ModificationDate",
    "Application",
];

/// How the reader treats harmless defects: files that break a rule of the specification in a
/// way that leaves no doubt about the model (a metadata name missing, duplicated or undefined,
/// a relationship Id used twice, a second StartPart that is a complete model of its own, a
/// duplicated resource id that nothing references).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ReadOptions {
    /// `false` (the default): such a defect is read past and reported as one warning in
    /// [`Package::warnings`] naming the defect, the part and what was kept, as lib3mf's lenient
    /// mode and PrusaSlicer read these files. `true`: it is an error, as the 3MF Consortium's
    /// validation suite (its MUSTFAIL files) demands.
    pub strict: bool,
}

/// Reads a 3MF package from its bytes in the default mode (harmless defects become warnings;
/// see [`ReadOptions`]).
///
/// Every model part reachable from the root model (production `p:path`, slice `slicepath`,
/// and `3dmodel` relationships of the root model) is read and validated; see the crate
/// documentation for the rules enforced and [`Limits`] for the resource bounds.
pub fn read(bytes: &[u8], limits: &Limits) -> Result<Package, ThreeMfError> {
    read_with(bytes, limits, ReadOptions::default())
}

/// Reads a 3MF package from its bytes with `options` (the default mode, or strict).
pub fn read_with(
    bytes: &[u8],
    limits: &Limits,
    options: ReadOptions,
) -> Result<Package, ThreeMfError> {
    let mut ar = Archive::open(bytes, limits)?;
    let mut ctx = Ctx::new(limits, options.strict);
    let (root_path, extra_starts) = root_model_path(&mut ar, &mut ctx)?;
    let (parts, seen) = read_model_parts(&mut ar, &root_path, &mut ctx)?;

    // Duplicated ids first: a reference to a dropped duplicate is reported as the duplicate.
    for w in check_duplicate_ids(&parts, &seen)? {
        ctx.warn(w);
    }
    validate_cross_part(&parts, &seen, &root_path)?;
    check_component_graph(&parts, limits)?;
    check_extra_starts(&mut ar, &root_path, &extra_starts, &seen, &mut ctx)?;

    let models: BTreeMap<String, Model> = parts.into_iter().map(|(k, v)| (k, v.model)).collect();
    let empty = Model::default();
    let root = models.get(&root_path).unwrap_or(&empty);
    let slicer = crate::slicer::read_settings(&mut ar, root, &mut ctx.warnings)?;
    Ok(Package {
        slicer,
        root_path,
        models,
        warnings: {
            let mut w = ctx.warnings;
            if ctx.suppressed > 0 {
                w.push(format!("({} more warnings not shown)", ctx.suppressed));
            }
            w
        },
        limits: limits.clone(),
    })
}

/// The path of the root model part: the target of the package's 3D model relationship,
/// which must be a part inside the package. Further StartPart relationships are an error in
/// strict mode; otherwise they are returned (relationship, resolved target) for
/// [`check_extra_starts`].
fn root_model_path(
    ar: &mut Archive<'_>,
    ctx: &mut Ctx<'_>,
) -> Result<(String, Vec<Relationship>), ThreeMfError> {
    if !ar.exists("/_rels/.rels") {
        return Err(ThreeMfError::MissingPart {
            part: "/_rels/.rels".into(),
            needed_for: "the package relationships locate the 3D model".into(),
        });
    }
    let rels = ar.relationships("/")?;
    let rels = check_relationships(ar, "/", rels, ctx)?;
    let starts: Vec<&Relationship> = rels.iter().filter(|r| r.kind == opc::REL_MODEL).collect();
    if starts.is_empty() || (starts.len() > 1 && ctx.strict) {
        return Err(start_part_error(&starts));
    }
    let root_rel = starts[0];
    let Some(root_path) = root_rel.part.clone() else {
        return Err(ThreeMfError::Relationship {
            rels_part: "/_rels/.rels".into(),
            id: root_rel.id.clone(),
            target: root_rel.target.clone(),
            reason: "the 3D model must be a part inside the package",
        });
    };
    let extra = starts[1..].iter().map(|r| (*r).clone()).collect();
    Ok((root_path, extra))
}

/// The error for a package without exactly one StartPart relationship.
fn start_part_error(starts: &[&Relationship]) -> ThreeMfError {
    ThreeMfError::StartPart {
        found: starts.len(),
        detail: if starts.is_empty() {
            String::new()
        } else {
            format!(
                ": {}",
                starts
                    .iter()
                    .map(|r| r.target.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        },
    }
}

/// Default mode: a StartPart relationship after the first is ignored with a warning when its
/// target is the root part again or a part already read as part of the payload, or a complete
/// 3D model part of its own (it reads without an error or a warning). Any other second
/// StartPart (a broken part, or one that uses textures through the first part's
/// relationships, as in the validation suite's MUSTFAIL 2.1.2) leaves it unclear which part is
/// the payload, and the package is refused.
fn check_extra_starts(
    ar: &mut Archive<'_>,
    root_path: &str,
    extra: &[Relationship],
    seen: &HashMap<String, String>,
    ctx: &mut Ctx<'_>,
) -> Result<(), ThreeMfError> {
    if extra.is_empty() {
        return Ok(());
    }
    let all = || {
        let mut v: Vec<Relationship> = Vec::with_capacity(extra.len() + 1);
        v.push(Relationship {
            id: String::new(),
            kind: opc::REL_MODEL.into(),
            target: root_path.into(),
            part: Some(root_path.into()),
        });
        v.extend(extra.iter().cloned());
        v
    };
    for r in extra {
        // External targets were refused by `check_relationships`.
        let Some(target) = r.part.as_deref() else {
            return Err(start_part_error(&all().iter().collect::<Vec<_>>()));
        };
        if !seen.contains_key(&opc::key(target)) {
            let mut scratch = Ctx::new(ctx.limits, false);
            let clean = read_model_part(ar, target, true, &mut scratch).is_ok()
                && scratch.warnings.is_empty()
                && scratch.suppressed == 0;
            if !clean {
                return Err(start_part_error(&all().iter().collect::<Vec<_>>()));
            }
        }
        ctx.warn(format!(
            "/_rels/.rels: {} StartPart relationships of type 3dmodel; {root_path} is read and {} (relationship {:?}) is ignored",
            extra.len() + 1,
            r.target,
            r.id
        ));
    }
    Ok(())
}

/// The model parts read, by path, and every part path seen, by lookup key.
type ModelParts = (BTreeMap<String, PartInfo>, HashMap<String, String>);

/// Reads every model part reachable from the root, breadth-first. Returns the parts by path
/// and every part path seen, by lookup key.
fn read_model_parts(
    ar: &mut Archive<'_>,
    root_path: &str,
    ctx: &mut Ctx<'_>,
) -> Result<ModelParts, ThreeMfError> {
    let limits = ctx.limits;
    let mut parts: BTreeMap<String, PartInfo> = BTreeMap::new();
    let mut queue: VecDeque<(String, bool)> = VecDeque::new();
    queue.push_back((root_path.to_owned(), true));
    let mut seen: HashMap<String, String> = HashMap::new();
    seen.insert(opc::key(root_path), root_path.to_owned());
    while let Some((path, is_root)) = queue.pop_front() {
        let (info, refs) = read_model_part(ar, &path, is_root, ctx)?;
        for r in refs {
            let k = opc::key(&r);
            if !seen.contains_key(&k) {
                if seen.len() >= limits.max_archive_entries {
                    return Err(ThreeMfError::LimitExceeded {
                        part: path.clone(),
                        limit: "max_archive_entries",
                        max: limits.max_archive_entries as u64,
                        found: seen.len() as u64 + 1,
                    });
                }
                seen.insert(k, r.clone());
                queue.push_back((r, false));
            }
        }
        parts.insert(path, info);
    }
    Ok((parts, seen))
}

/// Reads the model part at `path` (which must have the model content type) and checks its
/// relationships. Returns it with the model parts it references (and, for the root, those
/// its 3D model relationships target).
fn read_model_part(
    ar: &mut Archive<'_>,
    path: &str,
    is_root: bool,
    ctx: &mut Ctx<'_>,
) -> Result<(PartInfo, Vec<String>), ThreeMfError> {
    match ar.content_type(path) {
        Some(opc::CT_MODEL) => {}
        found => {
            if !ar.exists(path) {
                return Err(ThreeMfError::MissingPart {
                    part: path.to_owned(),
                    needed_for: "referenced as a 3D model part".into(),
                });
            }
            return Err(ThreeMfError::ContentType {
                part: path.to_owned(),
                found: found.map(str::to_string),
                expected: opc::CT_MODEL,
            });
        }
    }
    let Some(bytes) = ar.read(path)? else {
        return Err(ThreeMfError::MissingPart {
            part: path.to_owned(),
            needed_for: "referenced as a 3D model part".into(),
        });
    };
    let rels = ar.relationships(path)?;
    let rels = check_relationships(ar, path, rels, ctx)?;
    let info = parse_part(path, &bytes, is_root, ar, &rels, ctx)?;
    let mut refs: Vec<String> = info.referenced_parts.clone();
    if is_root {
        refs.extend(
            rels.iter()
                .filter(|r| r.kind == opc::REL_MODEL)
                .filter_map(|r| r.part.clone()),
        );
    }
    Ok((info, refs))
}

/// Most warnings kept per package; the rest are counted.
const MAX_WARNINGS: usize = 1000;

/// Shared reading state: limits, the mode, counters over the whole package, warnings.
struct Ctx<'l> {
    limits: &'l Limits,
    /// Harmless defects are errors ([`ReadOptions::strict`]).
    strict: bool,
    warnings: Vec<String>,
    suppressed: usize,
    vertices: usize,
    triangles: usize,
    resources: usize,
}

impl<'l> Ctx<'l> {
    fn new(limits: &'l Limits, strict: bool) -> Ctx<'l> {
        Ctx {
            limits,
            strict,
            warnings: Vec::new(),
            suppressed: 0,
            vertices: 0,
            triangles: 0,
            resources: 0,
        }
    }

    /// A harmless defect: `error` in strict mode, else the warning `warning` (built only when
    /// needed).
    fn defect(
        &mut self,
        error: impl FnOnce() -> ThreeMfError,
        warning: impl FnOnce() -> String,
    ) -> Result<(), ThreeMfError> {
        if self.strict {
            return Err(error());
        }
        let w = warning();
        self.warn(w);
        Ok(())
    }

    fn warn(&mut self, msg: String) {
        if self.warnings.len() < MAX_WARNINGS {
            self.warnings.push(msg);
        } else {
            self.suppressed += 1;
        }
    }
}

/// 3MF-defined relationship types must target existing parts inside the package, and a part
/// has at most one print ticket. A relationship Id used twice is a harmless defect: the first
/// relationship is kept. Returns the relationships kept.
fn check_relationships(
    ar: &Archive<'_>,
    source: &str,
    rels: Vec<Relationship>,
    ctx: &mut Ctx<'_>,
) -> Result<Vec<Relationship>, ThreeMfError> {
    let rels_part = opc::rels_part_of(source);
    let err = |r: &Relationship, reason: &'static str| ThreeMfError::Relationship {
        rels_part: rels_part.clone(),
        id: r.id.clone(),
        target: r.target.clone(),
        reason,
    };
    let tickets: Vec<&Relationship> = rels
        .iter()
        .filter(|r| r.kind == opc::REL_PRINTTICKET)
        .collect();
    if let Some(second) = tickets.get(1) {
        return Err(err(second, "more than one print ticket for one part"));
    }
    let mut ids = HashSet::new();
    let mut kept = Vec::with_capacity(rels.len());
    for r in rels {
        if ids.contains(&r.id) {
            ctx.defect(
                || err(&r, "relationship Id is used twice in this part"),
                || {
                    format!(
                        "{rels_part}: relationship Id {:?} is used twice (the second targets {}); the first is kept",
                        r.id, r.target
                    )
                },
            )?;
            continue;
        }
        ids.insert(r.id.clone());
        kept.push(r);
    }
    let rels = kept;
    for r in &rels {
        let is_3mf = [
            opc::REL_MODEL,
            opc::REL_THUMBNAIL,
            opc::REL_PRINTTICKET,
            opc::REL_TEXTURE,
        ]
        .contains(&r.kind.as_str());
        match &r.part {
            None if is_3mf => {
                return Err(err(
                    r,
                    "3MF relationships must target a part inside the package",
                ));
            }
            None => {}
            Some(p) if !ar.exists(p) => {
                if is_3mf {
                    return Err(err(r, "target part does not exist"));
                }
                ctx.warn(format!(
                    "{rels_part}: relationship {} targets missing part {}",
                    r.id, r.target
                ));
            }
            Some(_) => {}
        }
    }
    Ok(rels)
}

/// Kind of a resource id in one model part.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Res {
    Object(ObjectType),
    Base(usize),
    Color(usize),
    Texture,
    TexGroup(usize),
    Composite(usize),
    Multi(usize),
    SliceStack { has_refs: bool },
    Other,
}

impl Res {
    /// Number of entries if this is a property group a `pid` may reference.
    fn property_count(self) -> Option<usize> {
        match self {
            Res::Base(n) | Res::Color(n) | Res::TexGroup(n) | Res::Composite(n) | Res::Multi(n) => {
                Some(n)
            }
            _ => None,
        }
    }
}

/// A reference to an object, checked once every part is read.
#[derive(Debug, Clone)]
struct ObjectRef {
    at: Location,
    element: &'static str,
    object_id: u32,
    path: Option<String>,
}

/// A `sliceref`, checked once every part is read.
#[derive(Debug, Clone)]
struct SliceRef {
    at: Location,
    stack_id: u32,
    path: Option<String>,
}

/// One parsed model part with what is needed for cross-part validation.
struct PartInfo {
    model: Model,
    res: HashMap<u32, Res>,
    object_refs: Vec<ObjectRef>,
    slice_refs: Vec<SliceRef>,
    slicestack_uses: Vec<(Location, u32)>,
    referenced_parts: Vec<String>,
    /// Ids referenced inside this part while it was parsed (`pid`, `texid`, `matid`, `pids`).
    used_ids: HashSet<u32>,
    /// Default mode: resources whose id an earlier resource of this part already had (where
    /// the later one is, its id); they were dropped, the first definition kept.
    duplicate_ids: Vec<(Location, u32)>,
}

fn parse_part(
    part: &str,
    bytes: &[u8],
    is_root: bool,
    ar: &Archive<'_>,
    rels: &[Relationship],
    ctx: &mut Ctx<'_>,
) -> Result<PartInfo, ThreeMfError> {
    let x = Xml::new(part, bytes)?;
    let targets = |kind: &str| -> HashSet<String> {
        rels.iter()
            .filter(|r| r.kind == kind)
            .filter_map(|r| r.part.as_deref().map(opc::key))
            .collect()
    };
    let mut p = Parser {
        x,
        ctx,
        ar,
        texture_targets: targets(opc::REL_TEXTURE),
        thumbnail_targets: targets(opc::REL_THUMBNAIL),
        is_root,
        info: PartInfo {
            model: Model::default(),
            res: HashMap::new(),
            object_refs: Vec::new(),
            slice_refs: Vec::new(),
            slicestack_uses: Vec::new(),
            referenced_parts: Vec::new(),
            used_ids: HashSet::new(),
            duplicate_ids: Vec::new(),
        },
        slicestack_uses: Vec::new(),
    };
    p.model()?;
    p.info.slicestack_uses = std::mem::take(&mut p.slicestack_uses);
    Ok(p.info)
}

struct Parser<'x, 'c, 'l, 'a> {
    x: Xml<'x>,
    ctx: &'c mut Ctx<'l>,
    ar: &'c Archive<'a>,
    /// Parts targeted by this part's texture / thumbnail relationships (lookup keys).
    texture_targets: HashSet<String>,
    thumbnail_targets: HashSet<String>,
    is_root: bool,
    info: PartInfo,
    slicestack_uses: Vec<(Location, u32)>,
}

/// Metadata entries of one scope (model, object group, item group) with their names.
#[derive(Default)]
struct MetaScope {
    entries: Vec<Metadata>,
    names: HashSet<String>,
}

/// Collected attributes of one element (values owned only when they had to be unescaped).
type Attrs<'v> = Vec<(Ns, String, Cow<'v, str>)>;

impl<'x> Parser<'x, '_, '_, '_> {
    fn part(&self) -> &str {
        self.x.part
    }

    fn warn(&mut self, msg: impl std::fmt::Display) {
        if self.ctx.warnings.len() >= MAX_WARNINGS {
            self.ctx.suppressed += 1;
            return;
        }
        let at = self.x.loc();
        self.ctx.warn(format!("{at}: {msg}"));
    }

    fn invalid(
        &self,
        element: &str,
        attribute: &str,
        value: &str,
        reason: &'static str,
    ) -> ThreeMfError {
        ThreeMfError::InvalidAttribute {
            at: self.x.loc(),
            element: element.to_string(),
            attribute: attribute.to_string(),
            value: clip(value),
            reason,
        }
    }

    fn missing(&self, element: &'static str, attribute: &'static str) -> ThreeMfError {
        ThreeMfError::MissingAttribute {
            at: self.x.loc(),
            element,
            attribute,
        }
    }

    fn rule(&self, element: &'static str, rule: &'static str) -> ThreeMfError {
        ThreeMfError::Rule {
            at: self.x.loc(),
            element,
            rule,
        }
    }

    fn u32_attr(&self, element: &str, attribute: &str, v: &str) -> Result<u32, ThreeMfError> {
        parse_u32(v).map_err(|r| self.invalid(element, attribute, v, r))
    }

    fn f64_attr(&self, element: &str, attribute: &str, v: &str) -> Result<f64, ThreeMfError> {
        parse_f64(v).map_err(|r| self.invalid(element, attribute, v, r))
    }

    fn u32_list(&self, element: &str, attribute: &str, v: &str) -> Result<Vec<u32>, ThreeMfError> {
        v.split(xml::is_xml_ws)
            .filter(|t| !t.is_empty())
            .map(|t| self.u32_attr(element, attribute, t))
            .collect()
    }

    /// Collects attributes of `e`; `xml:space` is rejected everywhere.
    fn attrs<'v>(&self, e: &'v BytesStart<'x>) -> Result<Attrs<'v>, ThreeMfError> {
        let mut out = Vec::new();
        let mut bad_space = false;
        self.x.attrs(e, |ns, local, v| {
            if ns == Ns::Xml && local == "space" {
                bad_space = true;
            }
            out.push((ns, local.to_string(), Cow::Owned(v.into_owned())));
            Ok(())
        })?;
        if bad_space {
            return Err(ThreeMfError::InvalidAttribute {
                at: self.x.loc(),
                element: e.local_name().as_ref().to_string(),
                attribute: "xml:space".into(),
                value: out
                    .iter()
                    .find(|(ns, l, _)| *ns == Ns::Xml && l == "space")
                    .map(|(_, _, v)| clip(v))
                    .unwrap_or_default(),
                reason: "the xml:space attribute is not allowed in 3MF model parts",
            });
        }
        Ok(out)
    }

    /// Registers a resource id, enforcing `max_objects`. A duplicated id is an error in strict
    /// mode; in the default mode the first definition is kept and `Ok(false)` tells the caller
    /// to drop this one ([`check_duplicate_ids`] refuses the package if anything references
    /// the id, since a reference could then mean either).
    fn add_res(&mut self, id: u32, kind: Res) -> Result<bool, ThreeMfError> {
        self.ctx.resources += 1;
        if self.ctx.resources > self.ctx.limits.max_objects {
            return Err(ThreeMfError::LimitExceeded {
                part: self.part().to_string(),
                limit: "max_objects",
                max: self.ctx.limits.max_objects as u64,
                found: self.ctx.resources as u64,
            });
        }
        if self.info.res.contains_key(&id) {
            if self.ctx.strict {
                return Err(ThreeMfError::DuplicateResourceId {
                    at: self.x.loc(),
                    id,
                });
            }
            self.info.duplicate_ids.push((self.x.loc(), id));
            return Ok(false);
        }
        self.info.res.insert(id, kind);
        Ok(true)
    }

    /// Records the final kind (with its entry count) of a resource registered by
    /// [`Self::add_res`], unless it was a dropped duplicate.
    fn set_res(&mut self, own: bool, id: u32, kind: Res) {
        if own {
            self.info.res.insert(id, kind);
        }
    }

    /// Looks up resource `id` as a reference, recording that it is used.
    fn res_ref(&mut self, id: u32) -> Option<Res> {
        self.info.used_ids.insert(id);
        self.info.res.get(&id).copied()
    }

    /// Handles an element conduit does not interpret at this position: unbound prefixes and
    /// unknown 3MF namespaces are errors, unknown core elements are warned about, everything
    /// else is skipped silently.
    fn unknown(&mut self, e: &BytesStart<'x>, empty: bool) -> Result<(), ThreeMfError> {
        let ns = self.x.element_ns(e);
        let name = e.name().as_ref().to_string();
        match ns {
            Ns::Unbound => {
                return Err(self.x.xml_err(format!(
                    "element <{name}> uses an undeclared namespace prefix"
                )));
            }
            Ns::Unknown3mf => {
                let uri = self.x.ns_uri(e.name(), true);
                if !self.x.ignorable.contains(&uri) {
                    return Err(ThreeMfError::UnknownNamespace {
                        at: self.x.loc(),
                        what: format!("element <{name}>"),
                        namespace: uri,
                    });
                }
            }
            Ns::Core | Ns::None => self.warn(format_args!("ignored unknown element <{name}>")),
            _ => {}
        }
        if !empty {
            self.x.skip()?;
        }
        Ok(())
    }

    /// Whether `e` is the materials-extension child `local`. The core namespace is tolerated
    /// with a warning (the 3MF Consortium's multiprop-*.3mf samples write `<multi>` unprefixed).
    fn material_child(&mut self, e: &BytesStart<'x>, local: &str) -> bool {
        if e.local_name().as_ref() != local {
            return false;
        }
        match self.x.element_ns(e) {
            Ns::Material => true,
            Ns::Core => {
                self.warn(format_args!(
                    "<{local}> should be in the materials namespace"
                ));
                true
            }
            _ => false,
        }
    }

    /// Reads children of the current element, calling `f(self, element, empty)` for each.
    fn children(
        &mut self,
        mut f: impl FnMut(&mut Self, BytesStart<'x>, bool) -> Result<(), ThreeMfError>,
    ) -> Result<(), ThreeMfError> {
        loop {
            match self.x.next()? {
                Ev::Start(e) => f(self, e, false)?,
                Ev::Empty(e) => f(self, e, true)?,
                Ev::End => return Ok(()),
                Ev::Text(_) => {}
                Ev::Eof => return Err(self.x.xml_err("unexpected end of document")),
            }
        }
    }

    fn id_attr(&self, element: &'static str, attrs: &Attrs<'_>) -> Result<u32, ThreeMfError> {
        let v = attrs
            .iter()
            .find(|(ns, l, _)| *ns == Ns::None && l == "id")
            .ok_or_else(|| self.missing(element, "id"))?;
        self.u32_attr(element, "id", &v.2)
    }

    fn get<'v>(attrs: &'v Attrs<'_>, ns: Ns, name: &str) -> Option<&'v str> {
        attrs
            .iter()
            .find(|(n, l, _)| *n == ns && l == name)
            .map(|(_, _, v)| v.as_ref())
    }

    /// Checks that `pid` names a property group defined so far and `index` is inside it.
    fn check_property(
        &mut self,
        element: &'static str,
        pid: u32,
        indices: &[(&'static str, u32)],
    ) -> Result<(), ThreeMfError> {
        let Some(count) = self.res_ref(pid).and_then(|r| r.property_count()) else {
            return Err(ThreeMfError::UnresolvedReference {
                at: self.x.loc(),
                element,
                attribute: "pid",
                id: pid,
                expected: "a property group (basematerials, colorgroup, texture2dgroup, compositematerials or multiproperties) defined earlier",
            });
        };
        for &(attribute, index) in indices {
            if index as usize >= count {
                return Err(ThreeMfError::IndexOutOfRange {
                    at: self.x.loc(),
                    element,
                    attribute,
                    index: index.into(),
                    count,
                });
            }
        }
        Ok(())
    }

    /// The production `p:path` attribute as an absolute part name; registers the part to read.
    fn path_attr(&mut self, attrs: &Attrs<'_>) -> Option<String> {
        let v = Self::get(attrs, Ns::Production, "path")?;
        let abs = opc::resolve_target(self.part(), v).unwrap_or_else(|| v.to_string());
        if opc::key(&abs) == opc::key(self.part()) {
            return Some(abs);
        }
        self.info.referenced_parts.push(abs.clone());
        Some(abs)
    }
}
