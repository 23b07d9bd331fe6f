//! conduit's integration tests: one binary, one module per area.
//!
//! Tests that need the shared corpus (`../shared/corpus` beside the checkout) print
//! `skipped: corpus not found` and pass when it is absent.

mod architecture;
mod board_copper;
mod browser;
mod calibrate;
mod clfff;
mod cli;
mod compensate;
mod conform;
mod conformance;
mod curved;
mod docs;
mod electrical;
mod electronics;
mod electronics_corpus;
mod fuzz_stable;
mod golden;
mod grammar;
mod jet;
mod kicad;
mod outputs;
mod overhangs;
mod pack_corpus;
mod place;
mod postprocess;
mod postprocess_e2e;
mod postprocess_octopnp;
mod preview;
mod prusa_macros;
mod regressions_conform;
mod regressions_route;
mod regressions_slice;
mod retractions;
mod robot;
mod roundtrip;
mod route_help;
mod route_limits;
mod slice;
mod slice_3mf;
mod studio;
mod support;
mod thin_walls;
mod three_de;
mod view;
mod wipe_tower;
