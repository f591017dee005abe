//! The whole plan (Tewolde & Sheng 2008 Fig. 3): partition → passes per patch → one sequenced
//! path → poses with time stamps.

use std::time::Instant;

use glam::DVec3;
use rayon::prelude::*;
use serde::Serialize;
use towpath_geom::Mesh;

use crate::deposition::{Gun, Pose};
use crate::error::{positive, SprayError};
use crate::frame::Frame;
use crate::modulation::{modulate, ModulationReport, DEFAULT_MAX_SPEED_CHANGE};
use crate::partition::{self, Partition, PartitionOptions};
use crate::passes::{self, Pass, PassParams, PatchPlan, Pattern, PatternChoice, Planned};
use crate::path::{assemble, PathTotals};
use crate::sequence::{sequence, SeqOptions, Sequenced};
use crate::slicer;
use crate::spacing::{self, SpacingChoice};
use crate::transit::Clearance;

/// Default travel speed with the spray off (mm/s).
pub const DEFAULT_TRAVEL_SPEED: f64 = 1000.0;
/// Default β_th (degrees).
pub const DEFAULT_MAX_DEVIATION: f64 = 20.0;
/// Most passes a plan may have.
pub const MAX_PASSES: usize = 200_000;

/// Everything a plan depends on.
#[derive(Debug, Clone)]
pub struct SprayParams {
    /// The gun and material.
    pub gun: Gun,
    /// Target mean thickness (µm).
    pub target_thickness: f64,
    /// β_th (degrees): largest deviation of a face normal from its patch's mean normal.
    pub max_deviation_deg: f64,
    /// Pass pattern.
    pub pattern: PatternChoice,
    /// Fixed pass spacing (mm), or `None` to optimise per patch.
    pub spacing: Option<f64>,
    /// Fixed gun speed (mm/s), or `None` to reach the target thickness.
    pub speed: Option<f64>,
    /// How far passes run past free and sharp edges (mm); `None`: one spray radius.
    pub overrun: Option<f64>,
    /// Speed of transits (mm/s).
    pub travel_speed: f64,
    /// Where the path starts.
    pub home: Option<DVec3>,
    /// Split pieces by topology before the flatness growth.
    pub topology: bool,
    /// Largest factor by which [`modulation`](crate::modulation) may change the gun speed along
    /// a pass (1: no modulation; ignored when `speed` is fixed).
    pub max_speed_change: f64,
    /// Sequencing.
    pub seq: SeqOptions,
}

impl SprayParams {
    /// Parameters with the defaults for everything but the gun and the target.
    pub fn new(gun: Gun, target_thickness: f64) -> SprayParams {
        SprayParams {
            gun,
            target_thickness,
            max_deviation_deg: DEFAULT_MAX_DEVIATION,
            pattern: PatternChoice::Auto,
            spacing: None,
            speed: None,
            overrun: None,
            travel_speed: DEFAULT_TRAVEL_SPEED,
            home: None,
            topology: true,
            max_speed_change: DEFAULT_MAX_SPEED_CHANGE,
            seq: SeqOptions::default(),
        }
    }

    /// Checks every parameter.
    pub fn validate(&self) -> Result<(), SprayError> {
        self.gun.validate()?;
        positive("the target thickness", self.target_thickness)?;
        if !(self.max_deviation_deg > 0.0 && self.max_deviation_deg < 90.0) {
            return Err(SprayError::BadParameter {
                what: "the maximum deviation angle",
                must: "between 0 and 90 degrees",
                got: self.max_deviation_deg,
            });
        }
        if let Some(d) = self.spacing {
            positive("the pass spacing", d)?;
            if d > 2.0 * self.gun.radius {
                return Err(SprayError::BadParameter {
                    what: "the pass spacing",
                    must: "at most twice the spray radius (wider leaves bare stripes)",
                    got: d,
                });
            }
        }
        if let Some(v) = self.speed {
            positive("the gun speed", v)?;
        }
        if let Some(e) = self.overrun {
            if !(e.is_finite() && e >= 0.0) {
                return Err(SprayError::BadParameter { what: "the run-out", must: "a length ≥ 0", got: e });
            }
        }
        positive("the travel speed", self.travel_speed)?;
        if !(self.max_speed_change >= 1.0 && self.max_speed_change.is_finite()) {
            return Err(SprayError::BadParameter {
                what: "the largest speed change",
                must: "a factor ≥ 1 (1: keep the planned speeds)",
                got: self.max_speed_change,
            });
        }
        if let Some(h) = self.home {
            if !h.is_finite() {
                return Err(SprayError::BadParameter { what: "the home position", must: "finite", got: f64::NAN });
            }
        }
        Ok(())
    }
}

/// Seconds spent in each stage.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct Timings {
    /// Partition.
    pub partition_s: f64,
    /// Passes.
    pub passes_s: f64,
    /// Sequencing (including transits).
    pub sequence_s: f64,
    /// Speed modulation.
    pub modulation_s: f64,
}

/// A spray plan.
#[derive(Debug, Clone)]
pub struct SprayPlan {
    /// The flat patches.
    pub partition: Partition,
    /// How each patch is sprayed.
    pub patches: Vec<PatchPlan>,
    /// Every pass.
    pub passes: Vec<Pass>,
    /// The order and the transits.
    pub sequenced: Sequenced,
    /// The robot path.
    pub poses: Vec<Pose>,
    /// Its totals.
    pub totals: PathTotals,
    /// The profile's optimal spacing on an endless plane.
    pub optimum: SpacingChoice,
    /// What the speed modulation did.
    pub modulation: ModulationReport,
    /// Time per stage.
    pub timings: Timings,
}

/// Plans the spraying of a mesh (see the crate docs).
pub fn plan(mesh: &Mesh, params: &SprayParams) -> Result<SprayPlan, SprayError> {
    params.validate()?;
    if !(mesh.area() > 0.0) || mesh.num_faces() == 0 {
        return Err(SprayError::NoArea);
    }
    let gun = params.gun;
    let overrun = params.overrun.unwrap_or(gun.radius);
    let optimum = spacing::optimal_spacing(&gun.profile, gun.radius);
    let pp = PassParams { gun, target: params.target_thickness, spacing: params.spacing, speed: params.speed, optimum };
    let t0 = Instant::now();
    let (partition, planned): (Partition, Vec<(Planned, Option<f64>)>) = if params.pattern == PatternChoice::Slicer {
        let all: Vec<u32> = (0..mesh.num_faces() as u32).collect();
        let part = partition::build(mesh, vec![(all, 0)], 1, 0, 1);
        let axes = slicer::principal_axes(mesh);
        let m = axes[1];
        let (lo, hi) = mesh.positions().iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            let x = p.dot(m);
            (a.min(x), b.max(x))
        });
        let d = params.spacing.unwrap_or_else(|| spacing::fit(&gun.profile, gun.radius, hi - lo, optimum.spacing).1);
        let n = ((hi - lo) / d).round().max(1.0) as usize;
        check_count(n)?;
        let offsets: Vec<f64> = (0..n).map(|k| lo + (k as f64 + 0.5) * d).collect();
        let geoms = slicer::slices(mesh, m, &offsets, gun.standoff, gun.radius / 4.0, overrun);
        let speed = params.speed.unwrap_or_else(|| gun.speed_for(params.target_thickness, d));
        let planned = Planned { pattern: Pattern::Slicer, direction: Some(axes[0]), spacing: d, speed, geoms };
        (part, vec![(planned, None)])
    } else {
        let opts = PartitionOptions {
            max_deviation_deg: params.max_deviation_deg,
            topology: params.topology,
            scale: gun.radius,
        };
        let part = partition::partition(mesh, &opts);
        let absorbed = absorbed(&part, gun.radius);
        let planned: Vec<Option<(Planned, Option<f64>)>> = part
            .patches
            .par_iter()
            .map(|p| {
                if absorbed[p.id as usize] {
                    return Some((Planned { pattern: Pattern::Absorbed, ..Planned::empty() }, None));
                }
                let frame = Frame::new(mesh, &part, p.id, overrun, &absorbed);
                plan_patch(&frame, &pp, params.pattern)
            })
            .collect();
        let planned = planned.into_iter().map(|p| p.unwrap_or((Planned::empty(), None))).collect();
        (part, planned)
    };
    let t_part = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let mut passes: Vec<Pass> = Vec::new();
    let mut patches: Vec<PatchPlan> = Vec::new();
    for (i, (pl, other)) in planned.iter().enumerate() {
        let ps = passes::finish(pl, i as u32, passes.len() as u32);
        check_count(passes.len() + ps.len())?;
        patches.push(PatchPlan {
            patch: i as u32,
            pattern: pl.pattern,
            direction: pl.direction,
            spacing: pl.spacing,
            speed: pl.speed,
            ripple: if pl.spacing > 0.0 { spacing::ripple(&gun.profile, gun.radius, pl.spacing) } else { 0.0 },
            passes: ps.iter().map(|p| p.id).collect(),
            estimate_s: pl.estimate(),
            other_estimate_s: *other,
        });
        passes.extend(ps);
    }
    let t_passes = t1.elapsed().as_secs_f64();
    let t2 = Instant::now();
    let clearance = Clearance::new(mesh, gun.standoff);
    let sequenced = sequence(&passes, params.home, &clearance, &params.seq)?;
    let (mut poses, mut totals) = assemble(&passes, &sequenced, params.home, params.travel_speed);
    let t_seq = t2.elapsed().as_secs_f64();
    let t3 = Instant::now();
    let change = if params.speed.is_some() { 1.0 } else { params.max_speed_change };
    let modulation = modulate(mesh, &gun, &mut poses, params.target_thickness, change)?;
    totals.spray_time_s += modulation.spray_time_after_s - modulation.spray_time_before_s;
    totals.cycle_time_s = poses.last().map_or(0.0, |p| p.time);
    let t_mod = t3.elapsed().as_secs_f64();
    Ok(SprayPlan {
        partition,
        patches,
        passes,
        sequenced,
        poses,
        totals,
        optimum,
        modulation,
        timings: Timings { partition_s: t_part, passes_s: t_passes, sequence_s: t_seq, modulation_s: t_mod },
    })
}

/// Patches of less than R² (R the spray radius) with a neighbour that is not that small get no
/// passes of their own: they are slivers left by the region growing (a corner of a rim, a
/// fillet), and their neighbours' passes run over them as over a free edge.
fn absorbed(part: &Partition, radius: f64) -> Vec<bool> {
    let small: Vec<bool> = part.patches.iter().map(|p| p.area < radius * radius).collect();
    part.patches.iter().map(|p| small[p.id as usize] && p.neighbors.iter().any(|n| !small[n.patch as usize])).collect()
}

fn check_count(n: usize) -> Result<(), SprayError> {
    if n > MAX_PASSES {
        return Err(SprayError::TooLarge { what: format!("more than {MAX_PASSES} passes") });
    }
    Ok(())
}

/// The passes of one patch under a pattern choice, and the estimate of the pattern not taken
/// when both were planned.
fn plan_patch(frame: &Frame, pp: &PassParams, choice: PatternChoice) -> Option<(Planned, Option<f64>)> {
    match choice {
        PatternChoice::Zigzag | PatternChoice::Slicer => passes::zigzag(frame, pp).map(|z| (z, None)),
        PatternChoice::Spiral => passes::spiral(frame, pp).or_else(|| passes::zigzag(frame, pp)).map(|s| (s, None)),
        PatternChoice::Auto => {
            let z = passes::zigzag(frame, pp);
            let s = passes::spiral(frame, pp);
            match (z, s) {
                (Some(z), Some(s)) => {
                    let (ez, es) = (z.estimate(), s.estimate());
                    if es < 0.9 * ez {
                        Some((s, Some(ez)))
                    } else {
                        Some((z, Some(es)))
                    }
                }
                (z, s) => z.or(s).map(|p| (p, None)),
            }
        }
    }
}
