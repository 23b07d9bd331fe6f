//! The toolpaths stage: each layer's regions, and what the other stages add to a layer
//! ([`LayerExtras`]: part events, conductive traces, curved layers), become a [`Program`] — toolpaths with
//! roles, widths, heights and speeds in print order, with tool changes between tools.
//!
//! Place in the pipeline: slice → regions (→ electronics) → **toolpaths** → emit. It takes its
//! own parameters ([`ProgramParams`], built from the config by the walk) and produces the model
//! every writer consumes ([`crate::program`]).
//!
//! - [`build`]: regions → Program ([`build_program`], [`build_program_with`]).
//! - [`order`]: travel ordering (nearest neighbour, then 2-opt / or-opt, deterministic).
//! - [`overhang`]: perimeters cut by overhang degree (speed, role, fan), bridges' fan.
//! - [`travel`]: the travels inside the internal infill, which need no retraction.
//! - [`tower`]: the wipe tower, where a tool just selected purges (a pass over the built
//!   Program).

pub mod build;
pub mod order;
pub mod overhang;
pub mod tower;
pub mod travel;

use crate::geom::Point2;

/// The box around `points`, nm: `[min_x, min_y, max_x, max_y]` (an empty box, which holds no
/// point, for none).
fn bounds<'a>(points: impl Iterator<Item = &'a Point2>) -> [i64; 4] {
    points.fold([i64::MAX, i64::MAX, i64::MIN, i64::MIN], |b, p| {
        [b[0].min(p.x), b[1].min(p.y), b[2].max(p.x), b[3].max(p.y)]
    })
}

pub use build::{
    ObjectLayers, ProgramParams, RoleSpeeds, ToolPathParams, build_program, build_program_with,
};
pub use order::{Group, OrderParams, SeamRule, order_groups, order_paths, travel_length};
pub use overhang::OverhangParams;
pub use tower::{TowerError, TowerMachine, TowerParams, TowerSummary, add_wipe_tower};
pub use travel::TravelParams;
