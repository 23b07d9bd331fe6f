//! Materials-extension resources: colour groups, textures, texture groups, composite
//! materials and multiproperties.

use quick_xml::events::BytesStart;

use super::*;

impl<'x> Parser<'x, '_, '_, '_> {
    pub(super) fn base_materials(
        &mut self,
        e: &BytesStart<'x>,
        empty: bool,
    ) -> Result<(), ThreeMfError> {
        let attrs = self.attrs(e)?;
        let id = self.id_attr("basematerials", &attrs)?;
        let own = self.add_res(id, Res::Base(0))?;
        let mut materials = Vec::new();
        if !empty {
            self.children(|p, e, empty| {
                if p.x.element_ns(&e) != Ns::Core || e.local_name().as_ref() != "base" {
                    return p.unknown(&e, empty);
                }
                let attrs = p.attrs(&e)?;
                let name = Self::get(&attrs, Ns::None, "name")
                    .ok_or_else(|| p.missing("base", "name"))?
                    .to_string();
                let c = Self::get(&attrs, Ns::None, "displaycolor")
                    .ok_or_else(|| p.missing("base", "displaycolor"))?;
                let display_color =
                    parse_color(c).map_err(|r| p.invalid("base", "displaycolor", c, r))?;
                materials.push(BaseMaterial {
                    name,
                    display_color,
                });
                if !empty {
                    p.x.skip()?;
                }
                Ok(())
            })?;
        }
        self.set_res(own, id, Res::Base(materials.len()));
        if own {
            self.info
                .model
                .base_materials
                .push(BaseMaterials { id, materials });
        }
        Ok(())
    }

    pub(super) fn color_group(
        &mut self,
        e: &BytesStart<'x>,
        empty: bool,
    ) -> Result<(), ThreeMfError> {
        let attrs = self.attrs(e)?;
        let id = self.id_attr("colorgroup", &attrs)?;
        let own = self.add_res(id, Res::Color(0))?;
        let mut colors = Vec::new();
        if !empty {
            self.children(|p, e, empty| {
                if !p.material_child(&e, "color") {
                    return p.unknown(&e, empty);
                }
                let attrs = p.attrs(&e)?;
                let c = Self::get(&attrs, Ns::None, "color")
                    .ok_or_else(|| p.missing("color", "color"))?;
                colors.push(parse_color(c).map_err(|r| p.invalid("color", "color", c, r))?);
                if !empty {
                    p.x.skip()?;
                }
                Ok(())
            })?;
        }
        self.set_res(own, id, Res::Color(colors.len()));
        if own {
            self.info.model.color_groups.push(ColorGroup { id, colors });
        }
        Ok(())
    }

    pub(super) fn texture(&mut self, e: &BytesStart<'x>, empty: bool) -> Result<(), ThreeMfError> {
        let attrs = self.attrs(e)?;
        let id = self.id_attr("texture2d", &attrs)?;
        self.add_res(id, Res::Texture)?;
        let path =
            Self::get(&attrs, Ns::None, "path").ok_or_else(|| self.missing("texture2d", "path"))?;
        let ct = Self::get(&attrs, Ns::None, "contenttype")
            .ok_or_else(|| self.missing("texture2d", "contenttype"))?;
        if !matches!(ct.trim(), "image/png" | "image/jpeg") {
            return Err(self.invalid(
                "texture2d",
                "contenttype",
                ct,
                "texture content type must be image/png or image/jpeg",
            ));
        }
        let abs = opc::resolve_target(self.part(), path);
        match abs {
            Some(a) if self.ar.exists(&a) => {
                if !self.texture_targets.contains(&opc::key(&a)) {
                    self.warn(format_args!(
                        "texture2d {id}: {path} is not the target of a 3D texture relationship of this part"
                    ));
                }
            }
            _ => {
                return Err(self.invalid(
                    "texture2d",
                    "path",
                    path,
                    "texture part does not exist in the package",
                ));
            }
        }
        if !empty {
            self.x.skip()?;
        }
        Ok(())
    }

    pub(super) fn texture_group(
        &mut self,
        e: &BytesStart<'x>,
        empty: bool,
    ) -> Result<(), ThreeMfError> {
        let attrs = self.attrs(e)?;
        let id = self.id_attr("texture2dgroup", &attrs)?;
        let texid = Self::get(&attrs, Ns::None, "texid")
            .ok_or_else(|| self.missing("texture2dgroup", "texid"))?;
        let texid = self.u32_attr("texture2dgroup", "texid", texid)?;
        if self.res_ref(texid) != Some(Res::Texture) {
            return Err(ThreeMfError::UnresolvedReference {
                at: self.x.loc(),
                element: "texture2dgroup",
                attribute: "texid",
                id: texid,
                expected: "a texture2d defined earlier",
            });
        }
        let own = self.add_res(id, Res::TexGroup(0))?;
        let mut n = 0usize;
        if !empty {
            self.children(|p, e, empty| {
                if !p.material_child(&e, "tex2coord") {
                    return p.unknown(&e, empty);
                }
                let attrs = p.attrs(&e)?;
                for a in ["u", "v"] {
                    let v = Self::get(&attrs, Ns::None, a)
                        .ok_or_else(|| p.missing("tex2coord", if a == "u" { "u" } else { "v" }))?;
                    p.f64_attr("tex2coord", a, v)?;
                }
                n += 1;
                if !empty {
                    p.x.skip()?;
                }
                Ok(())
            })?;
        }
        self.set_res(own, id, Res::TexGroup(n));
        Ok(())
    }

    pub(super) fn composite(
        &mut self,
        e: &BytesStart<'x>,
        empty: bool,
    ) -> Result<(), ThreeMfError> {
        let attrs = self.attrs(e)?;
        let id = self.id_attr("compositematerials", &attrs)?;
        let matid = Self::get(&attrs, Ns::None, "matid")
            .ok_or_else(|| self.missing("compositematerials", "matid"))?;
        let matid = self.u32_attr("compositematerials", "matid", matid)?;
        let mi = Self::get(&attrs, Ns::None, "matindices")
            .ok_or_else(|| self.missing("compositematerials", "matindices"))?;
        let matindices = self.u32_list("compositematerials", "matindices", mi)?;
        let Some(Res::Base(count)) = self.res_ref(matid) else {
            return Err(ThreeMfError::UnresolvedReference {
                at: self.x.loc(),
                element: "compositematerials",
                attribute: "matid",
                id: matid,
                expected: "a basematerials group defined earlier",
            });
        };
        if matindices.is_empty() {
            return Err(self.invalid("compositematerials", "matindices", mi, "empty list"));
        }
        for &i in &matindices {
            if i as usize >= count {
                return Err(ThreeMfError::IndexOutOfRange {
                    at: self.x.loc(),
                    element: "compositematerials",
                    attribute: "matindices",
                    index: i.into(),
                    count,
                });
            }
        }
        let own = self.add_res(id, Res::Composite(0))?;
        let mut n = 0usize;
        if !empty {
            self.children(|p, e, empty| {
                if !p.material_child(&e, "composite") {
                    return p.unknown(&e, empty);
                }
                let attrs = p.attrs(&e)?;
                let v = Self::get(&attrs, Ns::None, "values")
                    .ok_or_else(|| p.missing("composite", "values"))?;
                // Missing values default to 0 and extra values are ignored (materials 4.1);
                // each one must still be a number.
                for t in v.split(xml::is_xml_ws).filter(|t| !t.is_empty()) {
                    p.f64_attr("composite", "values", t)?;
                }
                n += 1;
                if !empty {
                    p.x.skip()?;
                }
                Ok(())
            })?;
        }
        self.set_res(own, id, Res::Composite(n));
        Ok(())
    }

    pub(super) fn multi(&mut self, e: &BytesStart<'x>, empty: bool) -> Result<(), ThreeMfError> {
        let attrs = self.attrs(e)?;
        let id = self.id_attr("multiproperties", &attrs)?;
        let pv = Self::get(&attrs, Ns::None, "pids")
            .ok_or_else(|| self.missing("multiproperties", "pids"))?;
        let pids = self.u32_list("multiproperties", "pids", pv)?;
        if pids.is_empty() {
            return Err(self.invalid("multiproperties", "pids", pv, "empty list"));
        }
        let counts = self.multi_layer_counts(id, &pids)?;
        if let Some(bm) = Self::get(&attrs, Ns::None, "blendmethods") {
            self.blend_methods(bm, pids.len())?;
        }
        let own = self.add_res(id, Res::Multi(0))?;
        let n = if empty {
            0
        } else {
            self.multi_children(id, &pids, &counts)?
        };
        self.set_res(own, id, Res::Multi(n));
        Ok(())
    }

    /// The number of entries of each property group that multiproperties `id` layers (`pids`),
    /// checking that they are groups defined earlier, with at most one material group, first,
    /// and at most one colour group. A texture is tolerated with a warning (count
    /// `usize::MAX`).
    fn multi_layer_counts(&mut self, id: u32, pids: &[u32]) -> Result<Vec<usize>, ThreeMfError> {
        let mut counts = Vec::with_capacity(pids.len());
        let (mut colors, mut materials) = (0, 0);
        for &pid in pids {
            let r = self.res_ref(pid);
            let unresolved = |expected| ThreeMfError::UnresolvedReference {
                at: self.x.loc(),
                element: "multiproperties",
                attribute: "pids",
                id: pid,
                expected,
            };
            match r {
                Some(Res::Base(n) | Res::Composite(n)) => {
                    materials += 1;
                    counts.push(n);
                }
                Some(Res::Color(n)) => {
                    colors += 1;
                    counts.push(n);
                }
                Some(Res::TexGroup(n)) => counts.push(n),
                Some(Res::Texture) => {
                    // Seen in the 3MF Consortium's own MUSTPASS files: tolerated, not indexed.
                    self.warn(format_args!(
                        "multiproperties {id}: pid {pid} is a texture2d, not a property group"
                    ));
                    counts.push(usize::MAX);
                }
                Some(Res::Multi(_)) => {
                    return Err(unresolved(
                        "a non-multiproperties property group (multiproperties must not reference multiproperties)",
                    ));
                }
                _ => {
                    return Err(unresolved(
                        "a basematerials, colorgroup, texture2dgroup or compositematerials group defined earlier",
                    ));
                }
            }
        }
        if materials > 0
            && !matches!(
                self.info.res.get(&pids[0]),
                Some(Res::Base(_) | Res::Composite(_))
            )
        {
            return Err(self.rule(
                "multiproperties",
                "a basematerials or compositematerials group in pids must be the first layer",
            ));
        }
        if materials > 1 {
            return Err(self.rule(
                "multiproperties",
                "pids may reference at most one basematerials or compositematerials group",
            ));
        }
        if colors > 1 {
            return Err(self.rule(
                "multiproperties",
                "pids may reference at most one colorgroup",
            ));
        }
        Ok(counts)
    }

    /// Checks `blendmethods`: at most one method per layer after the first, each `mix` or
    /// `multiply`.
    fn blend_methods(&self, bm: &str, layers: usize) -> Result<(), ThreeMfError> {
        let methods: Vec<&str> = bm.split(xml::is_xml_ws).filter(|t| !t.is_empty()).collect();
        if methods.len() >= layers {
            return Err(self.invalid(
                "multiproperties",
                "blendmethods",
                bm,
                "at most one blend method per pid after the first",
            ));
        }
        if let Some(bad) = methods.iter().find(|m| !matches!(**m, "mix" | "multiply")) {
            return Err(self.invalid(
                "multiproperties",
                "blendmethods",
                bad,
                "blend method must be mix or multiply",
            ));
        }
        Ok(())
    }

    /// Reads the `<multi>` children of multiproperties `id`, warning once about a `pindices`
    /// entry out of its layer's range; returns how many there are.
    fn multi_children(
        &mut self,
        id: u32,
        pids: &[u32],
        counts: &[usize],
    ) -> Result<usize, ThreeMfError> {
        let mut n = 0usize;
        let mut warned = false;
        self.children(|p, e, empty| {
            if !p.material_child(&e, "multi") {
                return p.unknown(&e, empty);
            }
            let attrs = p.attrs(&e)?;
            let v = Self::get(&attrs, Ns::None, "pindices")
                .ok_or_else(|| p.missing("multi", "pindices"))?;
            let mut idx = p.u32_list("multi", "pindices", v)?;
            // Missing indices default to 0, extra ones are ignored (materials 5.1).
            idx.truncate(counts.len());
            // Out-of-range layer indices are only warned about: the 3MF Consortium's own
            // MUSTPASS_Chapter3.4.2 / 3.4.3a files use them.
            if !warned
                && let Some((k, &i)) = idx
                    .iter()
                    .enumerate()
                    .find(|&(k, &i)| i as usize >= counts[k])
            {
                warned = true;
                p.warn(format_args!(
                    "multiproperties {id}: pindices {i} is out of range of pid {} (count {})",
                    pids[k], counts[k]
                ));
            }
            n += 1;
            if !empty {
                p.x.skip()?;
            }
            Ok(())
        })?;
        Ok(n)
    }
}
