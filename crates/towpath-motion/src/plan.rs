//! The transit planner: from a course's exit state to the next course's entry state, straight
//! when that keeps the clearance, else up, across and down at the least level that does.

use serde::{Deserialize, Serialize};
use towpath_geom::DVec3;
use towpath_machine::{AxisKind, MachineCost};

use crate::check::{Checker, Contact};
use crate::error::PlanError;

/// How the planner lifts the tool when a straight transit is not clear.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LiftRule {
    /// Radially on a mandrel machine without a DH chain, along the tool axis (the Z axis) on
    /// other machines without one; a machine with a DH chain has no automatic lift.
    #[default]
    Auto,
    /// Along the tool axis: the Z axis of a machine whose X/Y/Z axes are the tool point.
    ToolAxis,
    /// Along this linear axis (by index), in the direction that takes the tool away from the
    /// part: a clearance axis.
    Axis(usize),
    /// Away from the mandrel's axis (a machine whose X/Y/Z axes are the tool point).
    Radial,
}

/// Options of the planner.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PlanOptions {
    /// How to lift.
    pub lift: LiftRule,
    /// The level of a lifted transit is the least that clears, to within this step (mm of the
    /// lift axis, or of radius; default 1).
    pub step: f64,
}

impl Default for PlanOptions {
    fn default() -> Self {
        PlanOptions { lift: LiftRule::Auto, step: 1.0 }
    }
}

/// A planned transit.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Transit {
    /// The states the moves go to, in order, after the start: the last is the target. One
    /// state for a straight transit; up to three (up, across, down) for a lifted one.
    pub waypoints: Vec<Vec<f64>>,
    /// The level of the across move of a lifted transit (the lift axis's value in the lifting
    /// direction, or the radius about the mandrel axis); `None` for a straight one.
    pub level: Option<f64>,
}

/// How lifting is done, resolved for the machine.
#[derive(Clone, Copy, Debug)]
enum Lift {
    /// No way to lift.
    None(&'static str),
    /// Set this linear axis; the level is `sign · value`.
    Axis { axis: usize, sign: f64 },
    /// Move the tool point away from the mandrel axis with the X/Y/Z axes.
    Radial,
}

/// Plans transits of one machine in one cell; see the crate documentation for the rule.
#[derive(Clone, Debug)]
pub struct Planner {
    checker: Checker,
    lift: Lift,
    step: f64,
}

/// Lexicographic order of two states by total order of their values.
fn state_cmp(a: &[f64], b: &[f64]) -> std::cmp::Ordering {
    for (x, y) in a.iter().zip(b) {
        match x.total_cmp(y) {
            std::cmp::Ordering::Equal => continue,
            o => return o,
        }
    }
    a.len().cmp(&b.len())
}

impl Planner {
    /// A planner; refuses a lift the machine cannot make.
    pub fn new(checker: Checker, opts: PlanOptions) -> Result<Planner, PlanError> {
        let rig = checker.rig();
        let m = rig.machine();
        let xyz = rig.xyz_axes();
        let lift = match opts.lift {
            LiftRule::Auto if rig.has_chain() => {
                Lift::None("a machine with a DH chain lifts only along a linear clearance axis, and none is set")
            }
            LiftRule::Auto if rig.mandrel().is_some() => Lift::Radial,
            LiftRule::Auto | LiftRule::ToolAxis => match xyz[2] {
                Some(axis) if !rig.has_chain() => Lift::Axis { axis, sign: 1.0 },
                _ if opts.lift == LiftRule::Auto => Lift::None("the machine has no Z axis to lift along"),
                _ => return Err(PlanError::NoLift(
                    "lifting along the tool axis needs a machine whose X/Y/Z axes are the tool point, with a Z axis"
                        .into(),
                )),
            },
            LiftRule::Radial => {
                if rig.mandrel().is_none() || rig.has_chain() {
                    return Err(PlanError::NoLift(
                        "lifting radially needs a mandrel and a machine whose X/Y/Z axes are the tool point".into(),
                    ));
                }
                Lift::Radial
            }
            LiftRule::Axis(axis) => {
                let Some(a) = m.axes.get(axis) else {
                    return Err(PlanError::NoLift(format!("the machine has no axis {axis}")));
                };
                if a.kind != AxisKind::Linear {
                    return Err(PlanError::NoLift(format!("axis {} is not a linear axis", a.label)));
                }
                // Which way takes the tool away from the part: try a step at the home state.
                let home = m.home();
                let mut up = home.clone();
                up[axis] += 1.0;
                let (p0, p1) = (rig.pose(&home), rig.pose(&up));
                let along = (p1.tool - p0.tool).dot(-p0.axis);
                let moved = (p1.tool - p0.tool).length();
                if !(moved > 0.0 && along.abs() >= 0.5 * moved) {
                    return Err(PlanError::NoLift(format!(
                        "axis {} does not move the tool along the tool axis, away from the part",
                        a.label
                    )));
                }
                Lift::Axis { axis, sign: along.signum() }
            }
        };
        let step = if opts.step.is_finite() && opts.step > 0.0 { opts.step } else { 1.0 };
        Ok(Planner { checker, lift, step })
    }

    /// The checker.
    pub fn checker(&self) -> &Checker {
        &self.checker
    }

    /// The level of a state: its lift axis value (signed), or its radius about the mandrel.
    fn level(&self, s: &[f64]) -> f64 {
        match self.lift {
            Lift::None(_) => 0.0,
            Lift::Axis { axis, sign } => sign * s[axis],
            Lift::Radial => {
                let (v, k) = self.radial(s);
                (v - k * v.dot(k)).length()
            }
        }
    }

    /// The machine point relative to the mandrel origin, and the mandrel direction.
    fn radial(&self, s: &[f64]) -> (DVec3, DVec3) {
        let rig = self.checker.rig();
        let w = rig.kinematics().world_point(s);
        let (o, k) = rig.mandrel().map_or((DVec3::ZERO, DVec3::X), |(_, o, k)| (o, k));
        (DVec3::new(w[0], w[1], w[2]) - o, k)
    }

    /// The state `s` lifted to `level` (only the lift axes change), or why it cannot be.
    fn lifted(&self, s: &[f64], level: f64) -> Result<Vec<f64>, PlanError> {
        let mut out = s.to_vec();
        match self.lift {
            Lift::None(why) => return Err(PlanError::NoLift(why.into())),
            Lift::Axis { axis, sign } => out[axis] = sign * level,
            Lift::Radial => {
                let (v, k) = self.radial(s);
                let perp = v - k * v.dot(k);
                let r = perp.length();
                if !(r > 1e-9) {
                    return Err(PlanError::NoLift(
                        "the tool point is on the mandrel axis, which has no radial direction".into(),
                    ));
                }
                let shift = perp * ((level - r) / r);
                let xyz = self.checker.rig().xyz_axes();
                for (c, d) in [shift.x, shift.y, shift.z].into_iter().enumerate() {
                    match xyz[c] {
                        Some(i) => out[i] += d,
                        None if d.abs() > 1e-9 => {
                            return Err(PlanError::NoLift(format!(
                                "lifting radially here needs a {} axis, which the machine lacks",
                                ["X", "Y", "Z"][c]
                            )))
                        }
                        None => {}
                    }
                }
            }
        }
        Ok(out)
    }

    /// True when `s` is within the travel limits.
    fn within_limits(&self, s: &[f64]) -> bool {
        self.checker.rig().check_limits(s, 1e-9).is_ok()
    }

    /// Plans the transit from `from` to `to`. Both must be within the travel limits. The plan
    /// does not depend on the direction: planning `to → from` gives the same moves backwards.
    pub fn plan(&self, from: &[f64], to: &[f64]) -> Result<Transit, PlanError> {
        if state_cmp(from, to) == std::cmp::Ordering::Greater {
            // Planned from `to` to `from`, then run backwards: the intermediate states in the
            // opposite order, ending at `to`.
            let (mut pts, level) = self.plan_ordered(to, from)?;
            pts.pop();
            pts.reverse();
            pts.push(to.to_vec());
            return Ok(Transit { waypoints: pts, level });
        }
        let (pts, level) = self.plan_ordered(from, to)?;
        Ok(Transit { waypoints: pts, level })
    }

    /// The cost of the planned transit under `cost` (each move priced as a direct move), the
    /// same in both directions.
    pub fn price(&self, cost: &MachineCost, from: &[f64], to: &[f64]) -> Result<f64, PlanError> {
        let (a, b) = if state_cmp(from, to) == std::cmp::Ordering::Greater { (to, from) } else { (from, to) };
        let (pts, _) = self.plan_ordered(a, b)?;
        let mut total = 0.0;
        let mut prev = a;
        for p in &pts {
            total += cost.direct(prev, p);
            prev = p;
        }
        Ok(total)
    }

    /// Plans from `a` to `b` (in canonical order): the waypoints after `a` and the level.
    fn plan_ordered(&self, a: &[f64], b: &[f64]) -> Result<(Vec<Vec<f64>>, Option<f64>), PlanError> {
        let rig = self.checker.rig();
        rig.check_limits(a, 1e-9)?;
        rig.check_limits(b, 1e-9)?;
        let c = self.checker.options().clearance;
        // An end that is itself closer than the clearance (a short retract) gets a contact
        // zone on the move that leaves or reaches it.
        let za = self.checker.state_clearance(a) < c;
        let zb = self.checker.state_clearance(b) < c;
        let contact = |start: bool, end: bool| match (start, end) {
            (true, _) => Contact::Start,
            (false, true) => Contact::End,
            _ => Contact::None,
        };
        let straight_ok = if za && zb {
            // Both ends close: the first and second halves each get their end's zone.
            let mut mid = Vec::new();
            rig.at(a, &rig.deltas(a, b), 0.5, &mut mid);
            self.checker.is_clear(a, &mid, Contact::Start) && self.checker.is_clear(&mid, b, Contact::End)
        } else {
            self.checker.is_clear(a, b, contact(za, zb))
        };
        if straight_ok {
            return Ok((vec![b.to_vec()], None));
        }
        if let Lift::None(why) = self.lift {
            return Err(PlanError::NoSafeTransit(format!("the straight move is not clear and {why}")));
        }
        let try_level = |h: f64| -> Result<Option<Vec<Vec<f64>>>, PlanError> {
            let (u, v) = (self.lifted(a, h)?, self.lifted(b, h)?);
            if !self.within_limits(&u) || !self.within_limits(&v) {
                return Ok(None);
            }
            let up = same(a, &u) || self.checker.is_clear(a, &u, contact(za, false));
            let ok = up
                && self.checker.is_clear(&u, &v, Contact::None)
                && (same(&v, b) || self.checker.is_clear(&v, b, contact(false, zb)));
            Ok(ok.then(|| {
                let mut pts = Vec::with_capacity(3);
                for p in [u, v] {
                    if !same(pts.last().map_or(a, |q: &Vec<f64>| q.as_slice()), &p) {
                        pts.push(p);
                    }
                }
                pts.push(b.to_vec());
                pts
            }))
        };
        let lo = self.level(a).max(self.level(b));
        // Grow the lift until it clears (or leaves the travel limits), then bisect down to the
        // least clear level within the step.
        let mut below = lo;
        let mut found = None;
        if let Some(p) = try_level(lo)? {
            return Ok((p, Some(lo)));
        }
        let mut k = 0;
        let mut lifted = self.step;
        while k < 40 {
            let h = lo + lifted;
            let (u, v) = (self.lifted(a, h)?, self.lifted(b, h)?);
            if !self.within_limits(&u) || !self.within_limits(&v) {
                // Try the highest level the limits allow before giving up.
                let top = self.top_level(a, b, h)?;
                if top > below {
                    if let Some(p) = try_level(top)? {
                        found = Some((top, p));
                    }
                }
                break;
            }
            if let Some(p) = try_level(h)? {
                found = Some((h, p));
                break;
            }
            below = h;
            lifted *= 2.0;
            k += 1;
        }
        let Some((mut above, mut best)) = found else {
            return Err(PlanError::NoSafeTransit(format!(
                "the straight move is not clear, and lifting up to {:.3} (within the travel limits) does not clear it",
                below
            )));
        };
        while above - below > self.step {
            let h = 0.5 * (above + below);
            match try_level(h)? {
                Some(p) => {
                    above = h;
                    best = p;
                }
                None => below = h,
            }
        }
        Ok((best, Some(above)))
    }

    /// The highest level in [.., `h`] at which both lifted states are within the travel limits,
    /// found by bisection between the start levels and `h`.
    fn top_level(&self, a: &[f64], b: &[f64], h: f64) -> Result<f64, PlanError> {
        let mut lo = self.level(a).max(self.level(b));
        let mut hi = h;
        for _ in 0..60 {
            if hi - lo <= 1e-6 {
                break;
            }
            let m = 0.5 * (lo + hi);
            let ok = self.within_limits(&self.lifted(a, m)?) && self.within_limits(&self.lifted(b, m)?);
            if ok {
                lo = m;
            } else {
                hi = m;
            }
        }
        Ok(lo)
    }
}

fn same(a: &[f64], b: &[f64]) -> bool {
    a.iter().zip(b).all(|(x, y)| (x - y).abs() <= 1e-12)
}
