//! The in-memory description of a 3MF package: plain data, no behaviour beyond small helpers.
//!
//! These types describe the file as written. Converting into conduit's scene is the pipeline's
//! job; [`crate::FlatMesh`] is the one convenience view this crate offers.

use std::collections::BTreeMap;

use crate::Limits;

/// Unit of the model coordinates (`unit` attribute of `<model>`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Unit {
    /// 0.001 mm.
    Micron,
    /// 1 mm (the 3MF default when `unit` is absent).
    #[default]
    Millimeter,
    /// 10 mm.
    Centimeter,
    /// 25.4 mm.
    Inch,
    /// 304.8 mm.
    Foot,
    /// 1000 mm.
    Meter,
}

impl Unit {
    /// Length of one unit in millimetres.
    pub fn to_mm(self) -> f64 {
        match self {
            Unit::Micron => 0.001,
            Unit::Millimeter => 1.0,
            Unit::Centimeter => 10.0,
            Unit::Inch => 25.4,
            Unit::Foot => 304.8,
            Unit::Meter => 1000.0,
        }
    }

    /// The spelling used in the `unit` attribute.
    pub fn as_str(self) -> &'static str {
        match self {
            Unit::Micron => "micron",
            Unit::Millimeter => "millimeter",
            Unit::Centimeter => "centimeter",
            Unit::Inch => "inch",
            Unit::Foot => "foot",
            Unit::Meter => "meter",
        }
    }

    /// Parses the `unit` attribute value (exact, case-sensitive, as the schema requires).
    pub fn from_attr(s: &str) -> Option<Unit> {
        Some(match s {
            "micron" => Unit::Micron,
            "millimeter" => Unit::Millimeter,
            "centimeter" => Unit::Centimeter,
            "inch" => Unit::Inch,
            "foot" => Unit::Foot,
            "meter" => Unit::Meter,
            _ => return None,
        })
    }
}

/// A read 3MF package: every 3D model part that was reached from the root model.
#[derive(Debug, Clone, PartialEq)]
pub struct Package {
    /// Part name of the root model (the OPC StartPart target), e.g. `/3D/3dmodel.model`.
    pub root_path: String,
    /// Every model part that was read, keyed by its part name as spelled by the StartPart
    /// relationship or the referencing `p:path` / `slicepath` (always starting with `/`).
    pub models: BTreeMap<String, Model>,
    /// Non-fatal findings (ignored unknown elements, recognised-but-uninterpreted extensions,
    /// dangling optional relationships, ..., and in the default mode the harmless defects read
    /// past, see [`crate::ReadOptions`]), one line each, naming the part.
    pub warnings: Vec<String>,
    /// The limits the package was read with; [`Package::flatten`] enforces them on its output.
    pub limits: Limits,
    /// The profile, object settings and volume types a slicer stored beside the model (empty
    /// for other producers).
    pub slicer: crate::SlicerSettings,
}

impl Package {
    /// The root model (the StartPart target).
    ///
    /// # Panics
    /// Never for a `Package` returned by [`crate::read`], which always holds its root model; a
    /// hand-built package without it gets an empty static model instead.
    pub fn root(&self) -> &Model {
        static EMPTY: std::sync::OnceLock<Model> = std::sync::OnceLock::new();
        self.models
            .get(&self.root_path)
            .unwrap_or_else(|| EMPTY.get_or_init(Model::default))
    }
}

/// One 3D model part (`<model>` element).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Model {
    /// Coordinate unit.
    pub unit: Unit,
    /// `xml:lang` of the model element.
    pub language: Option<String>,
    /// Model-level `<metadata>` entries in file order (names are unique).
    pub metadata: Vec<Metadata>,
    /// Namespace URIs listed (by prefix) in `requiredextensions`, resolved.
    pub required_extensions: Vec<String>,
    /// `<object>` resources in file order.
    pub objects: Vec<Object>,
    /// `<basematerials>` resources in file order.
    pub base_materials: Vec<BaseMaterials>,
    /// `<m:colorgroup>` resources in file order.
    pub color_groups: Vec<ColorGroup>,
    /// `<build>` items in file order.
    pub build: Vec<BuildItem>,
}

impl Model {
    /// The object with resource id `id`, if any.
    pub fn object(&self, id: u32) -> Option<&Object> {
        self.objects.iter().find(|o| o.id == id)
    }
}

/// A `<metadata name="...">value</metadata>` entry.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Metadata {
    /// The `name` attribute (may carry a namespace prefix such as `slic3rpe:Version3mf`).
    pub name: String,
    /// Text content.
    pub value: String,
}

/// A `<basematerials>` group.
#[derive(Debug, Clone, PartialEq)]
pub struct BaseMaterials {
    /// Resource id.
    pub id: u32,
    /// The `<base>` entries; a property index selects one of them.
    pub materials: Vec<BaseMaterial>,
}

/// A `<base name=".." displaycolor="#RRGGBB[AA]"/>` entry.
#[derive(Debug, Clone, PartialEq)]
pub struct BaseMaterial {
    /// Material name.
    pub name: String,
    /// Display colour as sRGB RGBA (alpha 255 when the file gives `#RRGGBB`).
    pub display_color: [u8; 4],
}

/// A materials-extension `<m:colorgroup>`.
#[derive(Debug, Clone, PartialEq)]
pub struct ColorGroup {
    /// Resource id.
    pub id: u32,
    /// sRGB RGBA colours; a property index selects one of them.
    pub colors: Vec<[u8; 4]>,
}

/// `type` attribute of `<object>`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum ObjectType {
    /// `model` (the default): a part to print.
    #[default]
    Model,
    /// `support`: support structure the producer generated.
    Support,
    /// `solidsupport`: support that must be printed solid.
    SolidSupport,
    /// `surface`: an open surface.
    Surface,
    /// `other`: not printable; build items must not reference it.
    Other,
}

impl ObjectType {
    /// The spelling used in the `type` attribute.
    pub fn as_str(self) -> &'static str {
        match self {
            ObjectType::Model => "model",
            ObjectType::Support => "support",
            ObjectType::SolidSupport => "solidsupport",
            ObjectType::Surface => "surface",
            ObjectType::Other => "other",
        }
    }

    /// Parses the `type` attribute value.
    pub fn from_attr(s: &str) -> Option<ObjectType> {
        Some(match s {
            "model" => ObjectType::Model,
            "support" => ObjectType::Support,
            "solidsupport" => ObjectType::SolidSupport,
            "surface" => ObjectType::Surface,
            "other" => ObjectType::Other,
            _ => return None,
        })
    }
}

/// An `<object>` resource.
#[derive(Debug, Clone, PartialEq)]
pub struct Object {
    /// Resource id (unique among all resources of its model part).
    pub id: u32,
    /// `name` attribute.
    pub name: Option<String>,
    /// `type` attribute.
    pub kind: ObjectType,
    /// Default property group for the object's triangles.
    pub pid: Option<u32>,
    /// Default index into the `pid` group.
    pub pindex: Option<u32>,
    /// Geometry: a mesh or a list of components.
    pub content: ObjectContent,
}

/// What an object is made of.
#[derive(Debug, Clone, PartialEq)]
pub enum ObjectContent {
    /// A triangle mesh (possibly empty, e.g. a beam-lattice-only or slice-only object).
    Mesh(Mesh),
    /// Other objects placed with transforms.
    Components(Vec<Component>),
}

/// An indexed triangle mesh in model units.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Mesh {
    /// Vertex positions.
    pub vertices: Vec<[f64; 3]>,
    /// Triangles indexing `vertices`.
    pub triangles: Vec<Triangle>,
}

/// A `<triangle>`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Triangle {
    /// Vertex indices `v1 v2 v3` (in range and distinct).
    pub v: [u32; 3],
    /// Property group overriding the object's `pid`.
    pub pid: Option<u32>,
    /// Property indices `p1 p2 p3` for the three corners.
    pub p: [Option<u32>; 3],
}

/// A `<component>` of an object.
#[derive(Debug, Clone, PartialEq)]
pub struct Component {
    /// Referenced object id.
    pub object_id: u32,
    /// Production extension `p:path`: the model part holding the object (absolute part name).
    pub path: Option<String>,
    /// Affine transform in 3MF row layout `m00 m01 m02 m10 m11 m12 m20 m21 m22 m30 m31 m32`
    /// (row vector convention: `p' = [x y z 1] * M`, translation last).
    pub transform: Option<[f64; 12]>,
}

/// A build `<item>`.
#[derive(Debug, Clone, PartialEq)]
pub struct BuildItem {
    /// Referenced object id.
    pub object_id: u32,
    /// Production extension `p:path`: the model part holding the object (absolute part name).
    pub path: Option<String>,
    /// Affine transform, same layout as [`Component::transform`].
    pub transform: Option<[f64; 12]>,
    /// `partnumber` attribute.
    pub part_number: Option<String>,
}

/// The identity transform in 3MF row layout.
pub const IDENTITY: [f64; 12] = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0];
