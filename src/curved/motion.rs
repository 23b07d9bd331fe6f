//! Projected paths into toolpaths: flow from the local layer thickness and feed limited by the
//! z speed.
//!
//! Place in the pipeline: the last step of [`super`] before the curved paths join the Program.
//! The G-code writer computes E from each move's 3D length and the path's width and height, so
//! a projected path is cut into consecutive toolpaths of constant height (the local thickness,
//! rounded to [`HEIGHT_STEP`]) and constant speed: where the thickness under the lowest curved
//! layer varies, E follows it; where a move's z component would exceed `max_z_speed`, that
//! move's feed is reduced so it does not. The pieces join end to start, so the nozzle never
//! travels between them.

use super::tops::Projected;
use crate::geom::Point3;
use crate::program::Toolpath;

/// Rounding of the local thickness used as a toolpath's height, mm.
pub const HEIGHT_STEP: f64 = 0.01;

/// What [`to_toolpaths`] did to one path.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct MotionStats {
    /// Moves slowed for the z-speed limit.
    pub z_limited: usize,
    /// Thinnest and thickest local thickness, mm.
    pub thickness: Option<(f64, f64)>,
}

/// `piece` as toolpaths with the role, tool, width and nominal `speed` of `template` (see the
/// module docs).
pub fn to_toolpaths(
    piece: &Projected,
    template: &Toolpath,
    max_z_speed: f64,
) -> (Vec<Toolpath>, MotionStats) {
    let mut stats = MotionStats::default();
    let mut pts = piece.points.clone();
    let mut th = piece.thickness.clone();
    if pts.len() < 2 {
        return (Vec::new(), stats);
    }
    for &t in &th {
        stats.thickness = Some(match stats.thickness {
            Some((lo, hi)) => (lo.min(t), hi.max(t)),
            None => (t, t),
        });
    }
    if piece.closed {
        pts.push(pts[0]);
        th.push(th[0]);
    }
    // Per segment: height and speed.
    let segs: Vec<(f64, f64)> = pts
        .windows(2)
        .zip(th.windows(2))
        .map(|(p, t)| {
            let height =
                (((t[0] + t[1]) / 2.0 / HEIGHT_STEP).round() * HEIGHT_STEP).max(HEIGHT_STEP);
            let d = p[1] - p[0];
            let len = d.norm();
            let mut speed = template.speed;
            if len > 0.0 && speed * d.z.abs() / len > max_z_speed {
                speed = max_z_speed * len / d.z.abs();
                stats.z_limited += 1;
            }
            (height, speed)
        })
        .collect();
    let uniform = segs.windows(2).all(|w| same(w[0], w[1]));
    if uniform && piece.closed {
        let (height, speed) = segs[0];
        return (
            vec![Toolpath {
                points: piece.points.clone(),
                closed: true,
                height,
                speed,
                ..template.clone()
            }],
            stats,
        );
    }
    let mut out = Vec::new();
    let mut start = 0;
    for i in 1..=segs.len() {
        if i == segs.len() || !same(segs[i], segs[start]) {
            let (height, speed) = segs[start];
            let points: Vec<Point3> = pts[start..=i].to_vec();
            out.push(Toolpath {
                points,
                closed: false,
                height,
                speed,
                ..template.clone()
            });
            start = i;
        }
    }
    (out, stats)
}

fn same(a: (f64, f64), b: (f64, f64)) -> bool {
    (a.0 - b.0).abs() < HEIGHT_STEP / 2.0 && (a.1 - b.1).abs() < 1e-9
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::program::Role;

    #[test]
    fn steep_moves_are_slowed_and_thickness_changes_split_the_path() {
        let template = Toolpath {
            points: Vec::new(),
            closed: false,
            role: Role::SolidInfill,
            tool: 0,
            width: 0.45,
            height: 0.2,
            speed: 40.0,
            segments: None,
            tool_axis: None,
        };
        let piece = Projected {
            points: vec![
                Point3::new(0.0, 0.0, 1.0),
                Point3::new(1.0, 0.0, 1.0),
                Point3::new(1.5, 0.0, 1.5),
                Point3::new(2.0, 0.0, 1.5),
            ],
            thickness: vec![0.2, 0.2, 0.3, 0.3],
            closed: false,
        };
        let (paths, stats) = to_toolpaths(&piece, &template, 10.0);
        assert_eq!(stats.z_limited, 1);
        assert_eq!(paths.len(), 3);
        assert!((paths[1].speed - 10.0 * 0.5f64.hypot(0.5) / 0.5).abs() < 1e-9);
        assert!((paths[0].height - 0.2).abs() < 1e-9 && (paths[2].height - 0.3).abs() < 1e-9);
        assert_eq!(paths[0].points.last(), paths[1].points.first());
    }
}
