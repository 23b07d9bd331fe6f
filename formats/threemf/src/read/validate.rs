//! Checks that need every model part: object and slice references across parts, and the
//! component graph.

use super::*;

pub(super) fn check_object_ref(r: &ObjectRef, res: Option<Res>) -> Result<(), ThreeMfError> {
    match res {
        Some(Res::Object(kind)) => {
            if r.element == "item" && kind == ObjectType::Other {
                return Err(ThreeMfError::Rule {
                    at: r.at.clone(),
                    element: "item",
                    rule: "a build item must not reference an object of type \"other\"",
                });
            }
            Ok(())
        }
        _ => Err(ThreeMfError::UnresolvedReference {
            at: r.at.clone(),
            element: r.element,
            attribute: "objectid",
            id: r.object_id,
            expected: "an object",
        }),
    }
}

fn part_of<'p>(
    parts: &'p BTreeMap<String, PartInfo>,
    seen: &HashMap<String, String>,
    path: &str,
) -> Option<&'p PartInfo> {
    seen.get(&opc::key(path)).and_then(|p| parts.get(p))
}

pub(super) fn validate_cross_part(
    parts: &BTreeMap<String, PartInfo>,
    seen: &HashMap<String, String>,
    root: &str,
) -> Result<(), ThreeMfError> {
    // Slice references first, then object references (a file broken in both ways reports
    // the slice problem, which is the rarer and more specific one).
    for info in parts.values() {
        for s in &info.slice_refs {
            let target = match s.path.as_deref() {
                None => info,
                Some(p) => part_of(parts, seen, p).ok_or_else(|| ThreeMfError::MissingPart {
                    part: p.to_string(),
                    needed_for: format!("slicepath at {}", s.at),
                })?,
            };
            match target.res.get(&s.stack_id) {
                Some(Res::SliceStack { has_refs: false }) => {}
                Some(Res::SliceStack { has_refs: true }) => {
                    return Err(ThreeMfError::Rule {
                        at: s.at.clone(),
                        element: "sliceref",
                        rule: "a referenced slice stack must not itself contain slicerefs (references nested too deep)",
                    });
                }
                _ => {
                    return Err(ThreeMfError::UnresolvedReference {
                        at: s.at.clone(),
                        element: "sliceref",
                        attribute: "slicestackid",
                        id: s.stack_id,
                        expected: "a slicestack in the referenced part",
                    });
                }
            }
        }
        for (at, sid) in &info.slicestack_uses {
            if !matches!(info.res.get(sid), Some(Res::SliceStack { .. })) {
                return Err(ThreeMfError::UnresolvedReference {
                    at: at.clone(),
                    element: "object",
                    attribute: "s:slicestackid",
                    id: *sid,
                    expected: "a slicestack",
                });
            }
        }
    }
    for (name, info) in parts {
        let me = opc::key(name);
        for r in &info.object_refs {
            let path = r.path.as_deref().filter(|p| opc::key(p) != me);
            let Some(path) = path else {
                check_object_ref(r, info.res.get(&r.object_id).copied())?;
                continue;
            };
            if name != root && r.element == "item" {
                return Err(ThreeMfError::Rule {
                    at: r.at.clone(),
                    element: "item",
                    rule: "only the root model part has build items",
                });
            }
            let target = part_of(parts, seen, path).ok_or_else(|| ThreeMfError::MissingPart {
                part: path.to_string(),
                needed_for: format!("p:path of <{}> at {}", r.element, r.at),
            })?;
            check_object_ref(r, target.res.get(&r.object_id).copied())?;
        }
    }
    Ok(())
}

/// Rejects component cycles and nesting deeper than `max_component_depth`.
///
/// Iterative depth-first search over (part, object) nodes with memoised depths: linear in the
/// number of components, whatever the nesting.
pub(super) fn check_component_graph(
    parts: &BTreeMap<String, PartInfo>,
    limits: &Limits,
) -> Result<(), ThreeMfError> {
    type Node = (usize, usize); // (part index, object index)
    let names: Vec<&String> = parts.keys().collect();
    let infos: Vec<&PartInfo> = parts.values().collect();
    let part_index: HashMap<String, usize> = names
        .iter()
        .enumerate()
        .map(|(i, n)| (opc::key(n), i))
        .collect();
    let obj_index: Vec<HashMap<u32, usize>> = infos
        .iter()
        .map(|p| {
            p.model
                .objects
                .iter()
                .enumerate()
                .map(|(i, o)| (o.id, i))
                .collect()
        })
        .collect();
    // Unresolved references were reported by `validate_cross_part`; they are skipped here.
    let resolve = |pi: usize, c: &Component| -> Option<Node> {
        let tp = match &c.path {
            Some(p) => *part_index.get(&opc::key(p))?,
            None => pi,
        };
        Some((tp, *obj_index[tp].get(&c.object_id)?))
    };
    let components = |n: Node| -> &[Component] {
        match &infos[n.0].model.objects[n.1].content {
            ObjectContent::Components(c) => c,
            ObjectContent::Mesh(_) => &[],
        }
    };
    let too_deep = |n: Node, found: usize| ThreeMfError::LimitExceeded {
        part: names[n.0].clone(),
        limit: "max_component_depth",
        max: limits.max_component_depth as u64,
        found: found as u64,
    };
    let mut depth: HashMap<Node, usize> = HashMap::new();
    for (pi, info) in infos.iter().enumerate() {
        for oi in 0..info.model.objects.len() {
            let start = (pi, oi);
            if components(start).is_empty() || depth.contains_key(&start) {
                continue;
            }
            let mut stack: Vec<(Node, usize)> = vec![(start, 0)];
            let mut on_stack: HashSet<Node> = HashSet::from([start]);
            while let Some(&mut (node, ref mut next)) = stack.last_mut() {
                let comps = components(node);
                if *next < comps.len() {
                    let c = &comps[*next];
                    *next += 1;
                    let Some(child) = resolve(node.0, c) else {
                        continue;
                    };
                    if depth.contains_key(&child) {
                        continue;
                    }
                    if on_stack.contains(&child) {
                        return Err(ThreeMfError::ComponentCycle {
                            part: names[child.0].clone(),
                            object_id: c.object_id,
                        });
                    }
                    if stack.len() >= limits.max_component_depth {
                        return Err(too_deep(node, stack.len() + 1));
                    }
                    stack.push((child, 0));
                    on_stack.insert(child);
                } else {
                    let d = comps
                        .iter()
                        .filter_map(|c| resolve(node.0, c))
                        .map(|ch| depth.get(&ch).copied().unwrap_or(0) + 1)
                        .max()
                        .unwrap_or(0);
                    if d > limits.max_component_depth {
                        return Err(too_deep(node, d));
                    }
                    depth.insert(node, d);
                    on_stack.remove(&node);
                    stack.pop();
                }
            }
        }
    }
    Ok(())
}

/// Default mode: a resource id that an earlier resource of the same part already had is
/// harmless when nothing references the id (the later definition was dropped, the first
/// kept); one warning each. When something references it, the reference could mean either
/// definition and the package is refused, as in strict mode.
pub(super) fn check_duplicate_ids(
    parts: &BTreeMap<String, PartInfo>,
    seen: &HashMap<String, String>,
) -> Result<Vec<String>, ThreeMfError> {
    if parts.values().all(|p| p.duplicate_ids.is_empty()) {
        return Ok(Vec::new());
    }
    // (part key, id) of every reference across parts.
    let mut used: HashSet<(String, u32)> = HashSet::new();
    for (name, info) in parts {
        let me = opc::key(name);
        let target = |path: Option<&str>| {
            path.map(|p| {
                seen.get(&opc::key(p))
                    .map_or_else(|| opc::key(p), |t| opc::key(t))
            })
            .unwrap_or_else(|| me.clone())
        };
        used.extend(info.used_ids.iter().map(|&id| (me.clone(), id)));
        used.extend(info.slicestack_uses.iter().map(|&(_, id)| (me.clone(), id)));
        for r in &info.object_refs {
            used.insert((target(r.path.as_deref()), r.object_id));
        }
        for s in &info.slice_refs {
            used.insert((target(s.path.as_deref()), s.stack_id));
        }
    }
    let mut warnings = Vec::new();
    for (name, info) in parts {
        let me = opc::key(name);
        for (at, id) in &info.duplicate_ids {
            if used.contains(&(me.clone(), *id)) {
                return Err(ThreeMfError::DuplicateResourceId {
                    at: at.clone(),
                    id: *id,
                });
            }
            warnings.push(format!(
                "{at}: resource id {id} is already used by another resource in this part; nothing references it, the first definition is kept"
            ));
        }
    }
    Ok(warnings)
}
