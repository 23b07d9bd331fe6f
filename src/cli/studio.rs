//! `conduit studio`: the 3D view served on 127.0.0.1, where a circuit's parts are placed by
//! hand, checked against the solid as they move, routed by the same walk as `conduit slice
//! --circuit`, and saved as the placement TOML that `--placement` reads (or exported as
//! Electronic Slic3r's `.3de`).
//!
//! The server listens on loopback only, answers only requests whose `Host` (and `Origin`, when
//! sent) is its own address, and answers a malformed request with a 4xx and a JSON
//! `{"error": …}`; the work behind each request is the library's, and its failures come back
//! the same way.

use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

use anyhow::Context;
use axum::extract::{Request, State};
use axum::http::{StatusCode, header};
use axum::middleware::{self, Next};
use axum::response::{Html, IntoResponse, Response};
use axum::routing::{get, post};
use axum::{Json, Router};
use serde::Deserialize;
use serde_json::json;

use super::{Failure, args::StudioArgs, config::resolve};
use conduit::check::Frame;
use conduit::circuit::placement_toml::placement_toml;
use conduit::circuit::{Circuit, Electronics, Placement};
use conduit::config::Config;
use conduit::pipeline::place::{
    Auto, BottomChoice, Checked, FromBoard, PlaneChoice, Solid, check_placement, place_auto,
    place_from_board,
};
use conduit::pipeline::{place_on_bed_with_offsets, slice_scene_watched};
use conduit::route::RouteProgress;
use conduit::scene::{Scene, write_atomically};
use conduit::view::studio::{PartPose, StudioView, apply_poses, poses};
use conduit::view::{
    CircuitView, Entry, MeshView, ViewData, circuit_of, circuit_view, job_of, mesh_views, page_for,
};

/// Everything the server holds.
struct Studio {
    cfg: Config,
    scene: Scene,
    solid: Solid,
    circuit: Circuit,
    circuit_path: PathBuf,
    model_path: PathBuf,
    placement: Mutex<Placement>,
    save_path: PathBuf,
    models: Vec<MeshView>,
    /// A route is running (one at a time).
    routing: AtomicBool,
    progress: Arc<Mutex<Option<RouteProgress>>>,
    /// `127.0.0.1:PORT` and `localhost:PORT`: the only hosts answered.
    hosts: [String; 2],
}

type Shared = Arc<Studio>;

/// A request's failure: its status and message, sent as `{"error": message}`.
struct ApiError(StatusCode, String);

impl IntoResponse for ApiError {
    fn into_response(self) -> Response {
        (self.0, Json(json!({ "error": self.1 }))).into_response()
    }
}

fn bad_request(e: impl std::fmt::Display) -> ApiError {
    ApiError(StatusCode::BAD_REQUEST, e.to_string())
}

/// The body of the placing, routing and saving requests: the poses the page holds.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Poses {
    parts: Vec<PartPose>,
}

pub(crate) fn run(args: StudioArgs) -> Result<(), Failure> {
    let cfg = resolve(&args.config)?;
    let scene = super::slice::load_models(std::slice::from_ref(&args.model))?;
    let circuit = Circuit::load(&args.circuit).map_err(anyhow::Error::from)?;
    let solid = Solid::of(&scene, &cfg).with_context(|| format!("{}", args.model.display()))?;
    let placement = start_placement(&args, &scene, &cfg, &circuit)?;
    let save_path = args.save.clone().unwrap_or_else(|| match &args.placement {
        Some(p) if p.extension().is_some_and(|e| e == "toml") => p.clone(),
        _ => args.model.with_extension("placement.toml"),
    });
    let (meshes, _) = place_on_bed_with_offsets(&scene, &cfg);
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .context("starting the server's runtime")?;
    runtime.block_on(async move {
        let listener = tokio::net::TcpListener::bind(SocketAddr::from(([127, 0, 0, 1], args.port)))
            .await
            .with_context(|| format!("cannot listen on 127.0.0.1:{}", args.port))?;
        let port = listener
            .local_addr()
            .context("the server's address")?
            .port();
        let studio = Arc::new(Studio {
            models: mesh_views(&meshes),
            cfg,
            scene,
            solid,
            circuit,
            circuit_path: args.circuit.clone(),
            model_path: args.model.clone(),
            placement: Mutex::new(placement),
            save_path,
            routing: AtomicBool::new(false),
            progress: Arc::new(Mutex::new(None)),
            hosts: [format!("127.0.0.1:{port}"), format!("localhost:{port}")],
        });
        let app = Router::new()
            .route("/", get(index))
            .route("/api/place", post(place))
            .route("/api/route", post(route))
            .route("/api/progress", get(progress))
            .route("/api/save", post(save))
            .route("/api/export-3de", post(export_3de))
            .fallback(|| async { ApiError(StatusCode::NOT_FOUND, "no such page".into()) })
            .layer(middleware::from_fn_with_state(studio.clone(), guard))
            .with_state(studio);
        let url = format!("http://127.0.0.1:{port}/");
        outln!("conduit studio: {url} (Ctrl-C to stop)")?;
        if args.open {
            super::view::open_url(&url);
        }
        axum::serve(listener, app)
            .with_graceful_shutdown(async {
                while !conduit::interrupt::requested() {
                    tokio::time::sleep(std::time::Duration::from_millis(200)).await;
                }
            })
            .await
            .context("serving the studio")?;
        Ok::<(), Failure>(())
    })?;
    Ok(())
}

/// The placement the studio starts from: `--placement`, else the board's layout, else the
/// parts packed inside the solid, else a row of parts beside the model.
fn start_placement(
    args: &StudioArgs,
    scene: &Scene,
    cfg: &Config,
    circuit: &Circuit,
) -> Result<Placement, Failure> {
    if let Some(p) = &args.placement {
        return Ok(Placement::load(p).map_err(anyhow::Error::from)?);
    }
    let source = Some(args.circuit.display().to_string());
    let ext = args
        .circuit
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    if let Some(kicad) = match ext.as_deref() {
        Some("brd") => Some(false),
        Some("kicad_pcb") => Some(true),
        _ => None,
    } {
        let board = super::place::read_board(&args.circuit, kicad)?;
        let how = FromBoard {
            at: None,
            rotate_deg: 0.0,
            scale: 1.0,
            plane: PlaneChoice::UnderTop,
            bottom: BottomChoice::Below(None),
            body_height: 1.0,
        };
        match place_from_board(scene, cfg, circuit, &board, &how, source.clone()) {
            Ok(o) => return Ok(o.placement),
            Err(e) => warnln!("{}: not laid out as the board: {e}", args.circuit.display()),
        }
    }
    let how = Auto {
        z_range: None,
        from_top: None,
        spacing: None,
        body_height: 1.0,
    };
    match place_auto(scene, cfg, circuit, &how, source) {
        Ok(o) => Ok(o.placement),
        Err(e) => {
            warnln!("the parts do not pack inside the model ({e}); they start in a row beside it");
            Ok(row_beside(scene, circuit)?)
        }
    }
}

/// Every part in a row along +x beside object 0's box, on its bottom plane.
fn row_beside(scene: &Scene, circuit: &Circuit) -> anyhow::Result<Placement> {
    let b = conduit::pipeline::model_bboxes(scene)
        .first()
        .copied()
        .context("the model has no object")?;
    let mut toml = String::from("origin = \"model\"\n");
    let mut x = b.max[0] + 5.0;
    for part in &circuit.parts {
        toml.push_str(&format!(
            "[[part]]\nname = {}\nx = {x:.3}\ny = {:.3}\nz = {:.3}\n",
            conduit::circuit::placement_toml::toml_string(&part.name),
            (b.min[1] + b.max[1]) / 2.0,
            b.min[2]
        ));
        x += 8.0;
    }
    Ok(Placement::from_toml(&toml)?)
}

/// Refuses requests for another host (DNS rebinding) or from another origin (cross-site).
async fn guard(State(s): State<Shared>, req: Request, next: Next) -> Response {
    let headers = req.headers();
    let host = headers.get(header::HOST).and_then(|h| h.to_str().ok());
    if !host.is_some_and(|h| s.hosts.iter().any(|ok| ok == h)) {
        return ApiError(StatusCode::FORBIDDEN, "wrong host".into()).into_response();
    }
    if let Some(origin) = headers.get(header::ORIGIN) {
        let ok = origin.to_str().ok().is_some_and(|o| {
            s.hosts
                .iter()
                .any(|h| o.strip_prefix("http://") == Some(h.as_str()))
        });
        if !ok {
            return ApiError(
                StatusCode::FORBIDDEN,
                "requests from other sites are refused".into(),
            )
            .into_response();
        }
    }
    next.run(req).await
}

/// The placement with `poses` applied, checked against the solid.
fn checked(s: &Studio, body: &Poses) -> Result<(Placement, Checked), ApiError> {
    let mut placement = s
        .placement
        .lock()
        .map_err(|_| ApiError(StatusCode::INTERNAL_SERVER_ERROR, "state lost".into()))?
        .clone();
    apply_poses(&mut placement, &body.parts).map_err(bad_request)?;
    let found = check_placement(&s.solid, &s.cfg, &s.circuit, &placement).map_err(bad_request)?;
    Ok((placement, found))
}

fn store(s: &Studio, placement: Placement) {
    if let Ok(mut p) = s.placement.lock() {
        *p = placement;
    }
}

/// The circuit as drawn before any route: every wire a rubberband.
fn unrouted_view(s: &Studio, c: &Checked) -> CircuitView {
    circuit_view(&c.placed, None, s.cfg.electronics_params().cavity_offset)
}

fn studio_view(s: &Studio, placement: &Placement, c: &Checked) -> StudioView {
    StudioView {
        parts: poses(placement),
        origin: placement.origin,
        flagged: c.findings.flagged.clone(),
        problems: c.findings.problems.clone(),
        notes: c.findings.notes.clone(),
        save_path: s.save_path.display().to_string(),
    }
}

async fn index(State(s): State<Shared>) -> Result<Html<String>, ApiError> {
    let (placement, found) = checked(&s, &Poses { parts: Vec::new() })?;
    let data = ViewData {
        jobs: Vec::new(),
        models: s.models.clone(),
        circuit: Some(unrouted_view(&s, &found)),
        studio: Some(studio_view(&s, &placement, &found)),
    };
    let title = format!(
        "{} in {} — conduit studio",
        super::view::file_name(&s.circuit_path),
        super::view::file_name(&s.model_path)
    );
    page_for(&data, &title, Entry::Studio)
        .map(Html)
        .map_err(|e| ApiError(StatusCode::INTERNAL_SERVER_ERROR, e.to_string()))
}

async fn place(State(s): State<Shared>, Json(body): Json<Poses>) -> Result<Response, ApiError> {
    let (placement, found) = checked(&s, &body)?;
    let answer = json!({
        "circuit": unrouted_view(&s, &found),
        "flagged": found.findings.flagged,
        "problems": found.findings.problems,
        "notes": found.findings.notes,
    });
    store(&s, placement);
    Ok(Json(answer).into_response())
}

async fn progress(State(s): State<Shared>) -> Json<serde_json::Value> {
    let running = s.routing.load(Ordering::Relaxed);
    let p = s.progress.lock().ok().and_then(|p| *p);
    Json(json!({
        "running": running,
        "done": p.as_ref().map_or(0, |p| p.done),
        "total": p.as_ref().map_or(0, |p| p.total),
        "round": p.as_ref().map_or(0, |p| p.round),
        "unrouted": p.as_ref().map_or(0, |p| p.unrouted),
    }))
}

/// Clears the routing flag when a route ends, however it ends.
struct RoutingFlag(Shared);

impl Drop for RoutingFlag {
    fn drop(&mut self) {
        self.0.routing.store(false, Ordering::Relaxed);
    }
}

async fn route(State(s): State<Shared>, Json(body): Json<Poses>) -> Result<Response, ApiError> {
    let (placement, _) = checked(&s, &body)?;
    store(&s, placement.clone());
    if s.routing.swap(true, Ordering::Relaxed) {
        return Err(ApiError(
            StatusCode::CONFLICT,
            "a route is already running".into(),
        ));
    }
    let flag = RoutingFlag(s.clone());
    let answer = tokio::task::spawn_blocking(move || {
        let s = &flag.0;
        route_now(s, placement)
    })
    .await
    .map_err(|e| ApiError(StatusCode::INTERNAL_SERVER_ERROR, e.to_string()))??;
    Ok(Json(answer).into_response())
}

/// Slices the model with the circuit as `conduit slice --circuit` does and answers the view of
/// the G-code and the circuit with the wires its traces do not join.
fn route_now(s: &Studio, placement: Placement) -> Result<serde_json::Value, ApiError> {
    let e = Electronics {
        circuit: s.circuit.clone(),
        placement,
    };
    let shared = s.progress.clone();
    if let Ok(mut p) = shared.lock() {
        *p = None;
    }
    let progress: conduit::route::ProgressFn = Arc::new(move |p: RouteProgress| {
        if let Ok(mut slot) = shared.lock() {
            *slot = Some(p);
        }
    });
    let (gcode, _, _) = slice_scene_watched(&s.scene, &s.cfg, Some(&e), |_| {}, Some(&progress))
        .map_err(|e| ApiError(StatusCode::UNPROCESSABLE_ENTITY, format!("{e:#}")))?;
    let parsed = conduit_gcode::parse(&gcode).map_err(bad_request)?;
    let params = s.cfg.check_params();
    let job = job_of("routed.gcode", &parsed, &params)
        .ok_or_else(|| bad_request("the routed G-code has no move with X or Y"))?;
    let frame = Frame::Objects {
        bboxes: s.solid.bboxes.clone(),
        offsets: s.solid.offsets.clone(),
    };
    let circuit = circuit_of(
        &parsed,
        params.flavor,
        &e,
        &frame,
        &s.cfg.electronics_params(),
    )
    .map_err(bad_request)?;
    let summary = format!(
        "routed: {} of {} wires connected, {} layers",
        circuit.wires - circuit.unrouted.len(),
        circuit.wires,
        job.layers.len()
    );
    Ok(json!({ "job": job, "circuit": circuit, "summary": summary }))
}

async fn save(State(s): State<Shared>, Json(body): Json<Poses>) -> Result<Response, ApiError> {
    let (placement, found) = checked(&s, &body)?;
    let mut header = vec![format!(
        "placement of {} in {}, placed by hand in conduit studio",
        super::view::file_name(&s.circuit_path),
        super::view::file_name(&s.model_path)
    )];
    header.extend(
        found
            .findings
            .problems
            .iter()
            .map(|p| format!("problem: {p}")),
    );
    let toml = placement_toml(&placement, &header, |_| None);
    let answer = write_file(&s.save_path, toml.as_bytes())?;
    store(&s, placement);
    Ok(answer)
}

/// Writes the placement as Electronic Slic3r's `.3de` beside the save file (same name,
/// `.3de`), positions from object 0's bounding-box centre.
async fn export_3de(
    State(s): State<Shared>,
    Json(body): Json<Poses>,
) -> Result<Response, ApiError> {
    let (placement, _) = checked(&s, &body)?;
    let bbox = s
        .solid
        .bboxes
        .first()
        .copied()
        .ok_or_else(|| bad_request("the model has no object"))?;
    let xml = placement.to_3de(&s.circuit, &bbox);
    write_file(&s.save_path.with_extension("3de"), xml.as_bytes())
}

/// Writes `bytes` to `path` whole or not at all; the answer names the file.
fn write_file(path: &Path, bytes: &[u8]) -> Result<Response, ApiError> {
    write_atomically(path, |f| std::io::Write::write_all(f, bytes)).map_err(
        |e: std::io::Error| {
            ApiError(
                StatusCode::INTERNAL_SERVER_ERROR,
                format!("{}: {e}", path.display()),
            )
        },
    )?;
    Ok(Json(json!({ "path": path.display().to_string() })).into_response())
}
