//! Print time estimate: a trapezoidal velocity profile per move.
//!
//! Every move starts and ends at rest, accelerates at `a` up to its feed rate `v`, cruises and
//! decelerates at `a`. A move of length `d` takes
//!
//! ```text
//! t = d/v + v/a          when d ≥ v²/a  (it reaches v: two ramps of v/a each, v²/(2a) long)
//! t = 2·√(d/a)           otherwise      (a triangle: it never reaches v)
//! ```
//!
//! Real firmware blends consecutive moves (junction deviation, look-ahead), so this
//! over-estimates prints made of many short segments; it is deterministic and simple, which is
//! what the header needs. Heating waits are not counted; dwells are.

/// Seconds to move `distance` mm at feed rate `feed` mm/s with acceleration `accel` mm/s²
/// (see the module docs). Zero for a non-positive distance or feed; without a usable
/// acceleration the move runs at `feed` throughout.
pub fn move_time(distance: f64, feed: f64, accel: f64) -> f64 {
    if !(distance > 0.0 && feed > 0.0) {
        return 0.0;
    }
    if !(accel > 0.0 && accel.is_finite()) {
        return distance / feed;
    }
    if distance >= feed * feed / accel {
        distance / feed + feed / accel
    } else {
        2.0 * (distance / accel).sqrt()
    }
}

/// A duration as PrusaSlicer writes it: `1d 2h 3m 4s`, leading zero units left out (`17m 0s`,
/// `5s`), rounded to the second.
pub fn format_duration(seconds: f64) -> String {
    let total = if seconds.is_finite() && seconds > 0.0 {
        seconds.round() as u64
    } else {
        0
    };
    let (d, h, m, s) = (
        total / 86_400,
        total / 3600 % 24,
        total / 60 % 60,
        total % 60,
    );
    if d > 0 {
        format!("{d}d {h}h {m}m {s}s")
    } else if h > 0 {
        format!("{h}h {m}m {s}s")
    } else if m > 0 {
        format!("{m}m {s}s")
    } else {
        format!("{s}s")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trapezoid_and_triangle() {
        // 100 mm at 50 mm/s, 1000 mm/s²: ramps 2.5 mm / 0.05 s each; 95 mm cruise = 1.9 s.
        assert!((move_time(100.0, 50.0, 1000.0) - 2.05).abs() < 1e-12);
        // 1 mm at 50 mm/s: never reaches 50 (needs 2.5 mm): 2·√(1/1000).
        assert!((move_time(1.0, 50.0, 1000.0) - 2.0 * 0.001f64.sqrt()).abs() < 1e-12);
        // Continuous at d = v²/a.
        let d = 2.5;
        assert!((move_time(d, 50.0, 1000.0) - 2.0 * (d / 1000.0f64).sqrt()).abs() < 1e-12);
        assert_eq!(move_time(0.0, 50.0, 1000.0), 0.0);
        assert_eq!(move_time(10.0, 50.0, 0.0), 0.2);
    }

    #[test]
    fn durations_like_prusaslicer() {
        assert_eq!(format_duration(1020.0), "17m 0s");
        assert_eq!(format_duration(4.6), "5s");
        assert_eq!(format_duration(3723.0), "1h 2m 3s");
        assert_eq!(format_duration(90_061.0), "1d 1h 1m 1s");
        assert_eq!(format_duration(f64::NAN), "0s");
    }
}
