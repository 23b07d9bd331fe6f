//! `conduit postprocess`: the slicer plugin entry point. Reads the host's G-code and settings,
//! rebuilds its layers, applies the edits a circuit asks for and writes the file back in place
//! (a temporary file beside it, then a rename) — only when something changed, so a run without
//! circuit leaves the file exactly as the host wrote it.

use super::{Failure, args::ConfigSource, args::PostprocessArgs, config::resolve};
use anyhow::Context;
use conduit::circuit::Electronics;
use conduit::config::{Config, HostSettings};
use conduit::pipeline::postprocess::{Edit, HostPrint, edit, edit_circuit_watched};
use conduit::postprocess::rewrite::SUMMARY_PREFIX;
use conduit::postprocess::{detect_host, output_name_file, read_gcode};
use conduit::scene::OutputSet;

pub(crate) fn run(args: PostprocessArgs) -> Result<(), Failure> {
    let path = &args.file;
    // The G-code is rewritten in place (the plugin mode); no other output may overwrite it or
    // the other inputs.
    let mut outputs = OutputSet::new([path]);
    for p in [&args.circuit, &args.placement, &args.config.config]
        .into_iter()
        .flatten()
    {
        outputs.input(p);
    }
    if let Some(report) = &args.report {
        outputs.check(report)?;
    }
    let bytes = super::check::read_gcode_file(path)?;
    let gcode = read_gcode(&bytes).with_context(|| path.display().to_string())?;
    let host = detect_host(&gcode);
    let settings = HostSettings::collect(&gcode, host.host, host_environment());
    let config = settings_config(&args.config, &settings)?;
    let electronics = load_electronics(&args)?;
    let params = config.host_layer_params().for_host(host.host);
    let print = HostPrint::read_with(&gcode, host, settings, &params);
    let (changed, done) = match &electronics {
        None => {
            match edit(&gcode, &print, None, &config).with_context(|| path.display().to_string())? {
                Edit::Unchanged => (false, None),
                Edit::Rewritten(edited) => {
                    add_edited(&mut outputs, path, &edited)?;
                    (true, None)
                }
            }
        }
        Some(e) => {
            let (bar, routing) = super::progress::routing_bar();
            let done = edit_circuit_watched(&gcode, &print, e, &config, Some(&routing))
                .with_context(|| path.display().to_string())?;
            bar.finish_and_clear();
            super::slice::refuse_unbuilt_circuit(
                &done.plan.report,
                args.allow_unrouted,
                path,
                "the host's file was left as it was",
            )?;
            add_edited(&mut outputs, path, &done.gcode)?;
            (true, Some(done))
        }
    };
    if let Some(name) = &args.output_name {
        let target = output_name_file(path);
        outputs.add(&target, format!("{name}\n").as_bytes())?;
    }
    let report = print.report(changed, done.as_ref());
    if let Some(report_path) = &args.report {
        let json = serde_json::to_vec_pretty(&report).context("serialising the report")?;
        outputs.add(report_path, &json)?;
    }
    outputs.commit()?;
    let summary: Vec<&str> = done
        .iter()
        .flat_map(|d| &d.summary)
        .map(|line| line.strip_prefix(SUMMARY_PREFIX).unwrap_or(line).trim())
        .collect();
    if args.json {
        let mut written = Vec::new();
        if changed {
            written.push(path.clone());
        }
        if args.output_name.is_some() {
            written.push(output_name_file(path));
        }
        written.extend(args.report.clone());
        return super::print_json(&serde_json::json!({
            "outputs": super::paths(written.iter().map(|p| p.as_path())),
            "changed": changed,
            "summary": summary,
            "report": report,
        }));
    }
    for text in summary {
        infoln!("{}: {text}", path.display());
    }
    let outcome = if changed {
        "rewritten"
    } else {
        "left unchanged"
    };
    infoln!("{}: {report}; {outcome}", path.display());
    Ok(())
}

/// Stages the edited file in place of the host's (a temporary file beside it, renamed with the
/// run's other outputs).
fn add_edited(
    outputs: &mut OutputSet,
    path: &std::path::Path,
    edited: &conduit_gcode::Gcode,
) -> Result<(), Failure> {
    let mut bytes = Vec::new();
    edited
        .write_to(&mut bytes)
        .with_context(|| format!("{}: cannot write G-code", path.display()))?;
    outputs.add_in_place(path, &bytes)?;
    Ok(())
}

/// The environment of the call as text; variables that are not UTF-8 are skipped (only the
/// host's `SLIC3R_*` variables are used, and those are text).
fn host_environment() -> Vec<(String, String)> {
    std::env::vars_os()
        .filter_map(|(k, v)| Some((k.into_string().ok()?, v.into_string().ok()?)))
        .collect()
}

/// The config of the run: the `-c` file when given, otherwise the host's settings; then the
/// `--set` overrides. The host's settings serve the user rather than configure conduit, so
/// their mapping notes (settings conduit has no use for) are not shown, their validation
/// warnings only when `--set` changed something, and settings that do not make a valid config fall back to
/// conduit's defaults with a warning.
fn settings_config(src: &ConfigSource, settings: &HostSettings) -> Result<Config, Failure> {
    if src.config.is_some() {
        return resolve(src);
    }
    let from_host = settings
        .to_config()
        .and_then(|(cfg, _notes)| cfg.validate().map(|_| cfg));
    let mut cfg = match from_host {
        Ok(cfg) => cfg,
        Err(e) => {
            warnln!("the host's settings: {e}; using conduit's defaults");
            Config::default()
        }
    };
    for kv in &src.set {
        cfg.apply_set(kv)
            .map_err(|e| Failure::Usage(e.to_string()))?;
    }
    let warnings = cfg.validate().map_err(anyhow::Error::from)?;
    if !src.set.is_empty() {
        for w in warnings {
            warnln!("{w}");
        }
    }
    Ok(cfg)
}

/// The circuit and placement, loaded and checked against each other, when both are given.
fn load_electronics(args: &PostprocessArgs) -> Result<Option<Electronics>, Failure> {
    let (Some(circuit_path), Some(placement_path)) = (&args.circuit, &args.placement) else {
        return Ok(None);
    };
    super::slice::load_electronics(circuit_path, placement_path).map(Some)
}
