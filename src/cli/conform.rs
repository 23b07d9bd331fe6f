//! `conduit conform`: a 2D design laid onto a scanned surface and printed with a
//! micro-extrusion nozzle (see [`conduit::conform`]), as 3-axis G-code or, with a tool axis per
//! point ([`conduit::conform::orient`]), as a robot or five-axis program
//! ([`conduit::emit::robot`]).

use super::{Failure, args::ConformArgs, config::resolve};
use anyhow::{Context, anyhow};
use conduit::config::{Config, Corrections, Mapping};
use conduit::conform::markers::{Marker, find_markers};
use conduit::conform::orient::{self, OrientParams, OrientationReport, ToolAxis};
use conduit::conform::register::least_squares;
use conduit::conform::surface::CloudInfo;
use conduit::conform::{self, ConformParams, ConformReport, Placement, Registration, Surface};
use conduit::emit::gcode::GcodeParams;
use conduit::emit::robot::Dialect;
use conduit::geom::{Point3, Vector3};
use conduit::mesh::Mesh;
use conduit::scene::{Content, LoadOptions, load, placed_meshes, write_atomically};
use serde::Serialize;
use std::io::Write;
use std::path::Path;

/// Most markers tried in every assignment to the machine points (8·7·6 = 336 for three).
const MAX_MARKERS: usize = 8;

pub(crate) fn run(args: ConformArgs) -> Result<(), Failure> {
    let mut cfg = resolve(&args.config)?;
    match args.mapping.as_deref() {
        Some("geodesic") => cfg.conform.mapping = Mapping::Geodesic,
        Some(_) => cfg.conform.mapping = Mapping::Projection,
        None => {}
    }
    let params = ConformParams::from_settings(&cfg.conform).context("invalid configuration")?;
    let dialect_name = match &args.output_dialect {
        Some(name) => {
            eprintln!("warning: `--output {name}` is now spelled `--dialect {name}`");
            name.clone()
        }
        None => args.dialect.clone(),
    };
    let dialect = Dialect::from_name(&dialect_name);
    let axis = args
        .tool_axis
        .as_deref()
        .map(ToolAxis::parse)
        .transpose()
        .map_err(|e| Failure::Usage(e.to_string()))?
        .unwrap_or(ToolAxis::Vertical);
    if dialect.is_none() && axis != ToolAxis::Vertical {
        return Err(Failure::Usage(format!(
            "--tool-axis {} tilts the tool, which 3-axis G-code cannot do: choose --dialect \
             urscript, krl, rapid, poses-csv or gcode-5axis",
            args.tool_axis.as_deref().unwrap_or_default()
        )));
    }
    let orient_params = OrientParams::new(
        axis,
        args.max_tilt.unwrap_or(cfg.robot.max_tilt),
        cfg.robot.axis_smoothing,
    )
    .map_err(|e| Failure::Usage(e.to_string()))?;
    let place = args.place.as_deref().map(parse_place).transpose()?;
    let (surface, mesh, cloud) = load_surface(&args.surface, args.as_cloud, cfg.conform.fold_gap)?;

    // Registration.
    let machine = args
        .refs_machine
        .as_deref()
        .map(|s| parse_points(s, "--refs-machine"))
        .transpose()?;
    let mut markers = Vec::new();
    let registration = match (&args.refs_scan, args.refs_auto, &machine) {
        (Some(scan), _, Some(machine)) => {
            let scan = parse_points(scan, "--refs-scan")?;
            conform::register(&scan, machine).context("registration")?
        }
        (None, true, Some(machine)) => {
            let Some(mesh) = &mesh else {
                return Err(anyhow!(
                    "{}: --refs-auto finds marker holes in a mesh; this scan is a point cloud",
                    args.surface.display()
                )
                .into());
            };
            markers = find_markers(mesh, cfg.conform.marker_max_size);
            auto_register(&markers, machine)
                .with_context(|| format!("{}: --refs-auto", args.surface.display()))?
        }
        (None, false, Some(_)) => {
            return Err(Failure::Usage(
                "--refs-machine needs --refs-scan (the same points in the scan) or --refs-auto"
                    .to_owned(),
            ));
        }
        _ => Registration::identity(),
    };
    let surface = if registration.method == "identity" {
        surface
    } else {
        surface
            .transformed(&registration.transform)
            .with_context(|| format!("{}: registered surface", args.surface.display()))?
    };

    // Design.
    let design = match load(&args.design, &LoadOptions::default())
        .map_err(anyhow::Error::from)?
        .content
    {
        Content::Design(d) => d,
        _ => {
            return Err(anyhow!("{}: not an SVG design", args.design.display()).into());
        }
    };
    let (lo, hi) = (surface.min(), surface.max());
    let place = place.unwrap_or(Placement {
        x: (lo.x + hi.x) / 2.0,
        y: (lo.y + hi.y) / 2.0,
        rot_deg: 0.0,
        scale: 1.0,
    });
    let planned = orient::plan(&surface, &design, &place, &params, &orient_params)
        .with_context(|| format!("{} on {}", args.design.display(), args.surface.display()))?;
    let mut report = planned.report;
    report.registration = registration;
    report.markers = markers;
    report.surface.cloud = cloud;

    let lowest = planned
        .paths
        .iter()
        .flatten()
        .map(|p| p.z)
        .fold(f64::MAX, f64::min);
    let safe_z = hi.z + cfg.conform.travel_clearance;
    let writer = conform::machine_params(cfg.gcode_params(), &cfg.conform, &surface, lowest)
        .context("[conform]")?;
    let moves = match dialect {
        None => {
            // 3-axis G-code, replayed against the surface.
            let (gcode, replay) =
                conform::write_and_replay(&planned.paths, &cfg, &surface, &params)
                    .context("[conform]")?;
            write_atomically(&args.out, |f| f.write_all(&gcode))
                .with_context(|| format!("{}: cannot write G-code", args.out.display()))?;
            report.replay = Some(replay);
            None
        }
        Some(dialect) => Some(write_program(
            &args,
            dialect,
            (&planned.paths, &planned.axes),
            &cfg,
            &writer,
            safe_z,
        )?),
    };
    if let Some(path) = &args.report {
        let full = FullReport {
            conform: &report,
            orientation: &planned.orientation,
        };
        let json = serde_json::to_vec_pretty(&full).context("serialising the report")?;
        write_atomically(path, |f| f.write_all(&json))
            .with_context(|| format!("{}: cannot write report", path.display()))?;
    }
    if let Some(moves) = moves {
        let o = &planned.orientation;
        eprintln!(
            "{}: {} program, {} path(s), {} points, {moves} moves, {:.1} mm on the surface; tool \
             axis {}: largest tilt {:.1}°, largest angle to the surface normal {:.1}°{}; {} \
             nozzle contact(s)",
            args.out.display(),
            dialect_name,
            report.paths,
            report.points,
            report.geometry.length_3d,
            o.tool_axis,
            o.max_tilt_deg,
            o.max_normal_deviation_deg,
            if o.limited > 0 {
                format!(
                    " ({} axes held at the {}° limit)",
                    o.limited, o.max_tilt_limit_deg
                )
            } else {
                String::new()
            },
            o.contacts
        );
        return warnings(&args, &report);
    }
    let replay = report.replay.as_ref().map_or(0, |r| r.printing + r.travel);
    // The other modes on the same path, for comparison.
    let others: Vec<String> = Corrections::ALL
        .iter()
        .filter(|&&m| m != params.corrections)
        .map(|&m| format!("{} {:.3}", m.name(), report.comparison.of(m).mean_abs_error))
        .collect();
    eprintln!(
        "{}: {} path(s), {} points, {:.1} mm on the surface ({:.1} mm in the plane), Δz {:.2} mm; \
         deposit error {:.3} mm mean with {} corrections ({}); {} nozzle contact(s) in the replay",
        args.out.display(),
        report.paths,
        report.points,
        report.geometry.length_3d,
        report.geometry.length_2d,
        report.geometry.delta_z,
        report.comparison.of(params.corrections).mean_abs_error,
        report.corrections,
        others.join(", "),
        replay
    );
    warnings(&args, &report)
}

/// Writes the oriented paths as a robot or five-axis program to `--out`; returns the moves.
fn write_program(
    args: &ConformArgs,
    dialect: Dialect,
    (paths, axes): (&[Vec<Point3>], &[Vec<Vector3>]),
    cfg: &Config,
    writer: &GcodeParams,
    safe_z: f64,
) -> anyhow::Result<usize> {
    let program = orient::program(paths, axes, &cfg.conform, safe_z);
    super::robot_out::write_robot_file(
        &args.out,
        dialect,
        &program,
        &cfg.robot,
        (writer, cfg.conform.tool),
    )
}

/// The conform report with the orientation section.
#[derive(Serialize)]
struct FullReport<'a> {
    #[serde(flatten)]
    conform: &'a ConformReport,
    orientation: &'a OrientationReport,
}

/// Warnings about the run: contacts in the start/end G-code, design points off the surface, a
/// folded point cloud.
fn warnings(args: &ConformArgs, report: &ConformReport) -> Result<(), Failure> {
    if let Some(r) = &report.replay
        && r.custom > 0
    {
        eprintln!(
            "warning: the printer's start or end G-code moves the nozzle into the surface ({} \
             sample(s), first at {:?}): check printer.start_gcode (the default homes and primes a \
             line on the bed's front edge) and printer.end_gcode",
            r.custom,
            r.places.first().copied().unwrap_or_default()
        );
    }
    if report.off_surface > 0 {
        eprintln!(
            "warning: {} design point(s) have no surface under them and were left out",
            report.off_surface
        );
    }
    if let Some(c) = &report.surface.cloud
        && c.folds
    {
        eprintln!(
            "warning: {}: the point cloud folds over itself; a height field holds only its top \
             ({} of {} points below a fold were left out)",
            args.surface.display(),
            c.below_fold,
            c.points
        );
    }
    Ok(())
}

/// The surface of a scan file, with its mesh (for markers) and, for a cloud, what was done.
fn load_surface(
    path: &Path,
    as_cloud: bool,
    fold_gap: f64,
) -> Result<(Surface, Option<Mesh>, Option<CloudInfo>), Failure> {
    let file = load(path, &LoadOptions::default()).map_err(anyhow::Error::from)?;
    for w in &file.warnings {
        eprintln!("warning: {}: {w}", path.display());
    }
    let named = |e: conform::surface::SurfaceError| anyhow!("{}: {e}", path.display());
    match file.content {
        Content::Mesh { scene, .. } => {
            let mut mesh = Mesh::default();
            for m in placed_meshes(&scene) {
                mesh.append(&m);
            }
            let surface = Surface::from_mesh(&mesh).map_err(named)?;
            Ok((surface, Some(mesh), None))
        }
        Content::PointCloud(cloud) if !cloud.triangles.is_empty() && !as_cloud => {
            let mesh = Mesh {
                name: String::new(),
                vertices: cloud
                    .points
                    .iter()
                    .map(|p| Point3::new(p[0], p[1], p[2]))
                    .collect(),
                triangles: cloud.triangles.clone(),
            };
            let surface = Surface::from_mesh(&mesh).map_err(named)?;
            Ok((surface, Some(mesh), None))
        }
        Content::PointCloud(cloud) => {
            let (surface, info) = Surface::from_cloud(&cloud.points, fold_gap).map_err(named)?;
            Ok((surface, None, Some(info)))
        }
        _ => Err(anyhow!(
            "{}: holds no surface (a mesh or a point cloud is needed)",
            path.display()
        )
        .into()),
    }
}

/// The registration of the markers to the machine points in the assignment with the smallest
/// residual (every ordered choice of markers is tried).
fn auto_register(markers: &[Marker], machine: &[Point3]) -> anyhow::Result<Registration> {
    let n = machine.len();
    if markers.len() < n {
        return Err(anyhow!(
            "found {} marker hole(s), {} needed (raise conform.marker_max_size if the holes are \
             larger)",
            markers.len(),
            n
        ));
    }
    if markers.len() > MAX_MARKERS {
        return Err(anyhow!(
            "found {} small holes, more than {MAX_MARKERS}: lower conform.marker_max_size or \
             repair the scan's other holes",
            markers.len()
        ));
    }
    let pts: Vec<Point3> = markers
        .iter()
        .map(|m| Point3::new(m.centroid[0], m.centroid[1], m.centroid[2]))
        .collect();
    let mut best: Option<Registration> = None;
    let mut chosen = Vec::with_capacity(n);
    permute(pts.len(), n, &mut chosen, &mut |idx| {
        let scan: Vec<Point3> = idx.iter().map(|&i| pts[i]).collect();
        if let Ok(r) = least_squares(&scan, machine)
            && best.as_ref().is_none_or(|b| r.rms < b.rms)
        {
            best = Some(r);
        }
    });
    best.ok_or_else(|| anyhow!("the markers are collinear"))
}

/// Calls `f` with every ordered choice of `k` of `0..n`, in lexicographic order.
fn permute(n: usize, k: usize, chosen: &mut Vec<usize>, f: &mut impl FnMut(&[usize])) {
    if chosen.len() == k {
        f(chosen);
        return;
    }
    for i in 0..n {
        if !chosen.contains(&i) {
            chosen.push(i);
            permute(n, k, chosen, f);
            chosen.pop();
        }
    }
}

fn parse_numbers(s: &str, what: &str) -> anyhow::Result<Vec<f64>> {
    s.split(',')
        .map(|v| {
            v.trim()
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| anyhow!("{what}: `{}` is not a number", v.trim()))
        })
        .collect()
}

fn parse_place(s: &str) -> Result<Placement, Failure> {
    let v = parse_numbers(s, "--place").map_err(|e| Failure::Usage(e.to_string()))?;
    match v.as_slice() {
        [x, y] => Ok(Placement {
            x: *x,
            y: *y,
            rot_deg: 0.0,
            scale: 1.0,
        }),
        [x, y, r] => Ok(Placement {
            x: *x,
            y: *y,
            rot_deg: *r,
            scale: 1.0,
        }),
        [x, y, r, s] if *s > 0.0 => Ok(Placement {
            x: *x,
            y: *y,
            rot_deg: *r,
            scale: *s,
        }),
        _ => Err(Failure::Usage(format!(
            "--place: expected x,y[,rot[,scale]] with a positive scale, got `{s}`"
        ))),
    }
}

fn parse_points(s: &str, what: &str) -> Result<Vec<Point3>, Failure> {
    let pts = s
        .split(';')
        .filter(|p| !p.trim().is_empty())
        .map(|p| match parse_numbers(p, what)?.as_slice() {
            [x, y, z] => Ok(Point3::new(*x, *y, *z)),
            _ => Err(anyhow!("{what}: `{}` is not x,y,z", p.trim())),
        })
        .collect::<anyhow::Result<Vec<Point3>>>()
        .map_err(|e| Failure::Usage(e.to_string()))?;
    if pts.len() < 3 {
        return Err(Failure::Usage(format!(
            "{what}: at least three points `x,y,z;x,y,z;x,y,z` are needed, got {}",
            pts.len()
        )));
    }
    Ok(pts)
}
