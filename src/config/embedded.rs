//! The profile a slicer stored in a 3MF project, as the job's [`Config`].
//!
//! Place in the pipeline: a front door to [`Config`] beside [`super::load`]. `conduit slice`
//! and `conduit route` read a 3MF's [`SlicerSettings`] (`conduit_3mf`: PrusaSlicer's
//! `Metadata/Slic3r_PE.config`, OrcaSlicer's `Metadata/project_settings.config`) and, unless
//! `--config` names a file, build the job's config from it with [`from_3mf`]; `--set` still
//! applies on top.
//!
//! - The profile's keys go through the PrusaSlicer mapping ([`super::prusa_ini`]); OrcaSlicer's
//!   names are renamed to PrusaSlicer's first ([`super::host::ORCA_KEYS`]).
//! - An object's own settings (`<metadata type="object">`) override the profile when every
//!   object of the project has the same ones (a single object always does); otherwise conduit,
//!   which slices all objects with one profile, names each object's keys as not honoured.
//! - A volume's settings (a modifier's, or a part's own) are never honoured and are named.
//! - The colour changes, pauses and custom G-code by height of PrusaSlicer's layer slider, or of
//!   OrcaSlicer's and BambuStudio's (the first plate with any; `conduit_3mf::CustomGcodes`),
//!   become `printer.custom_gcode_per_print_z` ([`layer_gcodes`]), whichever config the job
//!   uses: they belong to the model, as in PrusaSlicer.
//!
//! Lists of keys not honoured are sorted by impact ([`super::prusa_ini::impact`]): keys conduit
//! reads from a profile first, then those that change the print, then the rest, each
//! alphabetically; every key is named once per object or volume.

use std::collections::BTreeMap;
use std::path::PathBuf;

use conduit_3mf::{CustomGcodeKind, Layout, ObjectSettings, Setting, SlicerSettings};

use super::prusa_ini::{from_lined_pairs, impact};
use super::{Config, ConfigError, LayerGcode, LayerGcodeKind};

/// The colour changes, pauses and custom G-code by height stored in `s`, for a printer with
/// `tools` tools, as PrusaSlicer applies them (`ToolOrdering::assign_custom_gcodes`), and what
/// was left out. conduit prints the model with one tool, so its printer is PrusaSlicer's
/// "single extruder" with one tool and "multi as single" with more:
///
/// - events entered for a multi-extruder printer (`mode` `MultiExtruder`) change colours by
///   switching extruders; their colour and tool changes are left out;
/// - tool changes entered as "multi as single" become colour changes of the one tool on a
///   one-tool printer, and are left out otherwise;
/// - a colour change for an extruder the printer does not have is left out.
pub fn layer_gcodes(s: &SlicerSettings, tools: usize) -> (Vec<LayerGcode>, Vec<String>) {
    let Some(c) = &s.custom_gcodes else {
        return (Vec::new(), Vec::new());
    };
    let part = c.part.trim_start_matches('/');
    let mode = c.mode.as_deref().unwrap_or("SingleExtruder");
    let multi_extruder = mode == "MultiExtruder";
    let (mut out, mut warnings) = (Vec::new(), Vec::new());
    for code in &c.codes {
        let left_out = |what: &str, why: &str| {
            format!(
                "{part}:{}: the {what} at {} mm is left out: {why}",
                code.line, code.print_z
            )
        };
        let mut tool = code.extruder.checked_sub(1).map(|t| t as usize);
        let kind = match code.kind {
            CustomGcodeKind::ColorChange | CustomGcodeKind::ToolChange if multi_extruder => {
                warnings.push(left_out(
                    "filament change",
                    "it was entered for a multi-extruder printer",
                ));
                continue;
            }
            CustomGcodeKind::ToolChange if !(mode == "MultiAsSingle" && tools == 1) => {
                warnings.push(left_out(
                    "tool change",
                    "conduit prints the model with one tool",
                ));
                continue;
            }
            // On the one tool: a change of filament in the tool printing.
            CustomGcodeKind::ToolChange => {
                tool = None;
                LayerGcodeKind::ColorChange
            }
            CustomGcodeKind::ColorChange => {
                if tool.is_some_and(|t| t >= tools) {
                    warnings.push(left_out(
                        "colour change",
                        &format!("extruder {} is not among the {tools} tools", code.extruder),
                    ));
                    continue;
                }
                LayerGcodeKind::ColorChange
            }
            CustomGcodeKind::PausePrint => LayerGcodeKind::Pause,
            CustomGcodeKind::Template => LayerGcodeKind::Template,
            CustomGcodeKind::Custom => LayerGcodeKind::Custom,
        };
        let change = kind == LayerGcodeKind::ColorChange;
        out.push(LayerGcode {
            print_z: code.print_z,
            kind,
            tool: tool.filter(|_| change),
            color: if change {
                code.color.clone()
            } else {
                String::new()
            },
            extra: if change {
                String::new()
            } else {
                code.extra.clone()
            },
        });
    }
    (out, warnings)
}

/// The job's config taken from a 3MF.
#[derive(Debug, Clone)]
pub struct Embedded {
    /// The config.
    pub config: Config,
    /// Settings ignored or adapted, and settings of objects and volumes not honoured.
    pub warnings: Vec<String>,
    /// What was used, for the terminal: `the PrusaSlicer 2.5.0 profile (Metadata/Slic3r_PE.config,
    /// 300 settings)`.
    pub source: String,
}

/// The config of the profile and object settings in `s`; `None` when the 3MF carries
/// neither. An error names the part and line of the value that does not read.
pub fn from_3mf(s: &SlicerSettings) -> Result<Option<Embedded>, ConfigError> {
    let object_settings = shared_object_settings(&s.objects);
    if s.profile.is_none() && object_settings.is_none_or(<[Setting]>::is_empty) {
        return Ok(None);
    }
    let layout = s.profile.as_ref().map_or(Layout::Prusa, |p| p.layout);
    // Key -> (value, line, part): later entries (the objects') override the profile's.
    let mut values: BTreeMap<String, (String, Option<usize>, &str)> = BTreeMap::new();
    if let Some(p) = &s.profile {
        for set in &p.settings {
            values.insert(set.key.clone(), (set.value.clone(), set.line, &p.part));
        }
    }
    let objects_part = s.objects_part.as_deref().unwrap_or_default();
    for set in object_settings.unwrap_or_default() {
        values.insert(set.key.clone(), (set.value.clone(), set.line, objects_part));
    }
    if layout == Layout::Orca {
        super::host::add_prusa_names(&mut values, true);
    }
    let parts: BTreeMap<String, &str> = values.iter().map(|(k, v)| (k.clone(), v.2)).collect();
    let pairs = values.into_iter().map(|(k, (v, l, _))| (k, v, l)).collect();
    let (config, mut warnings) = from_lined_pairs(pairs).map_err(|e| {
        let path = match &e {
            ConfigError::Ini { key, .. } => parts
                .get(key)
                .map(|p| PathBuf::from(p.trim_start_matches('/'))),
            _ => None,
        };
        e.in_ini_file(path)
    })?;
    warnings.extend(unhonoured(s, object_settings.is_some()));
    let source = match &s.profile {
        Some(p) => format!(
            "the {} profile ({}, {} settings)",
            p.writer.as_deref().unwrap_or("slicer"),
            p.part.trim_start_matches('/'),
            p.settings.len()
        ),
        None => "the objects' settings".to_owned(),
    };
    let source = match object_settings {
        Some(o) if s.profile.is_some() && !o.is_empty() => {
            format!("{source} with the objects' own settings")
        }
        _ => source,
    };
    Ok(Some(Embedded {
        config,
        warnings,
        source,
    }))
}

/// The settings of `s` conduit does not honour besides the profile's: each object's own
/// settings unless they were applied (`objects_applied`), and every volume's, one line per
/// object or volume naming its keys by impact.
pub fn unhonoured(s: &SlicerSettings, objects_applied: bool) -> Vec<String> {
    let mut out = Vec::new();
    for o in &s.objects {
        let name = o.name.clone().unwrap_or_else(|| format!("object {}", o.id));
        if !objects_applied && !o.settings.is_empty() {
            out.push(format!(
                "object \"{name}\": its own settings are not honoured (the objects' settings \
                 differ and conduit slices every object with one profile): {}",
                by_impact(&o.settings)
            ));
        }
        for v in o.volumes.iter().filter(|v| !v.settings.is_empty()) {
            let label = v
                .name
                .as_deref()
                .map_or_else(String::new, |n| format!(" \"{n}\""));
            out.push(format!(
                "object \"{name}\": the settings of {}{label} are not honoured: {}",
                v.kind.describe(),
                by_impact(&v.settings)
            ));
        }
    }
    out
}

/// The objects' own settings when every object has the same ones (`Some(&[])` when none has
/// any), `None` when they differ.
fn shared_object_settings(objects: &[ObjectSettings]) -> Option<&[Setting]> {
    fn key(o: &ObjectSettings) -> Vec<(&str, &str)> {
        let mut kv: Vec<(&str, &str)> = o
            .settings
            .iter()
            .map(|s| (s.key.as_str(), s.value.as_str()))
            .collect();
        kv.sort_unstable();
        kv
    }
    let first = objects.first()?;
    let same = objects.iter().all(|o| key(o) == key(first));
    same.then_some(first.settings.as_slice())
}

/// The keys of `settings`, once each, sorted by [`impact`] then name.
fn by_impact(settings: &[Setting]) -> String {
    let mut keys: Vec<(u8, &str)> = settings
        .iter()
        .map(|s| (impact(&s.key, &s.value), s.key.as_str()))
        .collect();
    keys.sort_unstable();
    keys.dedup_by(|a, b| a.1 == b.1);
    keys.iter().map(|(_, k)| *k).collect::<Vec<_>>().join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;
    use conduit_3mf::{CustomGcode, CustomGcodes};

    fn settings(mode: &str, codes: &[(f64, CustomGcodeKind, u32)]) -> SlicerSettings {
        SlicerSettings {
            custom_gcodes: Some(CustomGcodes {
                part: conduit_3mf::PRUSA_CUSTOM_GCODE_PART.to_owned(),
                plate: None,
                mode: Some(mode.to_owned()),
                codes: codes
                    .iter()
                    .enumerate()
                    .map(|(k, &(print_z, kind, extruder))| CustomGcode {
                        print_z,
                        kind,
                        extruder,
                        color: "#123456".to_owned(),
                        extra: "note".to_owned(),
                        line: k + 3,
                    })
                    .collect(),
            }),
            ..SlicerSettings::default()
        }
    }

    fn kinds(events: &[LayerGcode]) -> Vec<(f64, LayerGcodeKind, Option<usize>)> {
        events.iter().map(|e| (e.print_z, e.kind, e.tool)).collect()
    }

    #[test]
    fn layer_slider_events_apply_as_prusaslicer_applies_them() {
        use CustomGcodeKind as K;
        use LayerGcodeKind as L;
        let codes = [
            (1.0, K::ColorChange, 1),
            (2.0, K::PausePrint, 1),
            (3.0, K::ToolChange, 2),
            (4.0, K::Custom, 0),
            (5.0, K::ColorChange, 3),
        ];
        // One tool, entered for a single-extruder printer: the tool change is not a colour
        // change, extruder 3 does not exist.
        let (events, warnings) = layer_gcodes(&settings("SingleExtruder", &codes), 1);
        assert_eq!(
            kinds(&events),
            vec![
                (1.0, L::ColorChange, Some(0)),
                (2.0, L::Pause, None),
                (4.0, L::Custom, None)
            ]
        );
        assert_eq!(
            (events[0].color.as_str(), events[0].extra.as_str()),
            ("#123456", "")
        );
        assert_eq!(
            (events[1].color.as_str(), events[1].extra.as_str()),
            ("", "note")
        );
        assert_eq!(warnings.len(), 2, "{warnings:?}");
        assert!(warnings[0].starts_with(
            "Metadata/Prusa_Slicer_custom_gcode_per_print_z.xml:5: the tool change at 3 mm is left out"
        ));
        assert!(warnings[1].contains("extruder 3 is not among the 1 tools"));
        // Entered as "multi as single" for a one-tool printer: tool changes are colour changes.
        let (events, _) = layer_gcodes(&settings("MultiAsSingle", &codes), 1);
        assert!(kinds(&events).contains(&(3.0, L::ColorChange, None)));
        // Entered for a multi-extruder printer: its colour and tool changes mean extruder
        // switches, which conduit does not make; pauses and custom G-code stay.
        let (events, warnings) = layer_gcodes(&settings("MultiExtruder", &codes), 2);
        assert_eq!(
            kinds(&events),
            vec![(2.0, L::Pause, None), (4.0, L::Custom, None)]
        );
        assert_eq!(warnings.len(), 3, "{warnings:?}");
    }
}
