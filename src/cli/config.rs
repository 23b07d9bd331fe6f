//! `conduit config`: print the documented defaults, or load and validate a config file; and the
//! shared loading of `-c CONFIG --set KEY=VALUE` for the other commands.

use super::{Failure, args::ConfigArgs, args::ConfigSource};
use conduit::config::{self, Config};

/// Loads the config a command asked for (defaults when none), applies `--set` overrides and
/// validates it; warnings go to stderr.
pub(crate) fn resolve(src: &ConfigSource) -> Result<Config, Failure> {
    let (mut cfg, mut warnings) = match &src.config {
        Some(path) => {
            // Every error of `load` names the file but a failed validation.
            config::load(path).map_err(|e| match e {
                config::ConfigError::Invalid { .. } => {
                    anyhow::Error::new(e).context(path.display().to_string())
                }
                other => other.into(),
            })?
        }
        None => (Config::default(), Vec::new()),
    };
    for kv in &src.set {
        cfg.apply_set(kv)
            .map_err(|e| Failure::Usage(e.to_string()))?;
    }
    warnings.extend(cfg.validate().map_err(anyhow::Error::from)?);
    for w in warnings {
        eprintln!("warning: {w}");
    }
    Ok(cfg)
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
