//! Jobs: start an optimization or a layup, follow it (JSON or server-sent events at 10 updates
//! a second), cancel it, download its files.

use std::convert::Infallible;
use std::sync::Arc;
use std::time::Duration;

use axum::extract::{Path, State};
use axum::http::StatusCode;
use axum::response::sse::{Event, KeepAlive, Sse};
use axum::response::Response;
use axum::Json;
use futures_util::stream::{self, Stream};
use serde_json::{json, Value};

use crate::adapt::{layup, nc};
use crate::error::{ApiError, ApiResult};
use crate::jobs::{JobOutput, JobView, Jobs};
use crate::names;
use crate::state::{AppState, ProgramMeta};

/// How often progress is sent while a job runs.
pub const TICK: Duration = Duration::from_millis(100);

pub async fn list(State(s): State<Arc<AppState>>) -> Json<Value> {
    Json(json!({ "jobs": s.jobs.list() }))
}

pub async fn get(State(s): State<Arc<AppState>>, Path(id): Path<String>) -> ApiResult<Json<JobView>> {
    Ok(Json(s.jobs.get(&id)?.snapshot()))
}

pub async fn cancel(State(s): State<Arc<AppState>>, Path(id): Path<String>) -> ApiResult<Json<JobView>> {
    Ok(Json(s.jobs.cancel(&s, &id)?))
}

/// Server-sent events: `progress` with the job's view every 100 ms (and at every change) while
/// it waits or runs, then one `end` with its final view.
pub async fn events(
    State(s): State<Arc<AppState>>,
    Path(id): Path<String>,
) -> ApiResult<Sse<impl Stream<Item = Result<Event, Infallible>>>> {
    let job = s.jobs.get(&id)?;
    let rx = job.subscribe();
    let stream = stream::unfold((job, rx, false), |(job, mut rx, ended)| async move {
        if ended {
            return None;
        }
        let v = job.snapshot();
        let fin = v.state.is_final();
        let data = serde_json::to_string(&v).unwrap_or_default();
        let ev = Event::default().event(if fin { "end" } else { "progress" }).data(data);
        if !fin {
            let _ = tokio::time::timeout(TICK, rx.changed()).await;
            // Changes come in bursts; never send faster than the tick.
            tokio::time::sleep(Duration::from_millis(10)).await;
        }
        Some((Ok(ev), (job, rx, fin)))
    });
    Ok(Sse::new(stream).keep_alive(KeepAlive::default()))
}

/// The optimize request: `program` and the fields of [`nc::OptimizeRequest`] (unknown fields
/// refused, which `serde(flatten)` would not do).
pub struct OptimizeBody {
    program: String,
    request: nc::OptimizeRequest,
}

impl OptimizeBody {
    fn from_value(v: &Value) -> Result<OptimizeBody, ApiError> {
        let mut obj = v.as_object().cloned().ok_or_else(|| ApiError::bad("request: a JSON object"))?;
        let program = match obj.remove("program") {
            Some(Value::String(p)) => p,
            _ => return Err(ApiError::bad("program: give the id of the program to optimize")),
        };
        let request = serde_json::from_value(Value::Object(obj)).map_err(|e| ApiError::bad(format!("request: {e}")))?;
        Ok(OptimizeBody { program, request })
    }
}

/// `POST /api/jobs/optimize`: `{"program": id, cost, bidirectional, precedence, ...}`.
pub async fn optimize(
    State(s): State<Arc<AppState>>,
    body: Result<Json<Value>, axum::extract::rejection::JsonRejection>,
) -> ApiResult<(StatusCode, Json<JobView>)> {
    let Json(raw) = body.map_err(|e| ApiError::bad(format!("request: {}", e.body_text())))?;
    let b = OptimizeBody::from_value(&raw)?;
    b.request.validate()?;
    if let Some(t) = b.request.time_limit {
        if t > s.config.max_time_limit {
            return Err(ApiError::bad(format!(
                "time_limit {t} s: the server allows at most {} s",
                s.config.max_time_limit
            )));
        }
    }
    let entry = s.program(&b.program)?;
    let machine = s.machine(&entry.meta.machine)?;
    let dialect = s.dialect(&entry.meta.dialect)?;
    let mut req = b.request.clone();
    if req.tow_width.is_none() && req.course_width.is_none() {
        req.tow_width = entry.meta.tow_width;
    }
    // The cell's meshes are looked up now, so that a wrong name is refused before the job.
    let meshes = req.molds.iter().map(|m| Ok((m.clone(), s.mesh_bytes(m)?))).collect::<ApiResult<Vec<_>>>()?;
    let program_id = entry.id.clone();
    let meta = entry.meta.clone();
    let work = Box::new(move |ctx: &crate::jobs::JobCtx| {
        let text = entry.text();
        let c1 = ctx.clone();
        let c2 = ctx.clone();
        let hooks = nc::Hooks {
            cancel: ctx.cancel_flag(),
            phase: Arc::new(move |p| c1.phase(p)),
            progress: Arc::new(move |p| c2.progress(p)),
        };
        let safety = if meshes.is_empty() {
            None
        } else {
            ctx.phase("reading the cell");
            Some(nc::cell(&machine, &dialect, &meshes, req.clearance)?)
        };
        let out = nc::optimize(&program_id, &text, &machine, &dialect, &req, safety, &hooks)?;
        let stem = program_id.strip_suffix(".nc").unwrap_or(&program_id);
        let job_id = ctx.id();
        let new_id = format!("{stem}-opt-{job_id}");
        let result = json!({
            "program": new_id,
            "original": program_id,
            "savings": out.savings,
            "per_ply": out.per_ply,
            "verified": out.verified,
            "verdict": out.verdict,
            "fell_back": out.fell_back,
            "solver_cost": [out.solver_cost.0, out.solver_cost.1],
            "reversed": out.reversed,
            "cost": out.cost,
            "download_name": format!("{stem}-optimized.nc"),
            "molds": req.molds,
            "safety": out.safety.as_ref().map(|p| json!({
                "before": nc::safety_json(&p.before),
                "after": nc::safety_json(&p.after),
            })),
        });
        let pmeta = ProgramMeta {
            machine: meta.machine.clone(),
            dialect: meta.dialect.clone(),
            description: format!("{program_id} optimized ({})", out.cost),
            original: Some(program_id.clone()),
            order: Some(out.order.clone()),
            job: Some(job_id),
            tow_width: meta.tow_width,
            cell: if req.molds.is_empty() { meta.cell.clone() } else { req.molds.clone() },
        };
        Ok(JobOutput {
            result,
            files: vec![
                ("optimized.nc".into(), out.text.clone().into_bytes()),
                ("report.json".into(), out.report_json.into_bytes()),
                ("report.html".into(), out.report_html.into_bytes()),
            ],
            program: Some((new_id, pmeta, out.text)),
        })
    });
    let target = b.program.clone();
    let view = Jobs::submit(&s, "optimize", &target, raw, work)?;
    Ok((StatusCode::ACCEPTED, Json(view)))
}

/// `POST /api/jobs/layup`: the surface view's request.
pub async fn layup(
    State(s): State<Arc<AppState>>,
    body: Result<Json<Value>, axum::extract::rejection::JsonRejection>,
) -> ApiResult<(StatusCode, Json<JobView>)> {
    let Json(raw) = body.map_err(|e| ApiError::bad(format!("request: {}", e.body_text())))?;
    let req: layup::LayupRequest =
        serde_json::from_value(raw.clone()).map_err(|e| ApiError::bad(format!("request: {e}")))?;
    layup::validate(&req)?;
    let mesh_bytes = match &req.mesh {
        Some(name) => {
            names::check("mesh", name)?;
            Some(s.mesh_bytes(name)?)
        }
        None => None,
    };
    let target = req.mesh.clone().unwrap_or_else(|| req.surface.clone());
    let work = Box::new(move |ctx: &crate::jobs::JobCtx| {
        ctx.phase("building the surface and tracing courses");
        let c = ctx.clone();
        let out = layup::generate(&req, mesh_bytes.as_ref().map(|b| b.as_slice()), &mut |n| c.count(n as u64))?;
        Ok(JobOutput {
            result: json!({ "summary": out.summary }),
            files: vec![
                ("courses.json".into(), out.courses_json.into_bytes()),
                ("courses.nc".into(), out.gcode.into_bytes()),
                ("mesh.bin".into(), out.mesh.encode()),
            ],
            program: None,
        })
    });
    let view = Jobs::submit(&s, "layup", &target, raw, work)?;
    Ok((StatusCode::ACCEPTED, Json(view)))
}

/// A job's file, if the job lists it (nothing else in its folder, nothing outside it).
pub async fn file(State(s): State<Arc<AppState>>, Path((id, name)): Path<(String, String)>) -> ApiResult<Response> {
    names::check("file", &name)?;
    let v = s.jobs.get(&id)?.snapshot();
    let listed = v
        .result
        .as_ref()
        .and_then(|r| r["files"].as_array())
        .is_some_and(|f| f.iter().any(|x| x.as_str() == Some(name.as_str())));
    if !listed {
        return Err(ApiError::NotFound(format!("{id} has no file {name:?}")));
    }
    let bytes = std::fs::read(s.ws.root().join("results").join(&v.id).join(&name))?;
    let (ctype, download): (&'static str, String) = match name.rsplit('.').next() {
        Some("html") => ("text/html; charset=utf-8", format!("{}-report.html", v.id)),
        Some("json") => ("application/json", format!("{}-{name}", v.id)),
        Some("bin") => ("application/octet-stream", name.clone()),
        _ => (
            "text/plain; charset=utf-8",
            v.result.as_ref().and_then(|r| r["download_name"].as_str()).map_or(name.clone(), str::to_string),
        ),
    };
    Ok(super::attachment(&download, ctype, bytes))
}
