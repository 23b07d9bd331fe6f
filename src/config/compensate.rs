//! Documentation of the `[compensate]` keys for `conduit config --defaults`; the section's type
//! is [`crate::robot::compensate::CompensateSettings`].

/// Documentation of the `[compensate]` keys for `conduit config --defaults`.
pub(super) const KEYS: &[super::defaults::KeyDoc] = &[
    super::defaults::k(
        "compensate",
        "target",
        "Tool-to-surface gap the compensation aims for, mm (--target overrides, in µm).",
    ),
    super::defaults::k(
        "compensate",
        "smoothing",
        "Standard deviation of the Gaussian smoothing the corrections along the path, mm of arc \
         length, so sensor noise does not become path noise; 0 = none (--smoothing).",
    ),
    super::defaults::k(
        "compensate",
        "sensor_angle",
        "Angle between the displacement sensor's beam and the tool axis, degrees in [0, 90): a \
         reading h is a gap of h·cos(angle) (--sensor-angle).",
    ),
    super::defaults::k(
        "compensate",
        "passes",
        "Measure → compensate passes of --simulate (--passes).",
    ),
    super::defaults::k(
        "compensate",
        "error_shift",
        "Simulation: shift [dx, dy, dz] of the real substrate from the nominal one, mm (--shift).",
    ),
    super::defaults::k(
        "compensate",
        "error_tilt",
        "Simulation: turn of the real substrate about error_axis through the middle of the path, \
         degrees (--tilt).",
    ),
    super::defaults::k(
        "compensate",
        "error_axis",
        "Simulation: axis [x, y, z] of error_tilt (--tilt-axis).",
    ),
    super::defaults::k(
        "compensate",
        "error_z",
        "Simulation: tool-length error, mm: the real tip stands this far further back along the \
         tool axis, adding it to every gap (--z-error).",
    ),
    super::defaults::k(
        "compensate",
        "noise",
        "Simulation: standard deviation of the sensor noise, mm (--noise, in µm).",
    ),
    super::defaults::k(
        "compensate",
        "seed",
        "Simulation: seed of the sensor noise; the same seed gives the same readings (--seed).",
    ),
    super::defaults::k(
        "compensate",
        "pattern_spacing",
        "Patterns: distance between neighbouring points along the pattern, mm (--spacing).",
    ),
    super::defaults::k(
        "compensate",
        "pattern_pitch",
        "Patterns: distance between serpentine lines or spiral turns, mm (--pitch).",
    ),
];
