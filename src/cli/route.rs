//! `conduit route`: a circuit placed in models and routed, shown as one SVG per layer, without
//! G-code.

use super::{Failure, args::RouteArgs};
use anyhow::Context;
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
    let (scene, cfg) = super::slice::models_and_config(&args.models, &args.config)?;
    let electronics = super::slice::load_electronics(&args.circuit, &args.placement)?;
    let (bar, routing) = super::progress::routing_bar();
    let view = route_scene(&scene, &cfg, &electronics, |_| {}, Some(&routing))
        .with_context(|| format!("routing {}", args.circuit.display()))?;
    bar.finish_and_clear();
    std::fs::create_dir_all(&args.out_dir)
        .with_context(|| format!("{}: cannot create the folder", args.out_dir.display()))?;
    let mut written = Vec::new();
    if let Some(bounds) = view_box(&view.layers) {
        for (i, layer) in view.layers.iter().enumerate() {
            let path = args.out_dir.join(format!("layer_{:04}.svg", i + 1));
            let svg = layer_svg(layer, bounds, cfg.route.conductive_width);
            outputs.add(&path, svg.as_bytes())?;
            written.push(path);
        }
    }
    if let Some(report) = &args.report {
        let json = serde_json::to_vec_pretty(&view.report).context("serialising the report")?;
        outputs.add(report, &json)?;
    }
    outputs.commit()?;
    if args.json {
        let r = &view.report;
        super::print_json(&serde_json::json!({
            "outputs": super::paths(written.iter().map(|p| p.as_path()).chain(args.report.as_deref())),
            "layers": view.layers.len(),
            "parts": r.parts.len(),
            "wires": r.routed + r.unrouted,
            "routed": r.routed,
            "trace_mm": r.total_length,
            "straight_mm": r.total_lower_bound,
            "report": r,
        }))?;
        super::slice::routing_warnings(r);
        return super::slice::refuse_unbuilt_circuit(
            r,
            args.allow_unrouted,
            &args.out_dir,
            "the drawings show where",
        );
    }
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
