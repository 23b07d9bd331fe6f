//! `conduit conform`: a 2D design laid onto a scanned surface and printed with a
//! micro-extrusion nozzle (see [`conduit::conform`]).

use super::{Failure, args::ConformArgs, config::resolve};
use anyhow::{Context, anyhow};
use conduit::config::Mapping;
use conduit::conform::markers::{Marker, find_markers};
use conduit::conform::register::least_squares;
use conduit::conform::surface::CloudInfo;
use conduit::conform::{self, ConformParams, Placement, Registration, Surface};
use conduit::geom::Point3;
use conduit::mesh::Mesh;
use conduit::scene::{Content, LoadOptions, load, placed_meshes, write_atomically};
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
    let planned = conform::plan(&surface, &design, &place, &params, |_| {})
        .with_context(|| format!("{} on {}", args.design.display(), args.surface.display()))?;
    let mut report = planned.report;
    report.registration = registration;
    report.markers = markers;
    report.surface.cloud = cloud;

    // G-code.
    let lowest = planned
        .paths
        .iter()
        .flatten()
        .map(|p| p.z)
        .fold(f64::MAX, f64::min);
    let safe_z = hi.z + cfg.conform.travel_clearance;
    let program = conform::program(&planned.paths, &cfg.conform, safe_z);
    let machine_cfg = conform::machine_config(&cfg, &surface, lowest).context("[conform]")?;
    let mut gcode = Vec::new();
    conduit::emit::gcode::write_gcode(&program, &machine_cfg, &mut gcode)
        .context("writing G-code")?;
    write_atomically(&args.output, |f| f.write_all(&gcode))
        .with_context(|| format!("{}: cannot write G-code", args.output.display()))?;
    let parsed = conduit_gcode::parse(&gcode).context("re-reading the written G-code")?;
    report.replay = Some(conform::replay::replay(
        &parsed,
        cfg.printer.flavor,
        &surface,
        &params.nozzle,
        cfg.conform.feed,
        conform::replay::body_lines(&String::from_utf8_lossy(&gcode)),
    ));
    if let Some(path) = &args.report {
        let json = serde_json::to_vec_pretty(&report).context("serialising the report")?;
        write_atomically(path, |f| f.write_all(&json))
            .with_context(|| format!("{}: cannot write report", path.display()))?;
    }
    let replay = report.replay.as_ref().map_or(0, |r| r.printing + r.travel);
    eprintln!(
        "{}: {} path(s), {} points, {:.1} mm on the surface ({:.1} mm in the plane), Δz {:.2} mm; \
         deposit error {:.3} mm mean (controls: {:.3} slope-only, {:.3} uncorrected); \
         {} nozzle contact(s) in the replay",
        args.output.display(),
        report.paths,
        report.points,
        report.geometry.length_3d,
        report.geometry.length_2d,
        report.geometry.delta_z,
        report.comparison.full.mean_abs_error,
        report.comparison.slope.mean_abs_error,
        report.comparison.none.mean_abs_error,
        replay
    );
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
