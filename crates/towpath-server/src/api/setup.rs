//! Set-up: server status, machines (TOML or the editor's JSON, with a live tool-point
//! preview), dialects and meshes. Everything saved goes to the workspace.

use std::collections::HashMap;
use std::sync::Arc;

use axum::body::Bytes;
use axum::extract::rejection::BytesRejection;
use axum::extract::{Path, Query, State};
use axum::http::{header, HeaderMap, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::Json;
use serde::Deserialize;
use serde_json::{json, Value};

use crate::adapt::{layup, machine as am};
use crate::error::{ApiError, ApiResult};
use crate::names;
use crate::state::{AppState, DialectEntry, MachineEntry};
use crate::workspace::Kind;

pub async fn status(State(s): State<Arc<AppState>>) -> Json<Value> {
    let c = &s.config;
    Json(json!({
        "name": "towpath",
        "version": env!("CARGO_PKG_VERSION"),
        "workspace": s.ws.root().display().to_string(),
        "load_problems": s.read().load_problems,
        "limits": {
            "max_upload_bytes": c.max_upload,
            "max_jobs": c.max_jobs,
            "max_queue": c.max_queue,
            "max_time_limit": c.max_time_limit,
            "job_wall_limit": c.job_wall_limit,
        },
        "panel": crate::state::PANEL_ID,
        "panel_ready": s.read().programs.get(crate::state::PANEL_ID).is_some_and(|p| p.geometry.get().is_some()),
    }))
}

pub async fn machines(State(s): State<Arc<AppState>>) -> Json<Value> {
    let list: Vec<Value> = s
        .read()
        .machines
        .iter()
        .map(|(n, m)| json!({"name": n, "builtin": m.builtin, "axes": m.machine.axes.iter().map(|a| a.label.clone()).collect::<Vec<_>>()}))
        .collect();
    Json(json!({ "machines": list }))
}

pub async fn machine(State(s): State<Arc<AppState>>, Path(name): Path<String>) -> ApiResult<Json<Value>> {
    names::check("machine", &name)?;
    let st = s.read();
    let m = st.machines.get(&name).ok_or_else(|| ApiError::NotFound(format!("no machine {name:?}")))?;
    Ok(Json(json!({
        "name": name,
        "builtin": m.builtin,
        "machine": m.machine,
        "toml": am::machine_toml(&m.machine),
    })))
}

/// `PUT /api/machines/NAME`: a machine file (TOML) or, with a JSON content type, the editor's
/// machine; checked, then kept as `machines/NAME.toml`.
pub async fn save_machine(
    State(s): State<Arc<AppState>>,
    Path(name): Path<String>,
    headers: HeaderMap,
    body: Result<Bytes, BytesRejection>,
) -> ApiResult<Json<Value>> {
    names::check("machine", &name)?;
    let bytes = super::upload(&s, body)?;
    if s.read().machines.get(&name).is_some_and(|m| m.builtin) {
        return Err(ApiError::bad(format!("{name} is a built-in machine: save your changes under another name")));
    }
    let file = format!("{name}.toml");
    let is_json = headers
        .get(axum::http::header::CONTENT_TYPE)
        .and_then(|v| v.to_str().ok())
        .is_some_and(|v| v.starts_with("application/json"));
    let (machine, toml) = if is_json {
        let v: Value = serde_json::from_slice(&bytes).map_err(|e| ApiError::bad(format!("machine: {e}")))?;
        am::machine_from_json(v)?
    } else {
        let text = super::utf8(&file, &bytes)?;
        let m = am::parse_machine(&file, &text)?;
        (m, text)
    };
    s.ws.write(Kind::Machines, &file, toml.as_bytes())?;
    s.write().machines.insert(name.clone(), MachineEntry { machine: machine.clone(), builtin: false });
    Ok(Json(json!({"name": name, "machine": machine, "toml": toml})))
}

pub async fn delete_machine(State(s): State<Arc<AppState>>, Path(name): Path<String>) -> ApiResult<StatusCode> {
    names::check("machine", &name)?;
    if s.read().machines.get(&name).is_none_or(|m| m.builtin) {
        return Err(ApiError::bad(format!("{name}: no saved machine of that name (built-in machines stay)")));
    }
    s.ws.remove(Kind::Machines, &format!("{name}.toml"))?;
    s.write().machines.remove(&name);
    Ok(StatusCode::NO_CONTENT)
}

#[derive(Deserialize)]
pub struct Preview {
    machine: Value,
    #[serde(default)]
    values: Vec<f64>,
}

/// `POST /api/machine-preview`: checks the editor's machine, returns its TOML and the tool
/// point for the given axis values.
pub async fn preview(Json(p): Json<Preview>) -> ApiResult<Json<Value>> {
    let (m, toml) = am::machine_from_json(p.machine)?;
    let values = if p.values.is_empty() { m.home() } else { p.values };
    let tp = am::tool_point(&m, &values)?;
    Ok(Json(json!({"toml": toml, "tool_point": tp, "values": values})))
}

pub async fn dialects(State(s): State<Arc<AppState>>) -> Json<Value> {
    let list: Vec<Value> = s.read().dialects.iter().map(|(n, d)| json!({"name": n, "builtin": d.builtin})).collect();
    Json(json!({ "dialects": list }))
}

pub async fn dialect(State(s): State<Arc<AppState>>, Path(name): Path<String>) -> ApiResult<Json<Value>> {
    names::check("dialect", &name)?;
    let st = s.read();
    let d = st.dialects.get(&name).ok_or_else(|| ApiError::NotFound(format!("no dialect {name:?}")))?;
    Ok(Json(json!({"name": name, "builtin": d.builtin, "toml": d.text})))
}

pub async fn save_dialect(
    State(s): State<Arc<AppState>>,
    Path(name): Path<String>,
    body: Result<Bytes, BytesRejection>,
) -> ApiResult<Json<Value>> {
    names::check("dialect", &name)?;
    let bytes = super::upload(&s, body)?;
    if s.read().dialects.get(&name).is_some_and(|d| d.builtin) {
        return Err(ApiError::bad(format!("{name} is the built-in dialect: save yours under another name")));
    }
    let file = format!("{name}.toml");
    let text = super::utf8(&file, &bytes)?;
    let dialect = am::parse_dialect(&file, &text)?;
    s.ws.write(Kind::Dialects, &file, text.as_bytes())?;
    s.write().dialects.insert(name.clone(), DialectEntry { dialect, text, builtin: false });
    Ok(Json(json!({"name": name})))
}

pub async fn meshes(State(s): State<Arc<AppState>>) -> Json<Value> {
    let builtin: Vec<String> = s.read().builtin_meshes.keys().cloned().collect();
    Json(json!({ "meshes": s.mesh_names(), "builtin": builtin }))
}

/// `POST /api/meshes?name=N.stl`: read as a mesh before it is kept.
pub async fn upload_mesh(
    State(s): State<Arc<AppState>>,
    Query(q): Query<HashMap<String, String>>,
    body: Result<Bytes, BytesRejection>,
) -> ApiResult<(StatusCode, Json<Value>)> {
    let bytes = super::upload(&s, body)?;
    let name = q.get("name").cloned().ok_or_else(|| ApiError::bad("name: give the mesh's file name"))?;
    names::check("mesh", &name)?;
    if s.read().builtin_meshes.contains_key(&name) {
        return Err(ApiError::bad(format!("{name}: a built-in mesh has this name; choose another")));
    }
    let n = name.clone();
    let b = bytes.clone();
    let faces = tokio::task::spawn_blocking(move || layup::read_mesh(&n, &b).map(|m| m.num_faces()))
        .await
        .map_err(|e| ApiError::Internal(e.to_string()))??;
    s.ws.write(Kind::Meshes, &name, &bytes)?;
    let mut st = s.write();
    if !st.meshes.contains(&name) {
        st.meshes.push(name.clone());
        st.meshes.sort();
    }
    Ok((StatusCode::CREATED, Json(json!({"name": name, "triangles": faces}))))
}

/// `GET /api/meshes/{name}/geometry`: a mesh's vertices and triangles as typed arrays (the
/// program view draws a cell's meshes with it).
pub async fn mesh_geometry(State(s): State<Arc<AppState>>, Path(name): Path<String>) -> ApiResult<Response> {
    let bytes = s.mesh_bytes(&name)?;
    let blob =
        tokio::task::spawn_blocking(move || layup::read_mesh(&name, &bytes).map(|m| layup::mesh_blob(&m).encode()))
            .await
            .map_err(|e| ApiError::Internal(e.to_string()))??;
    Ok(([(header::CONTENT_TYPE, "application/octet-stream")], blob).into_response())
}
