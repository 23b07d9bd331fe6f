//! Slice stacks and beam lattices: validated, not interpreted.

use quick_xml::events::BytesStart;

use super::*;

impl<'x> Parser<'x, '_, '_, '_> {
    pub(super) fn slice_stack(
        &mut self,
        e: &BytesStart<'x>,
        empty: bool,
    ) -> Result<(), ThreeMfError> {
        let attrs = self.attrs(e)?;
        let id = self.id_attr("slicestack", &attrs)?;
        let own = self.add_res(id, Res::SliceStack { has_refs: false })?;
        let (mut slices, mut refs) = (0usize, 0usize);
        if !empty {
            self.children(|p, e, empty| {
                let ns = p.x.element_ns(&e);
                match (ns, e.local_name().as_ref()) {
                    (Ns::Slice, "slice") => {
                        slices += 1;
                        if !empty {
                            p.x.skip()?;
                        }
                        Ok(())
                    }
                    (Ns::Slice, "sliceref") => {
                        refs += 1;
                        let attrs = p.attrs(&e)?;
                        let sid = Self::get(&attrs, Ns::None, "slicestackid")
                            .ok_or_else(|| p.missing("sliceref", "slicestackid"))?;
                        let stack_id = p.u32_attr("sliceref", "slicestackid", sid)?;
                        let path = Self::get(&attrs, Ns::None, "slicepath").map(|v| {
                            opc::resolve_target(p.part(), v).unwrap_or_else(|| v.to_string())
                        });
                        if let Some(path) = &path
                            && opc::key(path) != opc::key(p.part())
                        {
                            p.info.referenced_parts.push(path.clone());
                        }
                        p.info.slice_refs.push(SliceRef {
                            at: p.x.loc(),
                            stack_id,
                            path,
                        });
                        if !empty {
                            p.x.skip()?;
                        }
                        Ok(())
                    }
                    _ => p.unknown(&e, empty),
                }
            })?;
        }
        if slices > 0 && refs > 0 {
            return Err(self.rule(
                "slicestack",
                "a slice stack contains either slices or slicerefs, not both",
            ));
        }
        self.set_res(own, id, Res::SliceStack { has_refs: refs > 0 });
        Ok(())
    }

    /// Beam lattices are not interpreted, but the rules lib3mf warns about are reported as
    /// warnings: clipping/representation meshes must be objects defined earlier, only `model`
    /// and `solidsupport` objects carry lattices, beam set identifiers are unique.
    pub(super) fn beam_lattice(
        &mut self,
        e: &BytesStart<'x>,
        empty: bool,
        obj_id: u32,
        obj_kind: ObjectType,
    ) -> Result<(), ThreeMfError> {
        let attrs = self.attrs(e)?;
        if !matches!(obj_kind, ObjectType::Model | ObjectType::SolidSupport) {
            self.warn(format_args!(
                "object {obj_id}: a beam lattice is only allowed in objects of type model or solidsupport"
            ));
        }
        for a in ["clippingmesh", "representationmesh"] {
            if let Some(v) = Self::get(&attrs, Ns::None, a) {
                let ok = parse_u32(v)
                    .ok()
                    .and_then(|id| self.res_ref(id))
                    .is_some_and(|r| matches!(r, Res::Object(_)));
                if !ok {
                    self.warn(format_args!(
                        "object {obj_id}: beamlattice {a}={v} does not reference an object defined earlier"
                    ));
                }
            }
        }
        if empty {
            return Ok(());
        }
        self.children(|p, e, empty| {
            if p.x.element_ns(&e) != Ns::Beam || e.local_name().as_ref() != "beamsets" || empty {
                if !empty {
                    p.x.skip()?;
                }
                return Ok(());
            }
            let mut ids: HashSet<String> = HashSet::new();
            p.children(|p, e, empty| {
                if e.local_name().as_ref() == "beamset" {
                    let attrs = p.attrs(&e)?;
                    if let Some(id) = Self::get(&attrs, Ns::None, "identifier") {
                        if !ids.insert(id.to_string()) {
                            p.warn(format_args!(
                                "object {obj_id}: beamset identifier {id:?} is not unique"
                            ));
                        }
                    }
                }
                if !empty {
                    p.x.skip()?;
                }
                Ok(())
            })
        })
    }
}
