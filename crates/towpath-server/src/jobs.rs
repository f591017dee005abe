//! Background jobs: a queue with a bounded number running at once, cancel, a wall-time limit,
//! live progress for server-sent events, and results kept in the workspace.
//!
//! A job's work runs on a blocking thread that holds one of `max_jobs` permits until the work
//! really ends and its result is stored, so a cancelled or timed-out job whose library call
//! cannot be interrupted still counts against the bound until it returns. Cancel and the wall limit end the job's state at
//! once; whatever the work returns afterwards is dropped.

use std::collections::BTreeMap;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

use serde::{Deserialize, Serialize};
use tokio::sync::{watch, Semaphore};

use crate::adapt::nc::{SolveProgress, Stopped};
use crate::error::ApiError;
use crate::state::{AppState, Config, ProgramMeta, Source};
use crate::workspace::{write_atomic, Kind};

/// Where a job is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum JobState {
    /// Waiting for a free slot.
    Queued,
    /// Working.
    Running,
    /// Finished with a result.
    Done,
    /// Refused or failed; `error` says why.
    Failed,
    /// Cancelled by the user.
    Cancelled,
}

impl JobState {
    /// The job will not change any more.
    pub fn is_final(self) -> bool {
        matches!(self, JobState::Done | JobState::Failed | JobState::Cancelled)
    }
}

/// What the page sees of a job (also kept as `job.json` in its result folder).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct JobView {
    /// `job-N`.
    pub id: String,
    /// `optimize` or `layup`.
    pub kind: String,
    /// The program or surface it works on.
    pub target: String,
    /// State.
    pub state: JobState,
    /// What it is doing.
    pub phase: String,
    /// Created, seconds since 1970.
    pub created: u64,
    /// Seconds since it started running.
    pub elapsed: f64,
    /// Fraction of the solver's budget used.
    pub fraction: f64,
    /// Solver cost of the original order.
    pub initial_cost: Option<f64>,
    /// Best solver cost so far.
    pub best_cost: Option<f64>,
    /// Saving of the best so far against the original, %.
    pub saved_percent: Option<f64>,
    /// Solver kicks so far.
    pub iterations: u64,
    /// Courses traced so far (layup).
    pub count: u64,
    /// Why it failed.
    pub error: Option<String>,
    /// The result's figures and file names.
    pub result: Option<serde_json::Value>,
    /// The request as given.
    pub request: serde_json::Value,
}

/// One job.
pub struct Job {
    view: Mutex<JobView>,
    started: Mutex<Option<Instant>>,
    cancel: Arc<AtomicBool>,
    tick: watch::Sender<u64>,
}

impl Job {
    fn lock(&self) -> std::sync::MutexGuard<'_, JobView> {
        self.view.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The job as it is now (elapsed time counted to this instant while it runs).
    pub fn snapshot(&self) -> JobView {
        let mut v = self.lock().clone();
        if v.state == JobState::Running {
            if let Some(t) = *self.started.lock().unwrap_or_else(|e| e.into_inner()) {
                v.elapsed = t.elapsed().as_secs_f64();
            }
        }
        v
    }

    /// A receiver that wakes when the job changes.
    pub fn subscribe(&self) -> watch::Receiver<u64> {
        self.tick.subscribe()
    }

    fn update(&self, f: impl FnOnce(&mut JobView)) {
        {
            let mut v = self.lock();
            if v.state.is_final() {
                return;
            }
            f(&mut v);
        }
        self.tick.send_modify(|n| *n += 1);
    }

    fn elapsed_now(&self) -> f64 {
        self.started.lock().unwrap_or_else(|e| e.into_inner()).map_or(0.0, |t| t.elapsed().as_secs_f64())
    }
}

/// What a job's work gets: the cancel flag and ways to report progress.
#[derive(Clone)]
pub struct JobCtx {
    job: Arc<Job>,
}

impl JobCtx {
    /// The cancel flag (also set when the wall limit passes).
    pub fn cancel_flag(&self) -> Arc<AtomicBool> {
        self.job.cancel.clone()
    }

    /// The job's id.
    pub fn id(&self) -> String {
        self.job.lock().id.clone()
    }

    /// Sets the phase.
    pub fn phase(&self, p: &str) {
        self.job.update(|v| v.phase = p.to_string());
    }

    /// Reports solver progress.
    pub fn progress(&self, p: &SolveProgress) {
        self.job.update(|v| {
            v.initial_cost = p.initial_cost;
            v.best_cost = p.best_cost;
            v.iterations = p.iterations;
            v.fraction = p.fraction;
            v.saved_percent = match (p.initial_cost, p.best_cost) {
                (Some(i), Some(b)) if i > 0.0 => Some(100.0 * (i - b) / i),
                _ => None,
            };
        });
    }

    /// Reports a count (courses traced).
    pub fn count(&self, n: u64) {
        self.job.update(|v| v.count = n);
    }
}

/// What finished work hands back.
pub struct JobOutput {
    /// Figures for the page.
    pub result: serde_json::Value,
    /// Files for the result folder and downloads.
    pub files: Vec<(String, Vec<u8>)>,
    /// A program to register (id, meta, text).
    pub program: Option<(String, ProgramMeta, String)>,
}

/// The work of a job.
pub type Work = Box<dyn FnOnce(&JobCtx) -> Result<JobOutput, Stopped> + Send>;

/// All jobs.
pub struct Jobs {
    map: Mutex<BTreeMap<u64, Arc<Job>>>,
    next: AtomicU64,
    slots: Arc<Semaphore>,
    waiting: Arc<AtomicUsize>,
    max_queue: usize,
    wall: Duration,
}

fn now_unix() -> u64 {
    SystemTime::now().duration_since(UNIX_EPOCH).map_or(0, |d| d.as_secs())
}

fn number(id: &str) -> Option<u64> {
    id.strip_prefix("job-")?.parse().ok()
}

impl Jobs {
    /// No jobs yet.
    pub fn new(config: &Config) -> Jobs {
        Jobs {
            map: Mutex::new(BTreeMap::new()),
            next: AtomicU64::new(1),
            slots: Arc::new(Semaphore::new(config.max_jobs.max(1))),
            waiting: Arc::new(AtomicUsize::new(0)),
            max_queue: config.max_queue,
            wall: Duration::from_secs_f64(config.job_wall_limit.max(1.0)),
        }
    }

    fn map(&self) -> std::sync::MutexGuard<'_, BTreeMap<u64, Arc<Job>>> {
        self.map.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Every job, newest first.
    pub fn list(&self) -> Vec<JobView> {
        self.map().values().rev().map(|j| j.snapshot()).collect()
    }

    /// A job by id.
    pub fn get(&self, id: &str) -> Result<Arc<Job>, ApiError> {
        number(id).and_then(|n| self.map().get(&n).cloned()).ok_or_else(|| ApiError::NotFound(format!("no job {id:?}")))
    }

    /// Reloads the jobs kept in the workspace; a job the last server left unfinished is marked
    /// failed.
    pub fn restore(&self, state: &AppState) {
        let mut max = 0;
        for dir in state.ws.list(Kind::Results) {
            let Some(n) = number(&dir) else { continue };
            let path = state.ws.root().join("results").join(&dir).join("job.json");
            let Some(mut view) = std::fs::read(&path).ok().and_then(|b| serde_json::from_slice::<JobView>(&b).ok())
            else {
                continue;
            };
            if !view.state.is_final() {
                view.state = JobState::Failed;
                view.error = Some("interrupted: the server stopped while the job ran".into());
            }
            max = max.max(n);
            let (tick, _) = watch::channel(0);
            let job = Job {
                view: Mutex::new(view),
                started: Mutex::new(None),
                cancel: Arc::new(AtomicBool::new(false)),
                tick,
            };
            self.map().insert(n, Arc::new(job));
        }
        self.next.store(max + 1, Ordering::SeqCst);
    }

    /// Queues a job. Refused with 429 when the queue is full.
    pub fn submit(
        state: &Arc<AppState>,
        kind: &str,
        target: &str,
        request: serde_json::Value,
        work: Work,
    ) -> Result<JobView, ApiError> {
        let jobs = &state.jobs;
        let waiting = jobs.waiting.fetch_add(1, Ordering::SeqCst);
        if waiting >= jobs.max_queue {
            jobs.waiting.fetch_sub(1, Ordering::SeqCst);
            return Err(ApiError::Busy(format!(
                "{waiting} jobs are already waiting (at most {}): wait for one to finish or cancel one",
                jobs.max_queue
            )));
        }
        let n = jobs.next.fetch_add(1, Ordering::SeqCst);
        let view = JobView {
            id: format!("job-{n}"),
            kind: kind.into(),
            target: target.into(),
            state: JobState::Queued,
            phase: "waiting for a free slot".into(),
            created: now_unix(),
            elapsed: 0.0,
            fraction: 0.0,
            initial_cost: None,
            best_cost: None,
            saved_percent: None,
            iterations: 0,
            count: 0,
            error: None,
            result: None,
            request,
        };
        let (tick, _) = watch::channel(0);
        let job = Arc::new(Job {
            view: Mutex::new(view.clone()),
            started: Mutex::new(None),
            cancel: Arc::new(AtomicBool::new(false)),
            tick,
        });
        jobs.map().insert(n, job.clone());
        let st = state.clone();
        tokio::spawn(async move { run(st, job, work).await });
        Ok(view)
    }

    /// Cancels a job: its state ends at once, and its work is asked to stop.
    pub fn cancel(&self, state: &AppState, id: &str) -> Result<JobView, ApiError> {
        let job = self.get(id)?;
        job.cancel.store(true, Ordering::SeqCst);
        let elapsed = job.elapsed_now();
        finish(state, &job, |v| {
            v.state = JobState::Cancelled;
            v.phase = "cancelled".into();
            v.elapsed = elapsed;
        });
        Ok(job.snapshot())
    }
}

/// Ends a job's state (once) and keeps its view in the workspace.
fn finish(state: &AppState, job: &Job, f: impl FnOnce(&mut JobView)) {
    let view = {
        let mut v = job.lock();
        if v.state.is_final() {
            return;
        }
        f(&mut v);
        v.clone()
    };
    job.tick.send_modify(|n| *n += 1);
    if let Ok(dir) = state.ws.job_dir(&view.id) {
        if let Ok(bytes) = serde_json::to_vec_pretty(&view) {
            let _ = write_atomic(&dir.join("job.json"), &bytes);
        }
    }
}

async fn run(state: Arc<AppState>, job: Arc<Job>, work: Work) {
    let permit = state.jobs.slots.clone().acquire_owned().await;
    state.jobs.waiting.fetch_sub(1, Ordering::SeqCst);
    let Ok(permit) = permit else { return };
    if job.cancel.load(Ordering::SeqCst) {
        return;
    }
    *job.started.lock().unwrap_or_else(|e| e.into_inner()) = Some(Instant::now());
    job.update(|v| {
        v.state = JobState::Running;
        v.phase = "starting".into();
    });
    let ctx = JobCtx { job: job.clone() };
    // The work hands its permit back with its result, so that the slot stays taken until the
    // result is stored and the job is done (else the next job shows as running beside it). A
    // job past the wall limit is let go, and its permit is dropped only when its work returns.
    let handle = tokio::task::spawn_blocking(move || {
        let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| work(&ctx)));
        (result, permit)
    });
    let (outcome, _permit) = match tokio::time::timeout(state.jobs.wall, handle).await {
        Ok(Ok((result, permit))) => (Ok(Ok(result)), Some(permit)),
        Ok(Err(e)) => (Ok(Err(e)), None),
        Err(e) => (Err(e), None),
    };
    let elapsed = job.elapsed_now();
    match outcome {
        Err(_) => {
            job.cancel.store(true, Ordering::SeqCst);
            let limit = state.config.job_wall_limit;
            finish(&state, &job, |v| {
                v.state = JobState::Failed;
                v.elapsed = elapsed;
                v.error = Some(format!("stopped: the job ran past the server's limit of {limit} s"));
            });
        }
        Ok(Err(e)) => fail(&state, &job, elapsed, format!("internal error: {e}")),
        Ok(Ok(Err(_))) => fail(&state, &job, elapsed, "internal error: the job panicked".into()),
        Ok(Ok(Ok(Err(Stopped::Cancelled)))) => finish(&state, &job, |v| {
            v.state = JobState::Cancelled;
            v.phase = "cancelled".into();
            v.elapsed = elapsed;
        }),
        Ok(Ok(Ok(Err(Stopped::Failed(e))))) => {
            let msg = match &e {
                ApiError::BadInput { file: Some(f), line: Some(l), .. } => format!("{f}: line {l}: {e}"),
                ApiError::BadInput { file: Some(f), .. } => format!("{f}: {e}"),
                _ => e.to_string(),
            };
            fail(&state, &job, elapsed, msg)
        }
        Ok(Ok(Ok(Ok(out)))) => store_output(&state, &job, elapsed, out),
    }
}

fn fail(state: &AppState, job: &Job, elapsed: f64, msg: String) {
    finish(state, job, |v| {
        v.state = JobState::Failed;
        v.phase = "failed".into();
        v.elapsed = elapsed;
        v.error = Some(msg);
    });
}

fn store_output(state: &AppState, job: &Job, elapsed: f64, out: JobOutput) {
    if job.lock().state.is_final() {
        return;
    }
    let id = job.lock().id.clone();
    let saved = (|| -> Result<(), ApiError> {
        let dir = state.ws.job_dir(&id)?;
        for (name, bytes) in &out.files {
            crate::names::check("file", name)?;
            write_atomic(&dir.join(name), bytes)?;
        }
        if let Some((pid, meta, text)) = &out.program {
            state.ws.write(Kind::Programs, pid, text.as_bytes())?;
            let m = serde_json::to_vec_pretty(meta).map_err(|e| ApiError::Internal(e.to_string()))?;
            state.ws.write(Kind::Programs, &format!("{pid}.meta.json"), &m)?;
        }
        Ok(())
    })();
    if let Err(e) = saved {
        return fail(state, job, elapsed, format!("the results could not be saved: {e}"));
    }
    if let Some((pid, meta, text)) = out.program {
        state.add_program(&pid, Source::Result, meta, text);
    }
    let files: Vec<String> = out.files.iter().map(|f| f.0.clone()).collect();
    let mut result = out.result;
    if let Some(o) = result.as_object_mut() {
        o.insert("files".into(), serde_json::json!(files));
    }
    finish(state, job, |v| {
        v.state = JobState::Done;
        v.phase = "done".into();
        v.elapsed = elapsed;
        v.fraction = 1.0;
        v.result = Some(result);
    });
}
