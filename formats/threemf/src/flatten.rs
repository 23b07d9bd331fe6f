//! Resolving build items through components into plain meshes in millimetres.

use std::collections::HashMap;

use crate::error::ThreeMfError;
use crate::model::{IDENTITY, Model, Object, ObjectContent, ObjectType};
use crate::{Package, opc};

/// One build item resolved through its (nested, possibly cross-part) components into a plain
/// triangle mesh in millimetres, with every transform applied.
#[derive(Debug, Clone, PartialEq)]
pub struct FlatMesh {
    /// Name of the item's object (`object <id>` when it has none).
    pub name: String,
    /// Index of the build item in the root model's `build`.
    pub build_item: usize,
    /// Object id the build item references.
    pub object_id: u32,
    /// Type of that object (supports are flattened too; callers decide what to print).
    pub kind: ObjectType,
    /// Vertex positions in millimetres (root model unit converted).
    pub vertices: Vec<[f64; 3]>,
    /// Triangles indexing `vertices`. Winding is reversed for meshes placed by a mirroring
    /// transform, so outward normals stay outward.
    pub triangles: Vec<[u32; 3]>,
    /// Per triangle: `(pid, p1)` from the triangle, else from its object's `pid`/`pindex`
    /// (`None` when neither gives both). Ids refer to resources of the model part that
    /// defines the mesh.
    pub triangle_properties: Vec<Option<(u32, u32)>>,
    /// Per triangle: the id of the mesh object it comes from and its index in that mesh, which
    /// is how a slicer's volumes ([`crate::VolumeMesh`]) name triangles.
    pub triangle_sources: Vec<(u32, u32)>,
    /// Whether any mesh of this item was placed by a transform with negative determinant.
    pub mirrored: bool,
}

/// Composes two 3MF transforms: the result applies `a` first, then `b`
/// (row vectors: `p * A * B`).
pub fn compose(a: &[f64; 12], b: &[f64; 12]) -> [f64; 12] {
    let mut m = [0.0; 12];
    for r in 0..4 {
        for c in 0..3 {
            let mut s = if r == 3 { b[9 + c] } else { 0.0 };
            for k in 0..3 {
                s += a[r * 3 + k] * b[k * 3 + c];
            }
            m[r * 3 + c] = s;
        }
    }
    m
}

/// Applies a 3MF transform to a point.
pub fn apply(m: &[f64; 12], p: [f64; 3]) -> [f64; 3] {
    let [x, y, z] = p;
    [
        x * m[0] + y * m[3] + z * m[6] + m[9],
        x * m[1] + y * m[4] + z * m[7] + m[10],
        x * m[2] + y * m[5] + z * m[8] + m[11],
    ]
}

/// Determinant of the linear 3x3 part.
pub fn determinant(m: &[f64; 12]) -> f64 {
    m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6])
        + m[2] * (m[3] * m[7] - m[4] * m[6])
}

impl Package {
    /// Resolves every build item of the root model into a [`FlatMesh`] in millimetres.
    ///
    /// Coordinates of every part are taken in the root model's unit (the build and its
    /// transforms are expressed in it). Nesting deeper than `limits.max_component_depth`, and
    /// output beyond `limits.max_vertices` / `limits.max_triangles` in total, are errors, so a
    /// small file that instances a mesh exponentially often can not exhaust memory.
    pub fn flatten(&self) -> Result<Vec<FlatMesh>, ThreeMfError> {
        let by_key: HashMap<String, PartView<'_>> = self
            .models
            .iter()
            .map(|(k, m)| {
                let objects = m.objects.iter().map(|o| (o.id, o)).collect();
                (opc::key(k), (k.as_str(), m, objects))
            })
            .collect();
        let root = self.root();
        let scale = root.unit.to_mm();
        let mut out = Vec::with_capacity(root.build.len().min(4096));
        let mut budget = Budget {
            vertices: 0,
            triangles: 0,
        };
        for (i, item) in root.build.iter().enumerate() {
            let part = item.path.as_deref().unwrap_or(&self.root_path);
            let (pname, _, objects) = lookup(&by_key, part)?;
            let obj = *objects
                .get(&item.object_id)
                .ok_or_else(|| unresolved(pname, item.object_id))?;
            let mut fm = FlatMesh {
                name: obj
                    .name
                    .clone()
                    .unwrap_or_else(|| format!("object {}", obj.id)),
                build_item: i,
                object_id: item.object_id,
                kind: obj.kind,
                vertices: Vec::new(),
                triangles: Vec::new(),
                triangle_properties: Vec::new(),
                triangle_sources: Vec::new(),
                mirrored: false,
            };
            // Transforms stay in model units; the unit scale is applied per vertex at the end.
            let t = item.transform.unwrap_or(IDENTITY);
            self.emit(
                &by_key,
                pname,
                item.object_id,
                &t,
                0,
                scale,
                &mut fm,
                &mut budget,
            )?;
            out.push(fm);
        }
        Ok(out)
    }

    #[allow(clippy::too_many_arguments)]
    fn emit(
        &self,
        by_key: &HashMap<String, PartView<'_>>,
        part: &str,
        object_id: u32,
        t: &[f64; 12],
        depth: usize,
        scale: f64,
        fm: &mut FlatMesh,
        budget: &mut Budget,
    ) -> Result<(), ThreeMfError> {
        // `emit` recurses once per nesting level; the hard cap keeps the stack bounded even
        // when a caller raises `max_component_depth` to an absurd value.
        if depth > self.limits.max_component_depth.min(MAX_RECURSION) {
            return Err(ThreeMfError::LimitExceeded {
                part: part.to_string(),
                limit: "max_component_depth",
                max: self.limits.max_component_depth as u64,
                found: depth as u64,
            });
        }
        let (pname, _, objects) = lookup(by_key, part)?;
        let obj = *objects
            .get(&object_id)
            .ok_or_else(|| unresolved(pname, object_id))?;
        match &obj.content {
            ObjectContent::Mesh(mesh) => {
                budget.vertices += mesh.vertices.len();
                budget.triangles += mesh.triangles.len();
                if budget.vertices > self.limits.max_vertices {
                    return Err(ThreeMfError::LimitExceeded {
                        part: pname.to_string(),
                        limit: "max_vertices",
                        max: self.limits.max_vertices as u64,
                        found: budget.vertices as u64,
                    });
                }
                if budget.triangles > self.limits.max_triangles {
                    return Err(ThreeMfError::LimitExceeded {
                        part: pname.to_string(),
                        limit: "max_triangles",
                        max: self.limits.max_triangles as u64,
                        found: budget.triangles as u64,
                    });
                }
                let mirror = determinant(t) < 0.0;
                fm.mirrored |= mirror;
                let base =
                    u32::try_from(fm.vertices.len()).map_err(|_| ThreeMfError::LimitExceeded {
                        part: pname.to_string(),
                        limit: "max_vertices",
                        max: u32::MAX as u64,
                        found: fm.vertices.len() as u64,
                    })?;
                fm.vertices.extend(mesh.vertices.iter().map(|&p| {
                    let [x, y, z] = apply(t, p);
                    [x * scale, y * scale, z * scale]
                }));
                for (i, tri) in mesh.triangles.iter().enumerate() {
                    // The triangle count is bounded by `max_triangles`, far below u32::MAX.
                    fm.triangle_sources
                        .push((object_id, u32::try_from(i).unwrap_or(u32::MAX)));
                    let [a, b, c] = tri.v.map(|v| v + base);
                    fm.triangles
                        .push(if mirror { [a, c, b] } else { [a, b, c] });
                    let pid = tri.pid.or(obj.pid);
                    let p1 = tri.p[0].or(obj.pindex);
                    fm.triangle_properties.push(pid.zip(p1));
                }
            }
            ObjectContent::Components(comps) => {
                for c in comps {
                    let m = compose(&c.transform.unwrap_or(IDENTITY), t);
                    let cpart = c.path.as_deref().unwrap_or(pname);
                    self.emit(by_key, cpart, c.object_id, &m, depth + 1, scale, fm, budget)?;
                }
            }
        }
        Ok(())
    }
}

/// Deepest component nesting `flatten` follows whatever the limits say (stack safety).
const MAX_RECURSION: usize = 4096;

struct Budget {
    vertices: usize,
    triangles: usize,
}

/// A model part as `flatten` sees it: name, model, objects by id.
type PartView<'m> = (&'m str, &'m Model, HashMap<u32, &'m Object>);

fn lookup<'v, 'm>(
    by_key: &'v HashMap<String, PartView<'m>>,
    part: &str,
) -> Result<&'v PartView<'m>, ThreeMfError> {
    by_key
        .get(&opc::key(part))
        .ok_or_else(|| ThreeMfError::MissingPart {
            part: part.to_string(),
            needed_for: "flatten: referenced model part was not read".into(),
        })
}

fn unresolved(part: &str, id: u32) -> ThreeMfError {
    ThreeMfError::UnresolvedReference {
        at: crate::Location::part(part),
        element: "item",
        attribute: "objectid",
        id,
        expected: "an object",
    }
}
