//! Core-specification elements: model, metadata, resources, objects, meshes, components, build.

use quick_xml::events::BytesStart;

use super::*;

/// What is wrong with a metadata name that is neither well-known nor namespace-qualified.
const UNDEFINED_METADATA: &str =
    "is neither a well-known name nor qualified by a declared namespace prefix";

impl<'x> Parser<'x, '_, '_, '_> {
    pub(super) fn model(&mut self) -> Result<(), ThreeMfError> {
        let (e, empty) = self.root_element()?;
        self.ignorable_namespaces(&e);
        let required = self.model_attributes(&e)?;
        if let Some(req) = required {
            self.required_extensions(&req)?;
        }
        let (mut have_resources, mut have_build) = (false, false);
        if !empty {
            let mut metadata = MetaScope::default();
            self.children(|p, e, empty| {
                let ns = p.x.element_ns(&e);
                match (ns, e.local_name().as_ref()) {
                    (Ns::Core, "metadata") => p.metadata(&e, empty, &mut metadata),
                    (Ns::Core, "resources") => {
                        if have_resources {
                            return Err(p.rule("model", "more than one <resources> element"));
                        }
                        have_resources = true;
                        p.attrs(&e)?;
                        if empty { Ok(()) } else { p.resources() }
                    }
                    (Ns::Core, "build") => {
                        if have_build {
                            return Err(p.rule("model", "more than one <build> element"));
                        }
                        have_build = true;
                        p.attrs(&e)?;
                        if empty { Ok(()) } else { p.build() }
                    }
                    _ => p.unknown(&e, empty),
                }
            })?;
            self.info.model.metadata = metadata.entries;
        }
        // Trailing content after </model> (a second root element, text) is rejected by `next`.
        loop {
            match self.x.next()? {
                Ev::Eof => break,
                Ev::Text(_) => {}
                _ => return Err(self.x.xml_err("content after the root element")),
            }
        }
        if !have_resources {
            return Err(ThreeMfError::MissingElement {
                at: Location::part(self.part()),
                parent: "model",
                element: "resources",
            });
        }
        if self.is_root && !have_build {
            return Err(ThreeMfError::MissingElement {
                at: Location::part(self.part()),
                parent: "model",
                element: "build",
            });
        }
        Ok(())
    }

    /// The root element, which must be `<model>` in the core namespace, and whether it is
    /// empty.
    fn root_element(&mut self) -> Result<(BytesStart<'x>, bool), ThreeMfError> {
        let (e, empty) = loop {
            match self.x.next()? {
                Ev::Start(e) => break (e, false),
                Ev::Empty(e) => break (e, true),
                Ev::Eof => return Err(self.x.xml_err("no root element")),
                _ => {}
            }
        };
        if self.x.element_ns(&e) != Ns::Core || e.local_name().as_ref() != "model" {
            return Err(self
                .x
                .xml_err("root element must be <model> in the 3MF core namespace"));
        }
        if self.x.ns_uri(e.name(), true) == xml::NS_LEGACY {
            self.warn("legacy 3MF 0.93 namespace, read as core 1.x");
        }
        Ok((e, empty))
    }

    /// Records the namespaces that the root's `mc:Ignorable` names. Read before the other
    /// attributes, so attributes in ignorable namespaces pass the namespace check.
    fn ignorable_namespaces(&mut self, e: &BytesStart<'x>) {
        for a in e.attributes().flatten() {
            let k = a.key.as_ref();
            if let Some(prefix) = k.strip_suffix(":Ignorable") {
                if self.x.resolve_prefix(prefix).as_deref() == Some(xml::NS_MC) {
                    let v = a
                        .normalized_value(quick_xml::XmlVersion::Implicit1_0)
                        .unwrap_or_default()
                        .into_owned();
                    for p in v.split(xml::is_xml_ws).filter(|p| !p.is_empty()) {
                        if let Some(uri) = self.x.resolve_prefix(p) {
                            self.x.ignorable.push(uri);
                        }
                    }
                }
            }
        }
    }

    /// Reads the root's `unit` and `xml:lang`; returns its `requiredextensions`, if any.
    fn model_attributes(&mut self, e: &BytesStart<'x>) -> Result<Option<String>, ThreeMfError> {
        let mut required = None;
        for (ns, local, v) in self.attrs(e)? {
            match (ns, local.as_str()) {
                (Ns::None, "unit") => {
                    self.info.model.unit = Unit::from_attr(&v)
                        .ok_or_else(|| self.invalid("model", "unit", &v, "unknown unit"))?;
                }
                (Ns::None, "requiredextensions") => required = Some(v.into_owned()),
                (Ns::Xml, "lang") => self.info.model.language = Some(v.into_owned()),
                _ => {}
            }
        }
        Ok(required)
    }

    /// Checks each prefix of `requiredextensions` (declared, an extension this reader
    /// supports) and records its namespace.
    fn required_extensions(&mut self, req: &str) -> Result<(), ThreeMfError> {
        for prefix in req.split(xml::is_xml_ws).filter(|p| !p.is_empty()) {
            let Some(uri) = self.x.resolve_prefix(prefix) else {
                return Err(ThreeMfError::UndeclaredExtensionPrefix {
                    at: self.x.loc(),
                    prefix: prefix.to_string(),
                });
            };
            if !xml::SUPPORTED_REQUIRED.contains(&uri.as_str()) {
                return Err(ThreeMfError::UnsupportedExtension {
                    at: self.x.loc(),
                    namespace: uri,
                });
            }
            if !matches!(
                uri.as_str(),
                xml::NS_CORE | xml::NS_MATERIAL | xml::NS_PRODUCTION | xml::NS_SLICE
            ) {
                self.warn(format_args!(
                    "required extension {uri} is recognised but its data is not interpreted"
                ));
            }
            self.info.model.required_extensions.push(uri);
        }
        Ok(())
    }

    pub(super) fn metadata(
        &mut self,
        e: &BytesStart<'x>,
        empty: bool,
        scope: &mut MetaScope,
    ) -> Result<(), ThreeMfError> {
        let at = self.x.loc();
        let mut name = None;
        for (ns, local, v) in self.attrs(e)? {
            if ns == Ns::None && local == "name" {
                name = Some(v.into_owned());
            }
        }
        let mut value = String::new();
        if !empty {
            loop {
                match self.x.next()? {
                    Ev::Text(t) => value.push_str(&t),
                    Ev::Start(_) => self.x.skip()?,
                    Ev::Empty(_) => {}
                    Ev::End => break,
                    Ev::Eof => return Err(self.x.xml_err("unexpected end of document")),
                }
            }
        }
        let Some(name) = name else {
            return self.ctx.defect(
                || ThreeMfError::MissingAttribute {
                    at: at.clone(),
                    element: "metadata",
                    attribute: "name",
                },
                || format!("{at}: <metadata> has no name attribute; the entry is skipped"),
            );
        };
        if name.trim().is_empty() {
            return self.ctx.defect(
                || ThreeMfError::InvalidAttribute {
                    at: at.clone(),
                    element: "metadata".into(),
                    attribute: "name".into(),
                    value: name.clone(),
                    reason: "metadata name must not be empty",
                },
                || format!("{at}: metadata name is empty; the entry is skipped"),
            );
        }
        if scope.names.contains(&name) {
            return self.ctx.defect(
                || ThreeMfError::DuplicateMetadata {
                    at: at.clone(),
                    name: name.clone(),
                },
                || format!("{at}: metadata name {name:?} appears twice; the first is kept"),
            );
        }
        scope.names.insert(name.clone());
        let defined = match name.split_once(':') {
            Some((prefix, _)) => self.x.resolve_prefix(prefix).is_some(),
            None => WELL_KNOWN_METADATA.contains(&name.as_str()),
        };
        if !defined {
            self.ctx.defect(
                || ThreeMfError::InvalidAttribute {
                    at: at.clone(),
                    element: "metadata".into(),
                    attribute: "name".into(),
                    value: clip(&name),
                    reason: UNDEFINED_METADATA,
                },
                || format!("{at}: metadata name {name:?} {UNDEFINED_METADATA}; the entry is kept"),
            )?;
        }
        scope.entries.push(Metadata { name, value });
        Ok(())
    }

    pub(super) fn resources(&mut self) -> Result<(), ThreeMfError> {
        self.children(|p, e, empty| {
            let ns = p.x.element_ns(&e);
            match (ns, e.local_name().as_ref()) {
                (Ns::Core, "object") => p.object(&e, empty),
                (Ns::Core, "basematerials") => p.base_materials(&e, empty),
                (Ns::Material, "colorgroup") => p.color_group(&e, empty),
                (Ns::Material, "texture2d") => p.texture(&e, empty),
                (Ns::Material, "texture2dgroup") => p.texture_group(&e, empty),
                (Ns::Material, "compositematerials") => p.composite(&e, empty),
                (Ns::Material, "multiproperties") => p.multi(&e, empty),
                (Ns::Slice, "slicestack") => p.slice_stack(&e, empty),
                (Ns::Material | Ns::Beam | Ns::KnownOther | Ns::Vendor, _) => {
                    // Resources conduit does not interpret (display properties, ...): their
                    // ids still take part in the uniqueness rule.
                    let mut id = None;
                    for (ans, local, v) in p.attrs(&e)? {
                        if ans == Ns::None && local == "id" {
                            id = parse_u32(&v).ok();
                        }
                    }
                    if let Some(id) = id {
                        p.add_res(id, Res::Other)?;
                    }
                    if !empty {
                        p.x.skip()?;
                    }
                    Ok(())
                }
                _ => p.unknown(&e, empty),
            }
        })
    }

    pub(super) fn object(&mut self, e: &BytesStart<'x>, empty: bool) -> Result<(), ThreeMfError> {
        let at = self.x.loc();
        let attrs = self.attrs(e)?;
        let id = self.id_attr("object", &attrs)?;
        let kind = match Self::get(&attrs, Ns::None, "type") {
            None => ObjectType::Model,
            Some(t) => ObjectType::from_attr(t)
                .ok_or_else(|| self.invalid("object", "type", t, "unknown object type"))?,
        };
        let own = self.add_res(id, Res::Object(kind))?;
        let name = Self::get(&attrs, Ns::None, "name").map(str::to_string);
        let pid = Self::get(&attrs, Ns::None, "pid")
            .map(|v| self.u32_attr("object", "pid", v))
            .transpose()?;
        let pindex = Self::get(&attrs, Ns::None, "pindex")
            .map(|v| self.u32_attr("object", "pindex", v))
            .transpose()?;
        match (pid, pindex) {
            (None, Some(_)) => {
                return Err(self.rule("object", "pindex is given without a pid"));
            }
            (Some(pid), pindex) => {
                let idx: Vec<_> = pindex.map(|i| ("pindex", i)).into_iter().collect();
                self.check_property("object", pid, &idx)?;
            }
            (None, None) => {}
        }
        if let Some(stack) = Self::get(&attrs, Ns::Slice, "slicestackid") {
            let sid = self.u32_attr("object", "s:slicestackid", stack)?;
            self.slicestack_uses.push((at.clone(), sid));
        }
        if let Some(thumb) = Self::get(&attrs, Ns::None, "thumbnail") {
            self.object_thumbnail(id, thumb);
        }
        let content = if empty {
            None
        } else {
            self.object_content(id, kind, pid)?
        };
        let content = content.unwrap_or(ObjectContent::Mesh(Mesh::default()));
        if let ObjectContent::Components(c) = &content
            && c.is_empty()
        {
            return Err(ThreeMfError::Rule {
                at,
                element: "components",
                rule: "a components element needs at least one component",
            });
        }
        if !own {
            return Ok(());
        }
        self.info.model.objects.push(Object {
            id,
            name,
            kind,
            pid,
            pindex,
            content,
        });
        Ok(())
    }

    /// Warns when object `id`'s `thumbnail` is missing or not the target of a thumbnail
    /// relationship.
    fn object_thumbnail(&mut self, id: u32, thumb: &str) {
        let target = opc::resolve_target(self.part(), thumb);
        match target {
            Some(t) if self.ar.exists(&t) => {
                if !self.thumbnail_targets.contains(&opc::key(&t)) {
                    self.warn(format_args!(
                        "object {id} thumbnail {thumb} is not the target of a thumbnail relationship"
                    ));
                }
            }
            _ => self.warn(format_args!(
                "object {id} thumbnail {thumb} does not exist in the package"
            )),
        }
    }

    /// Reads the children of object `id`: its one mesh or components element (`None` when it
    /// has neither) and its metadata groups.
    fn object_content(
        &mut self,
        id: u32,
        kind: ObjectType,
        pid: Option<u32>,
    ) -> Result<Option<ObjectContent>, ThreeMfError> {
        let mut content: Option<ObjectContent> = None;
        let mut groups = MetaScope::default();
        self.children(|p, e, empty| {
            let ns = p.x.element_ns(&e);
            match (ns, e.local_name().as_ref()) {
                (Ns::Core, "mesh") => {
                    if content.is_some() {
                        return Err(
                            p.rule("object", "an object has one mesh or one components element")
                        );
                    }
                    p.attrs(&e)?;
                    let mesh = if empty {
                        Mesh::default()
                    } else {
                        p.mesh(id, kind, pid)?
                    };
                    content = Some(ObjectContent::Mesh(mesh));
                    Ok(())
                }
                (Ns::Core, "components") => {
                    if content.is_some() {
                        return Err(
                            p.rule("object", "an object has one mesh or one components element")
                        );
                    }
                    p.attrs(&e)?;
                    let comps = if empty { Vec::new() } else { p.components()? };
                    content = Some(ObjectContent::Components(comps));
                    Ok(())
                }
                (Ns::Core, "metadatagroup") => {
                    if empty {
                        return Ok(());
                    }
                    groups = MetaScope::default();
                    p.children(|p, e, empty| {
                        if p.x.element_ns(&e) == Ns::Core && e.local_name().as_ref() == "metadata" {
                            p.metadata(&e, empty, &mut groups)
                        } else {
                            p.unknown(&e, empty)
                        }
                    })
                }
                _ => p.unknown(&e, empty),
            }
        })?;
        Ok(content)
    }

    pub(super) fn mesh(
        &mut self,
        obj_id: u32,
        obj_kind: ObjectType,
        obj_pid: Option<u32>,
    ) -> Result<Mesh, ThreeMfError> {
        let mut mesh = Mesh::default();
        let mut have_vertices = false;
        self.children(|p, e, empty| {
            let ns = p.x.element_ns(&e);
            match (ns, e.local_name().as_ref()) {
                (Ns::Core, "vertices") => {
                    if have_vertices {
                        return Err(p.rule("mesh", "more than one <vertices> element"));
                    }
                    have_vertices = true;
                    p.attrs(&e)?;
                    if !empty {
                        p.vertices(&mut mesh.vertices)?;
                    }
                    Ok(())
                }
                (Ns::Core, "triangles") => {
                    p.attrs(&e)?;
                    if !empty {
                        p.triangles(&mut mesh, obj_pid)?;
                    }
                    Ok(())
                }
                (Ns::Beam, "beamlattice") => p.beam_lattice(&e, empty, obj_id, obj_kind),
                _ => p.unknown(&e, empty),
            }
        })?;
        Ok(mesh)
    }

    pub(super) fn vertices(&mut self, out: &mut Vec<[f64; 3]>) -> Result<(), ThreeMfError> {
        self.children(|p, e, empty| {
            if p.x.element_ns(&e) != Ns::Core || e.local_name().as_ref() != "vertex" {
                return p.unknown(&e, empty);
            }
            p.ctx.vertices += 1;
            if p.ctx.vertices > p.ctx.limits.max_vertices {
                return Err(ThreeMfError::LimitExceeded {
                    part: p.part().to_string(),
                    limit: "max_vertices",
                    max: p.ctx.limits.max_vertices as u64,
                    found: p.ctx.vertices as u64,
                });
            }
            let mut v = [None; 3];
            let mut err = None;
            p.x.attrs(&e, |ns, local, val| {
                if ns == Ns::None {
                    let i = match local {
                        "x" => 0,
                        "y" => 1,
                        "z" => 2,
                        _ => return Ok(()),
                    };
                    match parse_f64(&val) {
                        Ok(f) => v[i] = Some(f),
                        Err(r) => {
                            err = Some((["x", "y", "z"][i], val.into_owned(), r));
                        }
                    }
                }
                Ok(())
            })?;
            if let Some((a, val, r)) = err {
                return Err(p.invalid("vertex", a, &val, r));
            }
            let [Some(x), Some(y), Some(z)] = v else {
                let a = ["x", "y", "z"][v.iter().position(Option::is_none).unwrap_or(0)];
                return Err(p.missing("vertex", a));
            };
            out.push([x, y, z]);
            if !empty {
                p.x.skip()?;
            }
            Ok(())
        })
    }

    pub(super) fn triangles(
        &mut self,
        mesh: &mut Mesh,
        obj_pid: Option<u32>,
    ) -> Result<(), ThreeMfError> {
        let nverts = mesh.vertices.len();
        let out = &mut mesh.triangles;
        self.children(|p, e, empty| {
            if p.x.element_ns(&e) != Ns::Core || e.local_name().as_ref() != "triangle" {
                return p.unknown(&e, empty);
            }
            p.ctx.triangles += 1;
            if p.ctx.triangles > p.ctx.limits.max_triangles {
                return Err(ThreeMfError::LimitExceeded {
                    part: p.part().to_string(),
                    limit: "max_triangles",
                    max: p.ctx.limits.max_triangles as u64,
                    found: p.ctx.triangles as u64,
                });
            }
            const NAMES: [&str; 7] = ["v1", "v2", "v3", "pid", "p1", "p2", "p3"];
            let mut vals: [Option<u32>; 7] = [None; 7];
            let mut err = None;
            p.x.attrs(&e, |ns, local, val| {
                if ns == Ns::None
                    && let Some(i) = NAMES.iter().position(|n| *n == local)
                {
                    match parse_u32(&val) {
                        Ok(n) => vals[i] = Some(n),
                        Err(r) => err = Some((NAMES[i], val.into_owned(), r)),
                    }
                }
                Ok(())
            })?;
            if let Some((a, val, r)) = err {
                return Err(p.invalid("triangle", a, &val, r));
            }
            let mut v = [0u32; 3];
            for i in 0..3 {
                let Some(n) = vals[i] else {
                    return Err(p.missing("triangle", ["v1", "v2", "v3"][i]));
                };
                if n as usize >= nverts {
                    return Err(ThreeMfError::IndexOutOfRange {
                        at: p.x.loc(),
                        element: "triangle",
                        attribute: ["v1", "v2", "v3"][i],
                        index: n.into(),
                        count: nverts,
                    });
                }
                v[i] = n;
            }
            if v[0] == v[1] || v[1] == v[2] || v[0] == v[2] {
                return Err(p.rule("triangle", "the three vertex indices must be distinct"));
            }
            let pid = vals[3];
            let pp = [vals[4], vals[5], vals[6]];
            match pid.or(obj_pid) {
                Some(group) => {
                    let mut idx: Vec<(&'static str, u32)> = Vec::with_capacity(3);
                    for (i, name) in ["p1", "p2", "p3"].into_iter().enumerate() {
                        if let Some(n) = pp[i] {
                            idx.push((name, n));
                        }
                    }
                    if pid.is_some() || !idx.is_empty() {
                        p.check_property("triangle", group, &idx)?;
                    }
                }
                None => {
                    if pp.iter().any(Option::is_some) {
                        return Err(p.rule(
                            "triangle",
                            "property indices p1/p2/p3 are given but neither the triangle nor its object has a pid",
                        ));
                    }
                }
            }
            out.push(Triangle { v, pid, p: pp });
            if !empty {
                p.x.skip()?;
            }
            Ok(())
        })
    }

    pub(super) fn components(&mut self) -> Result<Vec<Component>, ThreeMfError> {
        let mut out = Vec::new();
        self.children(|p, e, empty| {
            if p.x.element_ns(&e) != Ns::Core || e.local_name().as_ref() != "component" {
                return p.unknown(&e, empty);
            }
            let attrs = p.attrs(&e)?;
            let object_id = match Self::get(&attrs, Ns::None, "objectid") {
                Some(v) => p.u32_attr("component", "objectid", v)?,
                None => return Err(p.missing("component", "objectid")),
            };
            let transform = Self::get(&attrs, Ns::None, "transform")
                .map(|v| parse_matrix(v).map_err(|r| p.invalid("component", "transform", v, r)))
                .transpose()?;
            let path = p.path_attr(&attrs);
            p.info.object_refs.push(ObjectRef {
                at: p.x.loc(),
                element: "component",
                object_id,
                path: path.clone(),
            });
            out.push(Component {
                object_id,
                path,
                transform,
            });
            if !empty {
                p.x.skip()?;
            }
            Ok(())
        })?;
        Ok(out)
    }

    pub(super) fn build(&mut self) -> Result<(), ThreeMfError> {
        self.children(|p, e, empty| {
            if p.x.element_ns(&e) != Ns::Core || e.local_name().as_ref() != "item" {
                return p.unknown(&e, empty);
            }
            let attrs = p.attrs(&e)?;
            let object_id = match Self::get(&attrs, Ns::None, "objectid") {
                Some(v) => p.u32_attr("item", "objectid", v)?,
                None => return Err(p.missing("item", "objectid")),
            };
            let transform = Self::get(&attrs, Ns::None, "transform")
                .map(|v| parse_matrix(v).map_err(|r| p.invalid("item", "transform", v, r)))
                .transpose()?;
            let part_number = Self::get(&attrs, Ns::None, "partnumber").map(str::to_string);
            let path = p.path_attr(&attrs);
            p.info.object_refs.push(ObjectRef {
                at: p.x.loc(),
                element: "item",
                object_id,
                path: path.clone(),
            });
            if !empty {
                let mut md = MetaScope::default();
                p.children(|p, e, empty| {
                    if p.x.element_ns(&e) == Ns::Core && e.local_name().as_ref() == "metadatagroup"
                    {
                        if empty {
                            return Ok(());
                        }
                        p.children(|p, e, empty| {
                            if p.x.element_ns(&e) == Ns::Core
                                && e.local_name().as_ref() == "metadata"
                            {
                                p.metadata(&e, empty, &mut md)
                            } else {
                                p.unknown(&e, empty)
                            }
                        })
                    } else {
                        p.unknown(&e, empty)
                    }
                })?;
            }
            p.info.model.build.push(BuildItem {
                object_id,
                path,
                transform,
                part_number,
            });
            Ok(())
        })
    }
}
