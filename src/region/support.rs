//! Support material: columns of sparse lines under the parts of an object that overhang more
//! than a threshold angle, topped by dense interface layers and kept a removable gap away from
//! the part.
//!
//! Place in the pipeline: part of the regions stage. Input is one object's (simplified) islands
//! per layer with the layer heights; output is, per layer, the support's area and its
//! centrelines, which the Program stage prints as `Support material` and `Support material
//! interface`.
//!
//! Layer `i` has islands `L_i`, height `h_i`, top `t_i` and bottom `b_i = t_i − h_i`.
//!
//! 1. **Overhangs.** `O_i = L_i − grow(L_(i−1), h_i · tan θ)` with `θ` the threshold angle from
//!    the vertical: what of layer `i` reaches further out over the layer below than a wall
//!    leaning at `θ` would. Pieces below [`MIN_OVERHANG_MM2`] are noise of the slicing and are
//!    dropped. Where there is an overhang, the whole step `L_i − L_(i−1)` near it is the
//!    contact, so a wall at exactly `θ` gets no support and at `θ + 1°` its per-layer steps
//!    add up below into one wedge of support under the whole slope.
//! 2. **Contact.** The overhang of layer `i` is supported from layer `c(i)`, the highest layer
//!    whose top is at least `z_gap` below `b_i` (the gap rounded up to whole layers, so it never
//!    shrinks): the empty layers between are what lets the support break away. An overhang
//!    closer to the bed than that is held by support on the first layer, which comes off like
//!    a brim.
//! 3. **Columns**, from the top down: `C_j = (C_(j+1) ∪ contacts_j) − L_j`. A column ends where
//!    it meets the part (it then stands on the part's top surface). What is printed on layer `j`
//!    is `S_j = C_j − grow(L_j, xy_gap + w/2) − L_(j−1) − … − L_(j−g)`: the line centres stay
//!    `xy_gap + w/2` from the part's walls (so the beads' edges keep `xy_gap`), and `g` layers
//!    (the same gap as above) stay empty over a top surface the column stands on. With
//!    `buildplate_only`, every column that would stand on the part is left out from the part's
//!    footprint up: `S_j` also loses everything over `L_0 ∪ … ∪ L_j`.
//! 4. **Interface**: the part of `S_j` directly under the part's layers whose contact layer is
//!    one of the `interface_layers` layers from `j` up, filled densely (`interface_spacing`
//!    between lines) at 90° to the base lines, so the part's first layer lies on a flat, closed
//!    surface; the rest of `S_j` is the **base**, lines `spacing` apart (and both directions
//!    with the grid pattern), joined into zig-zags, inside a loop along each piece's edge
//!    (the sheath, unless turned off). The first layer's base is filled at the interface
//!    spacing, to hold on to the bed.
//!
//! Columns are computed layer by layer (each depends on the one above), the fills in parallel;
//! the result does not depend on the thread count.

use super::gapfill::gap_fill;
use super::infill::lines::{LineFamily, fill_family};
use super::perimeters::PERIMETER_JOIN;
use crate::geom::{
    ExPolygon, Join, Polygon, Polyline, Tolerances, difference, intersection, offset, union,
};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Overhang pieces smaller than this (mm²) are slicing noise, not overhangs.
pub const MIN_OVERHANG_MM2: f64 = 0.01;

/// Support pieces smaller than this (mm²) on a layer are not printed: a line or two that would
/// neither hold nor stick.
pub const MIN_SUPPORT_MM2: f64 = 0.2;

/// Largest threshold angle, degrees from the vertical (90° would support nothing at all, and
/// every wall near it).
pub const MAX_THRESHOLD_DEG: f64 = 89.0;

/// How the base of the support columns is filled.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "lowercase")]
pub enum SupportPattern {
    /// Parallel lines in one direction, joined into zig-zags: the easiest to break away.
    #[default]
    Rectilinear,
    /// Lines in both directions on every layer: stiffer columns for tall supports.
    Grid,
}

/// How support material is built (`[support]` in the config, whose keys these are), when
/// `slice.support_material` is on: columns of lines under every overhang steeper than
/// `threshold_angle`, topped by dense interface layers, `z_gap` below the part and `xy_gap`
/// beside it. Lengths in mm.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct SupportParams {
    /// Build support at all: `slice.support_material`, not a key of `[support]`.
    #[serde(skip)]
    pub enabled: bool,
    /// Overhangs leaning out further than this from the vertical are supported, degrees, 0 to
    /// 89. Default 45, the angle `conduit check` holds every print to. PrusaSlicer's
    /// `support_material_threshold` counts from the horizontal: 55 there is 35 here.
    pub threshold_angle: f64,
    /// Vertical gap between the support's top and the part (and between a top surface of the
    /// part and the support standing on it), rounded up to whole layers: what lets the support
    /// break away. 0 to 5; 0 only for soluble support. Default 0.2.
    pub z_gap: f64,
    /// Horizontal gap between the support's beads and the part's walls, 0 to 20. Default 0.3.
    pub xy_gap: f64,
    /// Dense layers at the top of each column, 0 to 100. Default 3.
    pub interface_layers: usize,
    /// Gap between neighbouring lines of the columns' base, 0 to 50. Default 2.5.
    pub spacing: f64,
    /// Gap between neighbouring interface lines, 0 to 50. Default 0.2.
    pub interface_spacing: f64,
    /// Base pattern: `"rectilinear"` (default; parallel lines joined into zig-zags, the easiest
    /// to remove) or `"grid"` (both directions on every layer, stiffer for tall columns).
    pub pattern: SupportPattern,
    /// Direction of the base lines, degrees counter-clockwise from +X; the interface runs at
    /// 90° to it. Default 0.
    pub angle: f64,
    /// Only build support that stands on the bed, never on the part. Default false.
    pub buildplate_only: bool,
    /// A loop around each piece of the columns' base: it holds the base lines' ends and the
    /// interface above (stiffer, a little harder to remove). Default true.
    pub sheath: bool,
}

impl Default for SupportParams {
    /// PrusaSlicer's defaults, with the threshold at 45° from the vertical.
    fn default() -> Self {
        Self {
            enabled: false,
            threshold_angle: 45.0,
            z_gap: 0.2,
            xy_gap: 0.3,
            interface_layers: 3,
            spacing: 2.5,
            interface_spacing: 0.2,
            pattern: SupportPattern::Rectilinear,
            angle: 0.0,
            buildplate_only: false,
            sheath: true,
        }
    }
}

impl SupportParams {
    /// What is wrong with these parameters, one line each (empty when they are usable).
    pub fn problems(&self) -> Vec<String> {
        let mut out = Vec::new();
        let mut need = |ok: bool, what: String| {
            if !ok {
                out.push(what);
            }
        };
        let t = self.threshold_angle;
        need(
            t.is_finite() && (0.0..=MAX_THRESHOLD_DEG).contains(&t),
            format!("support.threshold_angle must be between 0 and {MAX_THRESHOLD_DEG}°, got {t}"),
        );
        for (name, v, max) in [
            ("z_gap", self.z_gap, 5.0),
            ("xy_gap", self.xy_gap, 20.0),
            ("spacing", self.spacing, 50.0),
            ("interface_spacing", self.interface_spacing, 50.0),
        ] {
            need(
                v.is_finite() && (0.0..=max).contains(&v),
                format!("support.{name} must be between 0 and {max} mm, got {v}"),
            );
        }
        need(
            self.angle.is_finite(),
            format!("support.angle must be finite, got {}", self.angle),
        );
        need(
            self.interface_layers <= 100,
            format!(
                "support.interface_layers must be at most 100, got {}",
                self.interface_layers
            ),
        );
        out
    }
}

/// The support on one layer of one object.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SupportLayer {
    /// Where the support's line centres may go on this layer (base and interface together).
    pub area: Vec<ExPolygon>,
    /// Loops around the base's pieces (empty without a sheath).
    pub sheath: Vec<Polygon>,
    /// Base lines, in print order.
    pub base: Vec<Polyline>,
    /// Interface lines, in print order.
    pub interface: Vec<Polyline>,
    /// Extrusion width of both, mm.
    pub width: f64,
}

impl SupportLayer {
    /// No support on this layer.
    pub fn is_empty(&self) -> bool {
        self.sheath.is_empty() && self.base.is_empty() && self.interface.is_empty()
    }
}

/// The support of every layer of one object (see the module docs): `layers[i]` are the
/// islands of layer `i`, `heights[i]` its height (mm) and `widths[i]` the extrusion width of
/// its support lines. Empty layers when support is off, the parameters are unusable or the
/// slices disagree in number.
pub fn make_supports(
    layers: &[Vec<ExPolygon>],
    heights: &[f64],
    widths: &[f64],
    params: &SupportParams,
) -> Vec<SupportLayer> {
    let n = layers.len();
    let empty = || vec![SupportLayer::default(); n];
    if !params.enabled
        || !params.problems().is_empty()
        || heights.len() != n
        || widths.len() != n
        || n < 2
    {
        return empty();
    }
    let tops: Vec<f64> = heights
        .iter()
        .scan(0.0, |z, h| {
            *z += h;
            Some(*z)
        })
        .collect();
    let tan = params.threshold_angle.to_radians().tan();
    let round = Join::Round(Tolerances::default().curve_flattening.mm());
    // 1. Overhangs, each layer against the one below; the contact is the whole step out over
    // the layer below where an overhang is, so the bands of a slope join into one wedge.
    let overhangs: Vec<Vec<ExPolygon>> = (0..n)
        .into_par_iter()
        .map(|i| {
            if i == 0 || layers[i].is_empty() {
                return Vec::new();
            }
            let d = heights[i] * tan;
            // Round: a corner of the layer below holds up to the same distance every way.
            let below = offset(&layers[i - 1], d, round);
            let mut o = difference(&layers[i], &below);
            o.retain(|e| e.area_mm2() >= MIN_OVERHANG_MM2);
            if o.is_empty() {
                return o;
            }
            let step = difference(&layers[i], &layers[i - 1]);
            intersection(&step, &offset(&o, d + widths[i], PERIMETER_JOIN))
        })
        .collect();
    // 2. Contact layers: c(i), the highest layer at least z_gap below layer i's bottom.
    let contact_of = |i: usize| -> Option<usize> {
        let limit = tops[i] - heights[i] - params.z_gap + 1e-6;
        (0..i).rev().find(|&j| tops[j] <= limit)
    };
    let mut contacts: Vec<Vec<ExPolygon>> = vec![Vec::new(); n];
    // Per layer j: the part's layers whose contact layer is j (for the interface).
    let mut supported_from: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (i, o) in overhangs.into_iter().enumerate() {
        if o.is_empty() {
            continue;
        }
        // An overhang within the gap of the bed is held by the first layer's support anyway
        // (it breaks away like a brim).
        let j = contact_of(i).unwrap_or(0);
        contacts[j].extend(o);
        supported_from[j].push(i);
    }
    let gap_layers = |j: usize| -> usize {
        // The layers below j within z_gap of its bottom stay empty over a top surface.
        let bottom = tops[j] - heights[j];
        (0..j)
            .rev()
            .take_while(|&k| tops[k] > bottom - params.z_gap + 1e-6)
            .count()
    };
    // 3. Columns, top down.
    let mut areas: Vec<Vec<ExPolygon>> = vec![Vec::new(); n];
    let mut carry: Vec<ExPolygon> = Vec::new();
    for j in (0..n).rev() {
        if !contacts[j].is_empty() {
            carry.append(&mut contacts[j]);
            carry = union(&carry);
        }
        if carry.is_empty() {
            continue;
        }
        carry = difference(&carry, &layers[j]);
        areas[j] = std::mem::take(&mut carry);
        carry = areas[j].clone();
    }
    let shadows: Vec<Vec<ExPolygon>> = if params.buildplate_only {
        let mut acc: Vec<ExPolygon> = Vec::new();
        layers
            .iter()
            .map(|l| {
                acc.extend(l.iter().cloned());
                acc = union(&acc);
                acc.clone()
            })
            .collect()
    } else {
        vec![Vec::new(); n]
    };
    // What is printed, the interface and the fills, layer by layer.
    (0..n)
        .into_par_iter()
        .map(|j| {
            if areas[j].is_empty() {
                return SupportLayer::default();
            }
            let w = widths[j];
            // One difference at a time: the layers' outlines nearly coincide, and a union of
            // them would cross every edge with its neighbour's.
            let beside = offset(&layers[j], params.xy_gap + w / 2.0, PERIMETER_JOIN);
            let mut area = difference(&areas[j], &beside);
            for k in (0..j).rev().take(gap_layers(j)) {
                if !area.is_empty() {
                    area = difference(&area, &layers[k]);
                }
            }
            if !shadows[j].is_empty() && !area.is_empty() {
                area = difference(&area, &shadows[j]);
            }
            area.retain(|e| e.area_mm2() >= MIN_SUPPORT_MM2);
            if area.is_empty() {
                return SupportLayer::default();
            }
            let above: Vec<ExPolygon> = (j..n.min(j + params.interface_layers))
                .flat_map(|k| &supported_from[k])
                .flat_map(|&i| layers[i].iter().cloned())
                .collect();
            let interface_area = if above.is_empty() {
                Vec::new()
            } else {
                intersection(&area, &union(&above))
            };
            let base_area = if interface_area.is_empty() {
                area.clone()
            } else {
                difference(&area, &interface_area)
            };
            let spacing = crate::region::spacing(w, heights[j]);
            let dense = params.interface_spacing + spacing;
            let base_gap = if j == 0 {
                dense
            } else {
                params.spacing + spacing
            };
            let family = |angle_deg: f64, spacing_mm: f64| LineFamily {
                angle_rad: angle_deg.to_radians(),
                spacing_mm,
                phase: 0.5,
            };
            let mut families = vec![family(params.angle, base_gap)];
            if params.pattern == SupportPattern::Grid && j > 0 {
                families.push(family(params.angle + 90.0, base_gap));
            }
            // The sheath runs along the base's edge; the lines stop half a spacing inside it.
            let (sheath, lines_area) = if params.sheath && !base_area.is_empty() {
                let loops = base_area
                    .iter()
                    .flat_map(|e| std::iter::once(&e.contour).chain(&e.holes))
                    .filter(|p| p.points.len() >= 3)
                    .cloned()
                    .collect();
                (loops, offset(&base_area, -spacing / 2.0, PERIMETER_JOIN))
            } else {
                (Vec::new(), base_area.clone())
            };
            let base = fill_pieces(&lines_area, &families);
            let interface = fill_pieces(&interface_area, &[family(params.angle + 90.0, dense)]);
            SupportLayer {
                area,
                sheath,
                base,
                interface,
                width: w,
            }
        })
        .collect()
}

/// Each piece of `area` filled with the line `families`, joined into zig-zags; a piece too
/// narrow for any line of the lattice (the thin top of a wedge under a slope) gets a line along
/// its middle instead.
fn fill_pieces(area: &[ExPolygon], families: &[LineFamily]) -> Vec<Polyline> {
    let mut out = Vec::new();
    for piece in area {
        let piece = std::slice::from_ref(piece);
        let lines: Vec<Polyline> = families
            .iter()
            .flat_map(|f| fill_family(piece, *f, true))
            .collect();
        if lines.is_empty() {
            out.extend(
                gap_fill(piece, 0.0, 1000.0)
                    .into_iter()
                    .map(|t| Polyline { points: t.points }),
            );
        } else {
            out.extend(lines);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point2;
    use crate::region::test_util::rect_island;

    fn on(params: SupportParams) -> SupportParams {
        SupportParams {
            enabled: true,
            ..params
        }
    }

    /// A T: a 4 × 20 mm stem for `stem` layers, then a 20 × 20 mm slab for 5 layers, all 0.2 mm.
    fn tee(stem: usize) -> Vec<Vec<ExPolygon>> {
        let mut layers = vec![vec![rect_island(8.0, 0.0, 12.0, 20.0)]; stem];
        layers.extend(vec![vec![rect_island(0.0, 0.0, 20.0, 20.0)]; 5]);
        layers
    }

    fn run(layers: &[Vec<ExPolygon>], params: &SupportParams) -> Vec<SupportLayer> {
        let n = layers.len();
        make_supports(layers, &vec![0.2; n], &vec![0.45; n], params)
    }

    fn x_range(area: &[ExPolygon]) -> (f64, f64) {
        let xs = area
            .iter()
            .flat_map(|e| &e.contour.points)
            .map(|p| p.to_mm().0);
        xs.fold((f64::MAX, f64::MIN), |(a, b), x| (a.min(x), b.max(x)))
    }

    #[test]
    fn a_tee_gets_columns_under_its_arms_with_a_gap_above_and_beside() {
        let layers = tee(10);
        let s = run(&layers, &on(SupportParams::default()));
        // The slab starts on layer 10; with a 0.2 mm gap the support ends on layer 8.
        assert!(s[9].is_empty() && s[10..].iter().all(SupportLayer::is_empty));
        for (j, layer) in s.iter().enumerate().take(9) {
            assert!(!layer.is_empty(), "layer {j}");
            // Two columns, each from the slab's edge to xy_gap + w/2 from the stem.
            assert_eq!(layer.area.len(), 2, "layer {j}");
            let (x0, x1) = x_range(&layer.area[..1]);
            let d = 0.3 + 0.225;
            assert!(
                x0.abs() < 1e-6 && (x1 - (8.0 - d)).abs() < 1e-3,
                "{x0} {x1}"
            );
            let area: f64 = layer.area.iter().map(ExPolygon::area_mm2).sum();
            let want = 2.0 * (8.0 - d) * 20.0;
            assert!((area - want).abs() < 0.01 * want, "{area} vs {want}");
        }
        // Three interface layers at the top (6, 7, 8), base lines below.
        for (j, layer) in s.iter().enumerate().take(9) {
            assert_eq!(!layer.interface.is_empty(), j >= 6, "layer {j}");
            assert_eq!(!layer.base.is_empty(), j < 6, "layer {j}");
        }
        // Interface lines run along y (90° to the base), 0.2 mm apart edge to edge.
        let lines = &s[8].interface;
        let long: Vec<&Polyline> = lines.iter().collect();
        let spacing = crate::region::spacing(0.45, 0.2) + 0.2;
        let total: f64 = long
            .iter()
            .flat_map(|l| l.points.windows(2))
            .map(|w| {
                let (a, b) = (w[0].to_mm(), w[1].to_mm());
                (b.0 - a.0).hypot(b.1 - a.1)
            })
            .sum();
        let want = 2.0 * (8.0 - 0.525) * 20.0 / spacing;
        assert!(
            total > 0.95 * want && total < 1.15 * want,
            "{total} vs {want}"
        );
    }

    #[test]
    fn the_threshold_angle_decides_which_slopes_get_support() {
        // A wall leaning out by `step` mm per 0.2 mm layer, 20 layers.
        let lean = |step: f64| -> Vec<Vec<ExPolygon>> {
            (0..20)
                .map(|i| vec![rect_island(0.0, 0.0, 10.0 + step * i as f64, 10.0)])
                .collect()
        };
        let params = on(SupportParams::default());
        // 40° from the vertical: 0.168 mm a layer; no support.
        let gentle = run(&lean(0.2 * 40f64.to_radians().tan()), &params);
        assert!(gentle.iter().all(SupportLayer::is_empty));
        // 60°: 0.346 mm a layer; a wedge of support under the slope, growing towards the bed.
        let steep = run(&lean(0.2 * 60f64.to_radians().tan()), &params);
        let width = |l: &SupportLayer| {
            let (a, b) = x_range(&l.area);
            if l.area.is_empty() { 0.0 } else { b - a }
        };
        assert!(!steep[2].is_empty() && !steep[16].is_empty());
        assert!(width(&steep[2]) > width(&steep[10]) && width(&steep[10]) > width(&steep[16]));
        // One solid wedge, not a band per layer above.
        let area: f64 = steep[2].area.iter().map(ExPolygon::area_mm2).sum();
        assert!(area > 0.98 * width(&steep[2]) * 10.0, "{area}");
        // The wedge reaches out to the outermost edge above (within the gap's layers).
        let (_, x1) = x_range(&steep[2].area);
        let top_edge = 10.0 + 0.2 * 60f64.to_radians().tan() * 19.0;
        assert!((x1 - top_edge).abs() < 1e-3, "{x1} vs {top_edge}");
    }

    #[test]
    fn columns_stand_on_the_part_with_a_gap_unless_buildplate_only() {
        // A 20 × 20 base (layers 0–4), nothing at x < 15 on layers 5–14 but a 5 mm pillar at
        // x ∈ [15, 20], then a 20 × 20 roof (layers 15–19): the roof's overhang over the base's
        // top surface gets a column standing on the base.
        let mut layers = vec![vec![rect_island(0.0, 0.0, 20.0, 20.0)]; 5];
        layers.extend(vec![vec![rect_island(15.0, 0.0, 20.0, 20.0)]; 10]);
        layers.extend(vec![vec![rect_island(0.0, 0.0, 20.0, 20.0)]; 5]);
        let s = run(&layers, &on(SupportParams::default()));
        // Support on layers 6–13: one empty layer over the base (5), one under the roof (14).
        for (j, layer) in s.iter().enumerate() {
            assert_eq!(!layer.is_empty(), (6..=13).contains(&j), "layer {j}");
        }
        let only = on(SupportParams {
            buildplate_only: true,
            ..Default::default()
        });
        assert!(run(&layers, &only).iter().all(SupportLayer::is_empty));
        // With the base gone, the column reaches the bed.
        let mut floating = layers.clone();
        for l in floating.iter_mut().take(5) {
            *l = vec![rect_island(15.0, 0.0, 20.0, 20.0)];
        }
        let s = run(&floating, &only);
        assert!((0..=13).all(|j| !s[j].is_empty()));
        // The first layer is dense: lines at the interface spacing (the y of the long
        // horizontal segments; links and anchors along the edge are short or vertical).
        let pitch = |l: &SupportLayer| -> f64 {
            let mut ys: Vec<i64> = l
                .base
                .iter()
                .flat_map(|p| p.points.windows(2))
                .filter(|w: &&[Point2]| w[0].y == w[1].y && (w[1].x - w[0].x).abs() > 1_000_000)
                .map(|w| w[0].y)
                .collect();
            ys.sort_unstable();
            ys.dedup();
            ys.windows(2)
                .map(|w| (w[1] - w[0]) as f64 / 1e6)
                .fold(f64::MAX, f64::min)
        };
        assert!(
            pitch(&s[0]) < 0.7 && pitch(&s[3]) > 2.5,
            "{} {}",
            pitch(&s[0]),
            pitch(&s[3])
        );
    }

    #[test]
    fn off_or_unusable_parameters_give_nothing_and_problems_are_named() {
        let layers = tee(5);
        assert!(
            run(&layers, &SupportParams::default())
                .iter()
                .all(SupportLayer::is_empty)
        );
        let bad = on(SupportParams {
            threshold_angle: 95.0,
            z_gap: -1.0,
            ..Default::default()
        });
        assert_eq!(bad.problems().len(), 2);
        assert!(run(&layers, &bad).iter().all(SupportLayer::is_empty));
        assert!(
            make_supports(&layers, &[0.2], &[0.45], &on(SupportParams::default()))
                .iter()
                .all(SupportLayer::is_empty)
        );
    }

    #[test]
    fn grid_support_crosses_and_output_does_not_depend_on_threads()
    -> Result<(), rayon::ThreadPoolBuildError> {
        let layers = tee(10);
        let grid = on(SupportParams {
            pattern: SupportPattern::Grid,
            ..Default::default()
        });
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()?
            .install(|| run(&layers, &grid));
        let two = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()?
            .install(|| run(&layers, &grid));
        assert_eq!(one, two);
        let rect = run(&layers, &on(SupportParams::default()));
        let len = |l: &SupportLayer| l.base.iter().map(|p| p.points.len()).sum::<usize>();
        assert!(len(&one[3]) > len(&rect[3]));
        Ok(())
    }
}
