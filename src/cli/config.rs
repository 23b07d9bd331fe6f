//! `conduit config`: print the documented defaults, or load and validate a config file; and the
//! shared loading of `-c CONFIG --set KEY=VALUE` for the other commands.

use super::{Failure, args::ConfigArgs, args::ConfigSource};
use conduit::config::{self, Config};

/// Loads the config a command asked for (defaults when none), applies `--set` overrides and
/// validates it; warnings go to stderr.
pub(crate) fn resolve(src: &ConfigSource) -> Result<Config, Failure> {
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
    for kv in &src.set {
        cfg.apply_set(kv)
            .map_err(|e| Failure::Usage(e.to_string()))?;
    }
    // `load` validated the file already: only what `--set` brought in is new.
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
