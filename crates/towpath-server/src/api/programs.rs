//! Programs: the list, uploads (parsed before they are kept), geometry, text, removal.

use std::collections::HashMap;
use std::sync::Arc;

use axum::body::Bytes;
use axum::extract::rejection::BytesRejection;
use axum::extract::{Path, Query, State};
use axum::http::{header, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::Json;
use serde_json::{json, Value};

use crate::adapt::machine::REFERENCE_DIALECT;
use crate::adapt::nc;
use crate::error::{ApiError, ApiResult};
use crate::names;
use crate::state::{AppState, ProgramEntry, ProgramMeta, Source};
use crate::workspace::Kind;

pub async fn list(State(s): State<Arc<AppState>>) -> Json<Value> {
    let programs: Vec<Value> = s.read().programs.values().map(|p| p.listing()).collect();
    Json(json!({ "programs": programs }))
}

/// Builds (once) and returns a program's geometry response.
pub(crate) async fn geometry_bytes(s: &Arc<AppState>, p: &Arc<ProgramEntry>) -> ApiResult<Arc<Vec<u8>>> {
    if let Some(g) = p.geometry.get() {
        return Ok(g.clone());
    }
    let machine = s.machine(&p.meta.machine)?;
    let dialect = s.dialect(&p.meta.dialect)?;
    let entry = p.clone();
    let bytes = tokio::task::spawn_blocking(move || -> ApiResult<Vec<u8>> {
        let text = entry.text();
        let parsed = nc::parse_program(&entry.id, &text, &machine, &dialect)?;
        let (info, mut blob) = parsed.geometry(&machine, entry.meta.order.as_deref());
        blob.meta("program", serde_json::to_value(&info).map_err(|e| ApiError::Internal(e.to_string()))?);
        blob.meta("listing", entry.listing());
        Ok(blob.encode())
    })
    .await
    .map_err(|e| ApiError::Internal(e.to_string()))??;
    Ok(p.geometry.get_or_init(|| Arc::new(bytes)).clone())
}

pub async fn geometry(State(s): State<Arc<AppState>>, Path(id): Path<String>) -> ApiResult<Response> {
    let p = s.program(&id)?;
    let bytes = geometry_bytes(&s, &p).await?;
    Ok(([(header::CONTENT_TYPE, "application/octet-stream")], Bytes::from(bytes.as_ref().clone())).into_response())
}

pub async fn info(State(s): State<Arc<AppState>>, Path(id): Path<String>) -> ApiResult<Json<Value>> {
    let p = s.program(&id)?;
    let bytes = geometry_bytes(&s, &p).await?;
    let (header, _) = crate::geometry::decode(&bytes).ok_or_else(|| ApiError::Internal("bad geometry".into()))?;
    Ok(Json(json!({ "listing": p.listing(), "program": header["program"] })))
}

pub async fn text(State(s): State<Arc<AppState>>, Path(id): Path<String>) -> ApiResult<Response> {
    let p = s.program(&id)?;
    let name = if p.id.contains('.') { p.id.clone() } else { format!("{}.nc", p.id) };
    Ok(super::attachment(&name, "text/plain; charset=utf-8", p.text().as_bytes().to_vec()))
}

pub async fn remove(State(s): State<Arc<AppState>>, Path(id): Path<String>) -> ApiResult<StatusCode> {
    let p = s.program(&id)?;
    if !matches!(p.source, Source::Upload | Source::Result) {
        return Err(ApiError::bad(format!("{id} is built in and cannot be removed")));
    }
    s.ws.remove(Kind::Programs, &id)?;
    s.ws.remove(Kind::Programs, &format!("{id}.meta.json"))?;
    s.write().programs.remove(&id);
    Ok(StatusCode::NO_CONTENT)
}

/// `POST /api/programs?name=N&machine=M&dialect=D`, the program text as the body: parsed with
/// the machine and dialect, refused (400, naming the line) if it does not read, else kept.
pub async fn upload(
    State(s): State<Arc<AppState>>,
    Query(q): Query<HashMap<String, String>>,
    body: Result<Bytes, BytesRejection>,
) -> ApiResult<(StatusCode, Json<Value>)> {
    let bytes = super::upload(&s, body)?;
    let raw = q.get("name").ok_or_else(|| ApiError::bad("name: give the program's file name"))?;
    names::check("program", raw)?;
    let name = raw.clone();
    let machine_name = q.get("machine").cloned().unwrap_or_else(|| "gantry-afp".into());
    let dialect_name = q.get("dialect").cloned().unwrap_or_else(|| REFERENCE_DIALECT.into());
    let machine = s.machine(&machine_name)?;
    let dialect = s.dialect(&dialect_name)?;
    if s.read().programs.get(&name).is_some_and(|p| p.source != Source::Upload) {
        return Err(ApiError::bad(format!("{name}: a built-in program or result has this name; choose another")));
    }
    let text = super::utf8(&name, &bytes)?;
    let (text, summary) = {
        let name = name.clone();
        tokio::task::spawn_blocking(move || -> ApiResult<(String, Value)> {
            let parsed = nc::parse_program(&name, &text, &machine, &dialect)?;
            if parsed.courses() == 0 {
                return Err(ApiError::in_file(
                    &name,
                    None,
                    "no course found: no roller contact (or tows on) under the dialect's codes",
                ));
            }
            let (info, _) = parsed.geometry(&machine, None);
            Ok((text, json!({"courses": info.courses.len(), "plies": info.plies.len(), "lines": info.lines})))
        })
        .await
        .map_err(|e| ApiError::Internal(e.to_string()))??
    };
    let meta = ProgramMeta {
        machine: machine_name,
        dialect: dialect_name,
        description: format!("uploaded: {} courses in {} plies", summary["courses"], summary["plies"]),
        original: None,
        order: None,
        job: None,
        tow_width: match q.get("tow_width") {
            Some(t) => Some(
                t.parse::<f64>()
                    .ok()
                    .filter(|w| w.is_finite() && *w > 0.0)
                    .ok_or_else(|| ApiError::bad(format!("tow_width {t:?}: a width in mm > 0")))?,
            ),
            None => None,
        },
        cell: Vec::new(),
    };
    let meta_bytes = serde_json::to_vec_pretty(&meta).map_err(|e| ApiError::Internal(e.to_string()))?;
    s.ws.write(Kind::Programs, &name, text.as_bytes())?;
    s.ws.write(Kind::Programs, &format!("{name}.meta.json"), &meta_bytes)?;
    s.add_program(&name, Source::Upload, meta, text);
    let listing = s.program(&name)?.listing();
    Ok((StatusCode::CREATED, Json(json!({ "listing": listing, "summary": summary }))))
}

/// What `POST /api/programs/{id}/check` takes: the cell's meshes and the clearance.
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CheckRequest {
    /// Mesh names (built-in or uploaded).
    molds: Vec<String>,
    /// Clearance, mm (default 5).
    #[serde(default)]
    clearance: Option<f64>,
}

/// `POST /api/programs/{id}/check`: the program's motion checked against the cell made of the
/// named meshes and the machine's travel limits (as `towpath verify --mold`): counts, the least
/// clearance and each collision, near miss and limit violation by line.
pub async fn check(
    State(s): State<Arc<AppState>>,
    Path(id): Path<String>,
    body: Result<Json<CheckRequest>, axum::extract::rejection::JsonRejection>,
) -> ApiResult<Json<Value>> {
    let Json(req) = body.map_err(|e| ApiError::bad(format!("request: {}", e.body_text())))?;
    if req.molds.is_empty() {
        return Err(ApiError::bad("molds: give at least one mesh of the cell"));
    }
    let p = s.program(&id)?;
    let machine = s.machine(&p.meta.machine)?;
    let dialect = s.dialect(&p.meta.dialect)?;
    let meshes = req.molds.iter().map(|m| Ok((m.clone(), s.mesh_bytes(m)?))).collect::<ApiResult<Vec<_>>>()?;
    let report = tokio::task::spawn_blocking(move || -> ApiResult<Value> {
        let safety = nc::cell(&machine, &dialect, &meshes, req.clearance)?;
        let r = nc::check_safety(&p.id, &p.text(), &machine, &dialect, &safety)?;
        Ok(nc::safety_json(&r))
    })
    .await
    .map_err(|e| ApiError::Internal(e.to_string()))??;
    Ok(Json(json!({ "program": id, "safety": report })))
}
