//! Step 1 of curved-layer FFF: the shell on the bed.
//!
//! Place in the pipeline: the pipeline centres the scene on the bed with its lowest point on it
//! ([`crate::pipeline::place_on_bed`]); [`raise`] then lifts it by `curved.raise` (room for
//! scaffold) plus one layer height when a buffer layer is printed (the buffer's bead hangs one
//! layer below the shell's bottom surface, so the buffer's lowest point lands at
//! `curved.raise`).

use crate::curved::CurvedParams;
use crate::geom::Transform;
use crate::mesh::Mesh;

/// How far [`raise`] lifts the shell, mm.
pub fn raise_height(cfg: &CurvedParams) -> f64 {
    let buffer = if cfg.curved.buffer {
        cfg.region.layer_height
    } else {
        0.0
    };
    cfg.curved.raise + buffer
}

/// Lifts meshes already on the bed by [`raise_height`]; returns the lift, mm.
pub fn raise(meshes: &mut [Mesh], cfg: &CurvedParams) -> f64 {
    let dz = raise_height(cfg);
    if dz != 0.0 {
        let t = Transform::translation(0.0, 0.0, dz);
        for m in meshes {
            m.transform(&t);
        }
    }
    dz
}
