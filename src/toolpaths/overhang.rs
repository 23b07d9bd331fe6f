//! Perimeters by overhang degree: each perimeter path is cut where its bead starts or stops
//! hanging out over the layer below, or hangs out by another degree, and every piece gets the
//! speed, role and fan of its degree (PrusaSlicer's `overhangs` and dynamic overhang speeds and
//! fans); bridges get the bridge fan.
//!
//! Place in the pipeline: toolpaths stage, on the paths of one tool on one layer after they
//! are ordered and their loops opened at the seam, with the zones the regions stage found
//! ([`crate::region::overhang`]).
//!
//! - **Degrees.** A point of a path has degree `d`, the number of its width's zones it lies in:
//!   0 on the layer below; 1 to 4 resting on it over less than 95 %, 75 %, 50 %, 25 % of its
//!   width; 5 more than half a nozzle beyond its edge. The cuts are exact: each zone clips the
//!   path ([`clip_intervals`]).
//! - **Speeds.** With [`OverhangParams::speeds`] (PrusaSlicer's `enable_dynamic_overhang_speeds`,
//!   `overhang_speed_0..3` for 0, 25, 50 and 75 % overlap), a piece of degree 1 to 4 prints at
//!   the speed of the lowest overlap it may have — degree 1 (75 to 95 %) at the 75 % speed,
//!   degree 4 at the 0 % speed — and never faster than its role's own speed. PrusaSlicer
//!   interpolates between those speeds point by point; a piece here is never faster than
//!   PrusaSlicer would print any of its points.
//! - **Overhang perimeters.** With [`OverhangParams::bridging`] (PrusaSlicer's `overhangs`), a
//!   piece of degree 5 becomes [`Role::OverhangPerimeter`]: a round thread of the nozzle's
//!   diameter, at the bridge speed (at the 0 % speed with dynamic speeds), as PrusaSlicer
//!   prints it.
//! - **Fan.** Bridge infill and overhang perimeters ask for [`OverhangParams::bridge_fan`];
//!   with [`OverhangParams::fans`] (`overhang_fan_speed_0..3`) every piece of degree 1 to 5
//!   asks for the fan of its degree as for its speed. A run of paths asking for a fan is
//!   wrapped in [`Event::PartFan`] events: the writer runs the fan at that speed or the layer's,
//!   whichever is higher, and returns to the layer's after.

use crate::geom::{ExPolygon, Point2, clip_intervals, polyline_length, scaled};
use crate::program::{Event, LayerItem, Role, Toolpath};
use crate::region::OverhangZones;
use crate::region::overhang::ZONES;

/// How perimeters over air and bridges are printed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OverhangParams {
    /// Print the stretches of a perimeter more than half a nozzle beyond the layer below as
    /// [`Role::OverhangPerimeter`] (PrusaSlicer's `overhangs`). Default true.
    pub bridging: bool,
    /// Speeds for 0, 25, 50 and 75 % overlap with the layer below, mm/s (PrusaSlicer's
    /// `overhang_speed_0..3`); `None`: perimeters keep their role's speed. Default
    /// PrusaSlicer's 15, 15, 20, 25.
    pub speeds: Option<[f64; 4]>,
    /// Fan speeds for 0, 25, 50 and 75 % overlap, percent (PrusaSlicer's
    /// `overhang_fan_speed_0..3`); `None` (the default): no fan of its own for overhangs.
    pub fans: Option<[f64; 4]>,
    /// Fan speed of bridge infill and overhang perimeters, percent; 0: the layer's.
    /// Default 100.
    pub bridge_fan: f64,
    /// Width of an overhang perimeter's round thread, mm: the nozzle diameter. Default 0.4.
    pub bridge_width: f64,
}

/// PrusaSlicer's default `overhang_speed_0..3`, mm/s.
pub const DEFAULT_OVERHANG_SPEEDS: [f64; 4] = [15.0, 15.0, 20.0, 25.0];

impl Default for OverhangParams {
    fn default() -> Self {
        Self {
            bridging: true,
            speeds: Some(DEFAULT_OVERHANG_SPEEDS),
            fans: None,
            bridge_fan: 100.0,
            bridge_width: 0.4,
        }
    }
}

/// Which of the four overlap entries (0, 25, 50, 75 %) a degree 1 to 5 takes: the lowest
/// overlap the degree allows.
fn table_index(degree: usize) -> usize {
    match degree {
        0 | 1 => 3,
        2 => 2,
        3 => 1,
        _ => 0,
    }
}

/// What a piece of a path prints as.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Piece {
    role: Role,
    width: f64,
    speed: f64,
    fan: Option<f64>,
}

impl OverhangParams {
    /// The piece of `path` with overhang `degree`; `bridge_speed` is the tool's.
    fn piece(&self, path: &Toolpath, degree: usize, bridge_speed: f64) -> Piece {
        let plain = Piece {
            role: path.role,
            width: path.width,
            speed: path.speed,
            fan: None,
        };
        if degree == 0 {
            return plain;
        }
        let i = table_index(degree);
        let fan = self.fans.map(|f| f[i]).filter(|f| *f > 0.0);
        if degree >= ZONES && self.bridging {
            let bridge_fan = (self.bridge_fan > 0.0).then_some(self.bridge_fan);
            return Piece {
                role: Role::OverhangPerimeter,
                width: self.bridge_width,
                speed: self.speeds.map_or(bridge_speed, |s| s[0]),
                fan: match (fan, bridge_fan) {
                    (Some(a), Some(b)) => Some(a.max(b)),
                    (a, b) => a.or(b),
                },
            };
        }
        Piece {
            speed: self.speeds.map_or(path.speed, |s| s[i].min(path.speed)),
            fan,
            ..plain
        }
    }

    /// The fan a path that is not cut asks for: the bridge fan for bridge infill.
    fn fan_of(&self, path: &Toolpath) -> Option<f64> {
        (matches!(path.role, Role::BridgeInfill | Role::OverhangPerimeter) && self.bridge_fan > 0.0)
            .then_some(self.bridge_fan)
    }
}

/// The zones of one width, gathered over the objects of a layer.
struct WidthZones {
    width: f64,
    zones: Vec<Vec<ExPolygon>>,
    /// Bounding box of zone 0 (the largest), nm: `[min_x, min_y, max_x, max_y]`.
    bounds: [i64; 4],
}

fn gather(zones: &[&OverhangZones]) -> Vec<WidthZones> {
    let mut out: Vec<WidthZones> = Vec::new();
    for z in zones.iter().filter(|z| !z.is_empty()) {
        let i = match out.iter().position(|w| (w.width - z.width).abs() < 1e-9) {
            Some(i) => i,
            None => {
                out.push(WidthZones {
                    width: z.width,
                    zones: vec![Vec::new(); ZONES],
                    bounds: [i64::MAX, i64::MAX, i64::MIN, i64::MIN],
                });
                out.len() - 1
            }
        };
        let w = &mut out[i];
        for (k, zone) in z.zones.iter().enumerate().take(ZONES) {
            w.zones[k].extend(zone.iter().cloned());
        }
        let b = super::bounds(z.zones[0].iter().flat_map(|ex| ex.contour.points.iter()));
        w.bounds = [
            w.bounds[0].min(b[0]),
            w.bounds[1].min(b[1]),
            w.bounds[2].max(b[2]),
            w.bounds[3].max(b[3]),
        ];
    }
    out
}

/// The degree of each stretch of `line` against `zones`: `(from, to, degree)` in arc length
/// (mm), covering the line, neighbours of equal degree merged.
fn degrees(line: &[Point2], zones: &[Vec<ExPolygon>]) -> Vec<(f64, f64, usize)> {
    let total = polyline_length(line) / 1e6;
    let mut inside: Vec<Vec<(f64, f64)>> = Vec::new();
    for zone in zones {
        if zone.is_empty() {
            break;
        }
        let iv = clip_intervals(line, zone);
        if iv.is_empty() {
            break;
        }
        inside.push(iv);
    }
    let mut cuts: Vec<f64> = vec![0.0, total];
    cuts.extend(inside.iter().flatten().flat_map(|&(a, b)| [a, b]));
    cuts.retain(|c| (0.0..=total).contains(c));
    cuts.sort_by(f64::total_cmp);
    cuts.dedup_by(|a, b| (*a - *b).abs() < 1e-6);
    let mut out: Vec<(f64, f64, usize)> = Vec::new();
    for w in cuts.windows(2) {
        let mid = (w[0] + w[1]) / 2.0;
        let degree = inside
            .iter()
            .filter(|iv| iv.iter().any(|&(a, b)| a <= mid && mid <= b))
            .count();
        match out.last_mut() {
            Some(last) if last.2 == degree => last.1 = w[1],
            _ => out.push((w[0], w[1], degree)),
        }
    }
    out
}

/// `path` (a planar path without arcs) cut at the arc-length positions of `pieces`, each part
/// open and with its piece's role, width and speed.
fn cut(path: &Toolpath, pieces: &[((f64, f64), Piece)]) -> Vec<Toolpath> {
    let mut pts = path.points.clone();
    if path.closed
        && let Some(&first) = path.points.first()
    {
        pts.push(first);
    }
    let mut out = Vec::with_capacity(pieces.len());
    let mut at = 0.0;
    let mut i = 0;
    for &((from, to), piece) in pieces {
        let point_at = |s: f64, i: usize, at: f64| {
            let (a, b) = (pts[i], pts[(i + 1).min(pts.len() - 1)]);
            let l = (b - a).norm();
            let t = if l > 0.0 {
                ((s - at) / l).clamp(0.0, 1.0)
            } else {
                0.0
            };
            a + (b - a) * t
        };
        let mut points = vec![point_at(from, i, at)];
        loop {
            let l = (pts[(i + 1).min(pts.len() - 1)] - pts[i]).norm();
            if i + 1 >= pts.len() - 1 || at + l >= to {
                break;
            }
            at += l;
            i += 1;
            points.push(pts[i]);
        }
        points.push(point_at(to, i, at));
        points.dedup_by(|a, b| (*a - *b).norm() < 1e-9);
        if points.len() >= 2 {
            out.push(Toolpath {
                points,
                closed: false,
                role: piece.role,
                width: piece.width,
                speed: piece.speed,
                ..path.clone()
            });
        }
    }
    out
}

/// The paths of one tool on one layer, in print order, with every perimeter path cut by
/// overhang degree against `zones` (see the module docs), and each with the fan it asks for.
pub fn split_paths(
    paths: Vec<Toolpath>,
    zones: &[&OverhangZones],
    params: &OverhangParams,
    bridge_speed: f64,
) -> Vec<(Toolpath, Option<f64>)> {
    let widths = gather(zones);
    let mut out = Vec::with_capacity(paths.len());
    for path in paths {
        let perimeter = matches!(path.role, Role::Perimeter | Role::ExternalPerimeter)
            && path.segments.is_none()
            && path.tool_axis.is_none();
        let w = widths
            .iter()
            .find(|w| perimeter && (w.width - path.width).abs() < 1e-9);
        let Some(w) = w else {
            let fan = params.fan_of(&path);
            out.push((path, fan));
            continue;
        };
        let mut line: Vec<Point2> = path
            .points
            .iter()
            .map(|p| Point2::new(scaled(p.x), scaled(p.y)))
            .collect();
        let b = super::bounds(line.iter());
        if b[2] < w.bounds[0] || b[0] > w.bounds[2] || b[3] < w.bounds[1] || b[1] > w.bounds[3] {
            out.push((path, None));
            continue;
        }
        if path.closed
            && let Some(&first) = line.first()
        {
            line.push(first);
        }
        let mut pieces: Vec<((f64, f64), Piece)> = Vec::new();
        for (from, to, degree) in degrees(&line, &w.zones) {
            let piece = params.piece(&path, degree, bridge_speed);
            match pieces.last_mut() {
                Some(last) if last.1 == piece => last.0.1 = to,
                _ => pieces.push(((from, to), piece)),
            }
        }
        if pieces.len() <= 1 && pieces.first().is_none_or(|p| p.1.role == path.role) {
            let piece = pieces.first().map(|p| p.1);
            let mut path = path;
            let mut fan = None;
            if let Some(piece) = piece {
                path.speed = piece.speed;
                fan = piece.fan;
            }
            out.push((path, fan));
            continue;
        }
        let fans: Vec<Option<f64>> = pieces.iter().map(|p| p.1.fan).collect();
        out.extend(cut(&path, &pieces).into_iter().zip(fans));
    }
    out
}

/// The layer items of `paths` in order, each run of paths asking for the same fan between an
/// [`Event::PartFan`] asking for it and one returning to the layer's fan.
pub fn with_fan_events(paths: Vec<(Toolpath, Option<f64>)>) -> Vec<LayerItem> {
    let mut items = Vec::with_capacity(paths.len());
    let mut current: Option<f64> = None;
    for (path, fan) in paths {
        if fan != current {
            items.push(LayerItem::Event(Event::PartFan { at_least: fan }));
            current = fan;
        }
        items.push(LayerItem::Path(path));
    }
    if current.is_some() {
        items.push(LayerItem::Event(Event::PartFan { at_least: None }));
    }
    items
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point3;
    use crate::region::overhang_zones;
    use crate::region::test_util::rect_island;

    fn loop_path(x0: f64, y0: f64, x1: f64, y1: f64, role: Role, speed: f64) -> Toolpath {
        Toolpath {
            points: vec![
                Point3::new(x0, y0, 1.0),
                Point3::new(x1, y0, 1.0),
                Point3::new(x1, y1, 1.0),
                Point3::new(x0, y1, 1.0),
            ],
            closed: true,
            role,
            tool: 0,
            width: 0.45,
            height: 0.2,
            speed,
            segments: None,
            tool_axis: None,
        }
    }

    #[test]
    fn a_loop_over_a_step_is_cut_where_it_leaves_the_layer_below() -> Result<(), String> {
        // Below: x ≤ 10; here: x ≤ 12, so the external loop's right side (x = 11.775) is in
        // the air and its top and bottom sides are in the air past x = 10.2.
        let below = vec![rect_island(0.0, 0.0, 10.0, 10.0)];
        let here = vec![rect_island(0.0, 0.0, 12.0, 10.0)];
        let zones = overhang_zones(&here, &below, 0.45, 0.4).ok_or("zones")?;
        let path = loop_path(0.225, 0.225, 11.775, 9.775, Role::ExternalPerimeter, 25.0);
        let out = split_paths(vec![path], &[&zones], &OverhangParams::default(), 60.0);
        let over: f64 = out
            .iter()
            .filter(|(p, _)| p.role == Role::OverhangPerimeter)
            .map(|(p, _)| p.length())
            .sum();
        // Right side (9.55) plus 2 × (11.775 − 10.2) along the top and bottom.
        let want = 9.55 + 2.0 * (11.775 - 10.2);
        assert!((over - want).abs() < 1e-3, "{over} vs {want}");
        for (p, fan) in &out {
            if p.role == Role::OverhangPerimeter {
                assert_eq!((p.width, p.speed, *fan), (0.4, 15.0, Some(100.0)));
            } else {
                assert_eq!(p.role, Role::ExternalPerimeter);
                assert!(p.speed <= 25.0 && fan.is_none());
            }
        }
        let total: f64 = out.iter().map(|(p, _)| p.length()).sum();
        assert!((total - 2.0 * (11.55 + 9.55)).abs() < 1e-6, "{total}");
        // Without dynamic speeds the overhang is at the bridge speed, the rest as it was.
        let plain = OverhangParams {
            speeds: None,
            ..Default::default()
        };
        let path = loop_path(0.225, 0.225, 11.775, 9.775, Role::ExternalPerimeter, 25.0);
        let out = split_paths(vec![path], &[&zones], &plain, 60.0);
        assert!(out.iter().all(|(p, _)| p.speed
            == if p.role == Role::OverhangPerimeter {
                60.0
            } else {
                25.0
            }));
        let items = with_fan_events(out);
        let fans: Vec<Option<f64>> = items
            .iter()
            .filter_map(|i| match i {
                LayerItem::Event(Event::PartFan { at_least }) => Some(*at_least),
                _ => None,
            })
            .collect();
        assert_eq!(fans.first(), Some(&Some(100.0)));
        assert_eq!(fans.last(), Some(&None));
        Ok(())
    }

    #[test]
    fn paths_on_the_layer_below_are_kept_whole() {
        let path = loop_path(0.225, 0.225, 9.775, 9.775, Role::ExternalPerimeter, 25.0);
        let out = split_paths(vec![path.clone()], &[], &OverhangParams::default(), 60.0);
        assert_eq!(out, vec![(path, None)]);
    }
}
