//! The one clock of a run: when it started, when it must stop (a time limit) and whether it was
//! cancelled. towpath's solver, the seed papers' solvers and the instance builders that precede
//! a solve (shortest paths of a travel graph, for instance) all ask the same [`Clock`], so a
//! command's time limit covers everything it does.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use crate::search::SolveOptions;

/// Wall time since a run started, its deadline (if it has a time limit) and its cancel flag
/// (if it has one).
#[derive(Clone, Debug)]
pub struct Clock {
    t0: Instant,
    deadline: Option<Instant>,
    cancel: Option<Arc<AtomicBool>>,
}

impl Clock {
    /// Starts a clock now, with an optional time limit and cancel flag. A time limit too large
    /// to be added to the current instant is no limit.
    pub fn start(time_limit: Option<Duration>, cancel: Option<Arc<AtomicBool>>) -> Self {
        let t0 = Instant::now();
        Clock { t0, deadline: time_limit.and_then(|d| t0.checked_add(d)), cancel }
    }

    /// A clock that never expires.
    pub fn unlimited() -> Self {
        Clock::start(None, None)
    }

    /// Starts the clock of a solve: the options' time limit and cancel flag.
    pub fn for_options(opts: &SolveOptions) -> Self {
        Clock::start(opts.time_limit, opts.cancel.clone())
    }

    /// When the clock started.
    pub fn started(&self) -> Instant {
        self.t0
    }

    /// Time since the clock started.
    pub fn elapsed(&self) -> Duration {
        self.t0.elapsed()
    }

    /// The deadline, if there is a time limit.
    pub fn deadline(&self) -> Option<Instant> {
        self.deadline
    }

    /// The time limit the clock was started with, if any.
    pub fn time_limit(&self) -> Option<Duration> {
        self.deadline.map(|d| d - self.t0)
    }

    /// Time left before the deadline (zero once it has passed); `None` without a time limit.
    pub fn remaining(&self) -> Option<Duration> {
        self.deadline.map(|d| d.saturating_duration_since(Instant::now()))
    }

    /// The cancel flag, if the run has one.
    pub fn cancel_flag(&self) -> Option<&Arc<AtomicBool>> {
        self.cancel.as_ref()
    }

    /// True once the run was cancelled.
    pub fn cancelled(&self) -> bool {
        self.cancel.as_ref().is_some_and(|c| c.load(Ordering::Relaxed))
    }

    /// True once the deadline has passed.
    pub fn past_deadline(&self) -> bool {
        self.deadline.is_some_and(|d| Instant::now() >= d)
    }

    /// True once the deadline has passed or the run was cancelled.
    pub fn expired(&self) -> bool {
        self.past_deadline() || self.cancelled()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn expires_at_the_deadline_or_when_cancelled() {
        let c = Clock::start(Some(Duration::ZERO), None);
        assert!(c.expired() && c.past_deadline() && !c.cancelled());
        assert_eq!(c.remaining(), Some(Duration::ZERO));
        let flag = Arc::new(AtomicBool::new(false));
        let c = Clock::start(Some(Duration::from_secs(3600)), Some(flag.clone()));
        assert!(!c.expired());
        assert!(c.remaining().is_some_and(|r| r > Duration::from_secs(3500)));
        assert_eq!(c.time_limit(), Some(Duration::from_secs(3600)));
        flag.store(true, Ordering::Relaxed);
        assert!(c.expired() && c.cancelled() && !c.past_deadline());
        let u = Clock::unlimited();
        assert!(!u.expired() && u.remaining().is_none() && u.deadline().is_none());
        // a limit beyond what an instant can hold is no limit
        assert!(Clock::start(Some(Duration::MAX), None).deadline().is_none());
    }
}
