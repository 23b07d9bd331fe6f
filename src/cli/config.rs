//! `conduit config`: print the documented defaults, or load and validate a config file; and the
//! shared loading of `-c CONFIG --set KEY=VALUE` for the other commands.

use super::{Failure, args::ConfigArgs, args::ConfigSource};
use conduit::config::{self, Config};

/// Loads the config a command asked for (defaults when none), applies `--set` overrides and
/// validates it; warnings go to stderr.
pub(crate) fn resolve(src: &ConfigSource) -> Result<Config, Failure> {
    resolve_adjusted(src, |_| {})
}

/// [`resolve`], with `adjust` applied to the loaded config before `--set`.
fn resolve_adjusted(
    src: &ConfigSource,
    adjust: impl FnOnce(&mut Config),
) -> Result<Config, Failure> {
    let (mut cfg, shown) = match &src.config {
        Some(path) => {
            // Every error of `load` names the file but a failed validation.
            let (cfg, warnings) = config::load(path).map_err(|e| match e {
                config::ConfigError::Invalid { .. } => {
                    anyhow::Error::new(e).context(path.display().to_string())
                }
                other => other.into(),
            })?;
            for w in &warnings {
                show_load_warning(path, w);
            }
            (cfg, warnings)
        }
        None => (Config::default(), Vec::new()),
    };
    adjust(&mut cfg);
    with_overrides(src, cfg, &shown)
}

/// The config of a job on the model file `model`, which may carry a slicer's settings
/// (`slicer`, a 3MF's): without `--config`, the profile and object settings stored in it
/// (`conduit::config::embedded`), said on the terminal, then `--set`; with `--config`, that
/// file alone, and the stored profile is said to be unused. Settings of objects and volumes
/// that are not honoured are named either way. The colour changes, pauses and custom G-code
/// stored by height belong to the model and join `printer.custom_gcode_per_print_z` either way
/// (`conduit::config::embedded::layer_gcodes`).
pub(crate) fn resolve_for_model(
    src: &ConfigSource,
    model: &std::path::Path,
    slicer: &conduit_3mf::SlicerSettings,
) -> Result<Config, Failure> {
    let file = model.display();
    if let Some(path) = &src.config {
        if let Some(p) = &slicer.profile {
            infoln!(
                "{file}: the {} profile stored in it is not used: --config {} is",
                p.writer.as_deref().unwrap_or("slicer"),
                path.display()
            );
        }
        for w in config::embedded::unhonoured(slicer, false) {
            warnln!("{file}: {w}");
        }
        return resolve_adjusted(src, |cfg| add_layer_gcodes(cfg, model, slicer));
    }
    let embedded = config::embedded::from_3mf(slicer)
        .map_err(|e| anyhow::Error::new(e).context(file.to_string()))?;
    let Some(e) = embedded else {
        for w in config::embedded::unhonoured(slicer, false) {
            warnln!("{file}: {w}");
        }
        return resolve_adjusted(src, |cfg| add_layer_gcodes(cfg, model, slicer));
    };
    infoln!(
        "{file}: slicing with {} stored in it (--config and --set override it)",
        e.source
    );
    for w in &e.warnings {
        show_load_warning(model, w);
    }
    let mut cfg = e.config;
    add_layer_gcodes(&mut cfg, model, slicer);
    with_overrides(src, cfg, &e.warnings)
}

/// Adds the colour changes, pauses and custom G-code stored by height in the model file
/// `model` to `cfg`, saying how many and what was left out.
fn add_layer_gcodes(
    cfg: &mut Config,
    model: &std::path::Path,
    slicer: &conduit_3mf::SlicerSettings,
) {
    let (events, warnings) = config::embedded::layer_gcodes(slicer, cfg.tools.len());
    let file = model.display();
    for w in &warnings {
        warnln!("{file}: {w}");
    }
    if let Some(c) = slicer.custom_gcodes.as_ref().filter(|_| !events.is_empty()) {
        let plate = c.plate.map(|p| format!(", plate {p}")).unwrap_or_default();
        infoln!(
            "{file}: {} event(s) of {}'s layer slider stored in it{plate} (colour changes, \
             pauses, custom G-code) go into printer.custom_gcode_per_print_z",
            events.len(),
            c.writer()
        );
    }
    cfg.printer.custom_gcode_per_print_z.extend(events);
}

/// `cfg` with the `--set` overrides of `src` applied and validated; the validation's warnings
/// not `shown` already go to stderr.
fn with_overrides(
    src: &ConfigSource,
    mut cfg: Config,
    shown: &[String],
) -> Result<Config, Failure> {
    for kv in &src.set {
        cfg.apply_set(kv)
            .map_err(|e| Failure::Usage(e.to_string()))?;
    }
    // The file was validated already: only what `--set` brought in is new.
    for w in cfg.validate().map_err(anyhow::Error::from)? {
        if !shown.contains(&w) {
            warnln!("{w}");
        }
    }
    Ok(cfg)
}

/// Shows a warning of loading the config file `path`, naming it. The list of ignored
/// PrusaSlicer keys is cut to its summary (every key with `--verbose`), so that a full profile
/// does not print one line of a few kilobytes.
fn show_load_warning(path: &std::path::Path, warning: &str) {
    let file = path.display();
    match warning.split_once(config::prusa_ini::IGNORED_LIST_MARK) {
        Some((summary, all)) if super::verbose() => {
            warnln!("{file}: {summary}");
            warnln!("{file}: ignored PrusaSlicer keys: {all}");
        }
        Some((summary, _)) => warnln!("{file}: {summary}; full list with --verbose"),
        None => warnln!("{file}: {warning}"),
    }
}

pub(crate) fn run(args: ConfigArgs) -> Result<(), Failure> {
    if args.defaults {
        out!("{}", config::defaults_toml())?;
        return Ok(());
    }
    if let Some(path) = &args.check {
        let cfg = resolve(&ConfigSource {
            config: Some(path.clone()),
            set: Vec::new(),
        })?;
        out!("{}", cfg.to_toml_string())?;
    }
    Ok(())
}
