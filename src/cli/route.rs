//! `conduit route`: a circuit placed in models and routed, shown as one SVG per layer, without
//! G-code.

use super::{Failure, args::RouteArgs, config::resolve};
use anyhow::Context;
use conduit::circuit::Electronics;
use conduit::circuit::{Circuit, Placement};
use conduit::emit::route_svg::{layer_svg, view_box};
use conduit::pipeline::route_scene;
use conduit::scene::OutputSet;

pub(crate) fn run(args: RouteArgs) -> Result<(), Failure> {
    let mut outputs = OutputSet::new(&args.models);
    for p in [&args.circuit, &args.placement]
        .into_iter()
        .chain(&args.config.config)
    {
        outputs.input(p);
    }
    if let Some(report) = &args.report {
        outputs.check(report)?;
    }
    let cfg = resolve(&args.config)?;
    let scene = super::slice::load_models(&args.models)?;
    let electronics = Electronics {
        circuit: Circuit::load(&args.circuit).map_err(anyhow::Error::from)?,
        placement: Placement::load(&args.placement).map_err(anyhow::Error::from)?,
    };
    let view = route_scene(&scene, &cfg, &electronics, |_| {})
        .with_context(|| format!("routing {}", args.circuit.display()))?;
    std::fs::create_dir_all(&args.out_dir)
        .with_context(|| format!("{}: cannot create the folder", args.out_dir.display()))?;
    if let Some(bounds) = view_box(&view.layers) {
        for (i, layer) in view.layers.iter().enumerate() {
            let path = args.out_dir.join(format!("layer_{:04}.svg", i + 1));
            let svg = layer_svg(layer, bounds, cfg.route.conductive_width);
            outputs.add(&path, svg.as_bytes())?;
        }
    }
    if let Some(report) = &args.report {
        let json = serde_json::to_vec_pretty(&view.report).context("serialising the report")?;
        outputs.add(report, &json)?;
    }
    outputs.commit()?;
    let lead = format!(
        "{}: {} layers drawn; ",
        args.out_dir.display(),
        view.layers.len()
    );
    super::slice::print_routing(&view.report, &lead);
    super::slice::refuse_unbuilt_circuit(
        &view.report,
        args.allow_unrouted,
        &args.out_dir,
        "the drawings show where",
    )
}
