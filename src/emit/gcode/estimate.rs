//! Durations as the header writes them. The estimate itself is the motion model of
//! [`crate::program::motion`]: the writer plans every move it writes with it, as `conduit check`
//! plans every move it replays, so the header's estimate and `check`'s agree. Heating waits are
//! not counted; dwells are.

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
    fn durations_like_prusaslicer() {
        assert_eq!(format_duration(1020.0), "17m 0s");
        assert_eq!(format_duration(4.6), "5s");
        assert_eq!(format_duration(3723.0), "1h 2m 3s");
        assert_eq!(format_duration(90_061.0), "1d 1h 1m 1s");
        assert_eq!(format_duration(f64::NAN), "0s");
    }
}
