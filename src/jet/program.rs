//! The job as a [`Program`]: every scheduled path a toolpath of lines and arcs between the
//! shutter's switch-on and switch-off, layer by layer at their z.
//!
//! Place in the pipeline: schedule → **program** → emit (the project's G-code writer, in its
//! switched-tool style: `Config::jet_gcode_params`).
//!
//! - Layer 0 starts by selecting `jet.tool`.
//! - Each path of a layer: [`Event::Switch`] on, the path ([`Role::JetWall`], or
//!   [`Role::JetFill`] for fill lines; `jet.tool`, the line width, the layer height,
//!   `jet.speed`; the chain's segments kept exactly as planned), [`Event::Switch`] off; both
//!   switches with `jet.shutter_lead_time`.

use super::JetSettings;
use super::schedule::{JetLayer, JetPath};
use crate::geom::Point3;
use crate::program::{Event, Layer, LayerItem, Program, Role, Toolpath};

/// The Program of the scheduled `layers`, lines `width` mm wide, with the `[jet]` settings.
pub fn program(layers: &[JetLayer], width: f64, settings: &JetSettings) -> Program {
    let layers = layers
        .iter()
        .map(|layer| {
            let mut items = Vec::new();
            if layer.index == 0 {
                items.push(LayerItem::Event(Event::ToolChange {
                    tool: settings.tool,
                }));
            }
            for path in &layer.paths {
                let Some(toolpath) = toolpath(path, layer, width, settings) else {
                    continue;
                };
                let lead_time = settings.shutter_lead_time;
                items.push(LayerItem::Event(Event::Switch {
                    on: true,
                    lead_time,
                }));
                items.push(LayerItem::Path(toolpath));
                items.push(LayerItem::Event(Event::Switch {
                    on: false,
                    lead_time,
                }));
            }
            Layer {
                index: layer.index,
                z: layer.z,
                height: layer.height,
                items,
            }
        })
        .collect();
    Program { layers }
}

/// The toolpath of `path` on `layer`; `None` for an empty chain.
fn toolpath(
    path: &JetPath,
    layer: &JetLayer,
    width: f64,
    settings: &JetSettings,
) -> Option<Toolpath> {
    let start = path.chain.start()?;
    let at = |p: [f64; 2]| Point3::new(p[0], p[1], layer.z);
    let points = std::iter::once(at(start))
        .chain(path.chain.segs.iter().map(|s| at(s.end())))
        .collect();
    Some(Toolpath {
        points,
        closed: false,
        role: if path.fill {
            Role::JetFill
        } else {
            Role::JetWall
        },
        tool: settings.tool,
        width,
        height: layer.height,
        speed: settings.speed,
        tool_axis: None,
        segments: Some(path.chain.segs.clone()),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::jet::path::{Chain, Seg};

    #[test]
    fn every_path_is_switched_on_and_off_around_it() {
        let chain = Chain {
            segs: vec![
                Seg::Line {
                    a: [0.0, 0.0],
                    b: [1.0, 0.0],
                },
                Seg::Arc {
                    a: [1.0, 0.0],
                    b: [2.0, 1.0],
                    c: [1.0, 1.0],
                    r: 1.0,
                    sweep: std::f64::consts::FRAC_PI_2,
                },
            ],
            closed: false,
        };
        let layer = JetLayer {
            index: 0,
            z: 0.005,
            height: 0.005,
            reversed: false,
            gap_place: 0,
            paths: vec![
                JetPath {
                    structure: 0,
                    chain: chain.clone(),
                    fill: true,
                    gapped: false,
                },
                JetPath {
                    structure: 0,
                    chain: Chain::default(),
                    fill: false,
                    gapped: false,
                },
            ],
        };
        let settings = JetSettings {
            shutter_lead_time: 0.05,
            ..JetSettings::default()
        };
        let p = program(&[layer], 0.02, &settings);
        let items = &p.layers[0].items;
        assert_eq!(items.len(), 4, "the empty chain is left out");
        assert_eq!(items[0], LayerItem::Event(Event::ToolChange { tool: 1 }));
        let switch = |on| {
            LayerItem::Event(Event::Switch {
                on,
                lead_time: 0.05,
            })
        };
        assert_eq!(items[1], switch(true));
        assert_eq!(items[3], switch(false));
        let LayerItem::Path(path) = &items[2] else {
            panic!("a path between the switches");
        };
        assert_eq!(path.role, Role::JetFill);
        assert_eq!(path.points.len(), 3);
        assert_eq!(path.points[2], Point3::new(2.0, 1.0, 0.005));
        assert_eq!(path.segments.as_deref(), Some(chain.segs.as_slice()));
        assert_eq!(path.length(), chain.length());
    }
}
