//! The 2D design: SVG paths placed on the surface's top view and cut into points two per
//! nozzle inner diameter.
//!
//! Place in the pipeline: step 3, after registration (the placement is in the machine frame)
//! and before projection. Disconnected paths stay separate polylines; the dispenser's pressure
//! goes off between them.

use serde::Serialize;

/// Where the design goes: its bounding-box centre at (`x`, `y`) after rotating it by `rot_deg`
/// counter-clockwise about that centre and scaling it by `scale`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Placement {
    /// X of the design's centre, mm.
    pub x: f64,
    /// Y of the design's centre, mm.
    pub y: f64,
    /// Rotation, degrees counter-clockwise.
    pub rot_deg: f64,
    /// Scale factor.
    pub scale: f64,
}

/// One design path in the machine's xy plane, mm.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanarPath {
    /// Points; a closed path repeats its first point at the end.
    pub points: Vec<[f64; 2]>,
    /// Whether it was a closed shape.
    pub closed: bool,
}

impl PlanarPath {
    /// Length, mm.
    pub fn length(&self) -> f64 {
        self.points
            .windows(2)
            .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]))
            .sum()
    }
}

/// The design's paths placed per `place` (closed paths get their first point again at the end).
pub fn place(design: &conduit_svg::Design, place: &Placement) -> Vec<PlanarPath> {
    let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
    for p in design.paths.iter().flat_map(|p| &p.points) {
        lo = [lo[0].min(p[0]), lo[1].min(p[1])];
        hi = [hi[0].max(p[0]), hi[1].max(p[1])];
    }
    let c = [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0];
    let (s, co) = place.rot_deg.to_radians().sin_cos();
    let map = |p: &[f64; 2]| {
        let (dx, dy) = ((p[0] - c[0]) * place.scale, (p[1] - c[1]) * place.scale);
        [place.x + co * dx - s * dy, place.y + s * dx + co * dy]
    };
    design
        .paths
        .iter()
        .filter(|p| p.points.len() >= 2)
        .map(|p| {
            let mut points: Vec<[f64; 2]> = p.points.iter().map(map).collect();
            if p.closed {
                points.push(points[0]);
            }
            PlanarPath {
                points,
                closed: p.closed,
            }
        })
        .collect()
}

/// `path` resampled at steps of at most `step` (with `step = d/2`, two points per inner
/// diameter): every segment of the design is cut into ⌈l/step⌉ equal parts, so every vertex of
/// the design is a point of the result — corners are kept, and the length is the design's.
pub fn discretise(path: &PlanarPath, step: f64) -> PlanarPath {
    let mut out: Vec<[f64; 2]> = Vec::with_capacity(path.points.len());
    if let Some(first) = path.points.first() {
        out.push(*first);
    }
    for w in path.points.windows(2) {
        let [a, b] = [w[0], w[1]];
        let l = (b[0] - a[0]).hypot(b[1] - a[1]);
        if l <= 0.0 {
            continue;
        }
        let n = ((l / step).ceil() as usize).max(1);
        for k in 1..n {
            let t = k as f64 / n as f64;
            out.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
        }
        out.push(b);
    }
    if out.len() == 1 {
        // A path of one point repeated: two points, as every path has.
        out.push(out[0]);
    }
    PlanarPath {
        points: out,
        closed: path.closed,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_line_is_cut_two_points_per_diameter() {
        let p = PlanarPath {
            points: vec![[0.0, 0.0], [10.0, 0.0]],
            closed: false,
        };
        let d = discretise(&p, 0.125);
        assert_eq!(d.points.len(), 81);
        assert!((d.length() - 10.0).abs() < 1e-12);
        assert!((d.points[1][0] - 0.125).abs() < 1e-12);
    }

    #[test]
    fn corners_are_kept_and_the_length_is_the_designs() {
        // An L of 1.0 and 0.3 mm: 8 and 3 parts of 0.125 and 0.1 mm, the corner a point.
        let p = PlanarPath {
            points: vec![[0.0, 0.0], [1.0, 0.0], [1.0, 0.3]],
            closed: false,
        };
        let d = discretise(&p, 0.125);
        assert_eq!(d.points.len(), 12);
        assert_eq!(d.points[8], [1.0, 0.0]);
        assert!((d.length() - 1.3).abs() < 1e-12, "{}", d.length());
        assert!((d.points[9][1] - 0.1).abs() < 1e-12);
    }
}
