//! The machine file: axes, their kinds, weights and limits, and the optional DH chain.

use serde::{Deserialize, Serialize};

use crate::kinematics::Kinematics;

/// What kind of motion an axis makes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum AxisKind {
    /// A prismatic axis, in mm.
    Linear,
    /// A rotary axis with a limited range, in degrees: it moves exactly by the programmed change.
    Rotary,
    /// A rotary axis that turns without limit, in degrees: moves take the short way round.
    Continuous,
    /// The mandrel (the part turns), in degrees: a continuous axis that also defines the part
    /// frame.
    Mandrel,
}

impl AxisKind {
    /// True for axes measured in degrees.
    pub fn is_angular(self) -> bool {
        !matches!(self, AxisKind::Linear)
    }

    /// True for axes that take the short way round (continuous and mandrel).
    pub fn wraps(self) -> bool {
        matches!(self, AxisKind::Continuous | AxisKind::Mandrel)
    }
}

fn default_weight() -> f64 {
    1.0
}

fn is_false(b: &bool) -> bool {
    !*b
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

/// One axis of the machine.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Axis {
    /// The axis label as written in programs (`X`, `A`, ...).
    pub label: String,
    /// The kind of axis.
    pub kind: AxisKind,
    /// The cost weight C(a) of seed 000 (default 1).
    #[serde(default = "default_weight")]
    pub weight: f64,
    /// Maximum velocity, mm/s or deg/s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_velocity: Option<f64>,
    /// Maximum acceleration, mm/s² or deg/s².
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_acceleration: Option<f64>,
    /// True for the axis that turns the head about the tool axis; a reversed course adds 180°.
    #[serde(default, skip_serializing_if = "is_false")]
    pub heading: bool,
    /// Lower travel limit (linear and rotary axes).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min: Option<f64>,
    /// Upper travel limit (linear and rotary axes).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max: Option<f64>,
    /// The axis value before the program sets it (default 0).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub home: f64,
    /// Mandrel only: the direction of the mandrel's axis of rotation (default `[1, 0, 0]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub direction: Option<[f64; 3]>,
    /// Mandrel only: a point on the mandrel's axis of rotation (default `[0, 0, 0]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub origin: Option<[f64; 3]>,
}

impl Axis {
    /// A new axis with weight 1 and no limits.
    pub fn new(label: &str, kind: AxisKind) -> Self {
        Axis {
            label: label.to_string(),
            kind,
            weight: 1.0,
            max_velocity: None,
            max_acceleration: None,
            heading: false,
            min: None,
            max: None,
            home: 0.0,
            direction: None,
            origin: None,
        }
    }
}

/// One joint of a Denavit–Hartenberg chain (standard convention:
/// `Rz(theta) · Tz(d) · Tx(a) · Rx(alpha)`), angles in degrees, lengths in mm.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DhJoint {
    /// Link length along x.
    #[serde(default)]
    pub a: f64,
    /// Link offset along z.
    #[serde(default)]
    pub d: f64,
    /// Link twist about x, degrees.
    #[serde(default)]
    pub alpha: f64,
    /// Joint angle about z, degrees.
    #[serde(default)]
    pub theta: f64,
    /// The axis that drives this joint: a linear axis adds its value to `d`, an angular axis
    /// to `theta`. Without one the joint is fixed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis: Option<String>,
}

/// A machine: its axes and, optionally, its kinematics.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Machine {
    /// The machine's name.
    pub name: String,
    /// The axes, in the order states list their values.
    #[serde(rename = "axis")]
    pub axes: Vec<Axis>,
    /// The DH chain from the machine base to the head (optional).
    #[serde(default, rename = "dh", skip_serializing_if = "Vec::is_empty")]
    pub dh: Vec<DhJoint>,
    /// The tool point in the last DH frame (default `[0, 0, 0]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tool_offset: Option<[f64; 3]>,
    /// A simple model of the head for motion-safety checks (optional `[head]` table).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub head: Option<Head>,
}

/// A simple model of the head (the roller and compaction unit, the cutter housing), the
/// optional `[head]` table of a machine file: a capsule whose axis runs along the tool axis,
/// away from the part, from `bottom` to `top` mm above the tool point, with radius `radius`.
/// Motion-safety checks test it like the tool point, with the same clearance
/// (`docs/motion.md`).
///
/// ```toml
/// [head]
/// radius = 40.0   # mm
/// bottom = 45.0   # mm above the tool point, along the tool axis (at least the radius)
/// top = 300.0     # mm
/// ```
///
/// A cylinder of radius r from height h0 to h1 lies inside the capsule with the same radius
/// and axis from h0 to h1, so describing a cylindrical head that way is safe (by up to r too
/// cautious at its two ends).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Head {
    /// Radius of the capsule, mm (> 0).
    pub radius: f64,
    /// Height of the lower end of the capsule's axis above the tool point, mm (≥ `radius`, so
    /// that the head never reaches below the tool point: a flat surface under the tool does not
    /// touch it).
    pub bottom: f64,
    /// Height of the upper end of the capsule's axis above the tool point, mm (≥ `bottom`).
    pub top: f64,
}

impl Head {
    /// Checks every value; a refused value is named as `head.radius` etc.
    pub fn validate(&self) -> Result<(), MachineError> {
        let bad = |key: &str, message: String| Err(invalid(format!("head.{key}"), message));
        for (k, v) in [("radius", self.radius), ("bottom", self.bottom), ("top", self.top)] {
            if !v.is_finite() || v.abs() > MAX_AXIS_VALUE {
                return bad(k, format!("{v} is not a finite number of at most {MAX_AXIS_VALUE} mm"));
            }
        }
        if self.radius <= 0.0 {
            return bad("radius", format!("{} is not a radius > 0", self.radius));
        }
        if self.bottom < self.radius {
            return bad(
                "bottom",
                format!(
                    "{} is below the radius {}: the head would reach below the tool point and touch the part at every contact",
                    self.bottom, self.radius
                ),
            );
        }
        if self.top < self.bottom {
            return bad("top", format!("{} is below bottom {}", self.top, self.bottom));
        }
        Ok(())
    }
}

/// Why a machine file was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MachineError {
    /// The file is not valid TOML or does not have the expected shape.
    #[error("line {line}: {message}")]
    Syntax {
        /// 1-based line of the problem (0 if unknown).
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// A value is out of range or inconsistent; `key` names it (`axis[2].weight`), `line` the
    /// line of the file that sets it (or the line of its table when the value is a default;
    /// 0 for a machine not read from a file).
    #[error("{}{key}: {message}", at_line(*line))]
    Invalid {
        /// 1-based line in the file, 0 if unknown.
        line: usize,
        /// The key, as a path.
        key: String,
        /// What is wrong.
        message: String,
    },
}

fn at_line(line: usize) -> String {
    if line > 0 {
        format!("line {line}: ")
    } else {
        String::new()
    }
}

fn invalid(key: impl Into<String>, message: impl Into<String>) -> MachineError {
    MachineError::Invalid { line: 0, key: key.into(), message: message.into() }
}

/// Largest magnitude of a position in a machine file (axis `home`, `min`, `max`, the mandrel's
/// `origin`, `tool_offset`, DH lengths), in mm or degrees: the range programs may use.
pub const MAX_AXIS_VALUE: f64 = 1e7;
/// Largest axis `weight`.
pub const MAX_WEIGHT: f64 = 1e6;
/// Range of `max_velocity`, mm/s or deg/s.
pub const VELOCITY_RANGE: (f64, f64) = (1e-3, 1e7);
/// Range of `max_acceleration`, mm/s² or deg/s².
pub const ACCELERATION_RANGE: (f64, f64) = (1e-3, 1e9);
/// Largest magnitude of a DH angle (`alpha`, `theta`), degrees.
pub const MAX_DH_ANGLE: f64 = 1e6;
/// Most axes, and most DH joints, a machine may have.
pub const MAX_AXES: usize = 64;

impl Machine {
    /// A machine with the given axes and no kinematics.
    pub fn new(name: &str, axes: Vec<Axis>) -> Result<Self, MachineError> {
        let m = Machine { name: name.to_string(), axes, dh: Vec::new(), tool_offset: None, head: None };
        m.validate()?;
        Ok(m)
    }

    /// Reads a machine from TOML text and validates it; a refused value names the line that
    /// sets it.
    pub fn from_toml_str(text: &str) -> Result<Self, MachineError> {
        let m: Machine = toml::from_str(text).map_err(|e| {
            let line = e.span().map_or(0, |s| text[..s.start.min(text.len())].matches('\n').count() + 1);
            MachineError::Syntax { line, message: e.message().to_string() }
        })?;
        m.validate().map_err(|e| match e {
            MachineError::Invalid { key, message, .. } => {
                MachineError::Invalid { line: crate::locate::line_of(text, &key), key, message }
            }
            e => e,
        })?;
        Ok(m)
    }

    /// Writes the machine as TOML.
    pub fn to_toml_string(&self) -> String {
        // Serializing plain data with finite numbers cannot fail.
        toml::to_string(self).unwrap_or_default()
    }

    /// Checks every value; called by the constructors.
    pub fn validate(&self) -> Result<(), MachineError> {
        if let Some(h) = &self.head {
            h.validate()?;
        }
        if self.axes.is_empty() {
            return Err(invalid("axis", "the machine has no axes"));
        }
        if self.axes.len() > MAX_AXES {
            return Err(invalid("axis", format!("{} axes: a machine has at most {MAX_AXES}", self.axes.len())));
        }
        if self.dh.len() > MAX_AXES {
            return Err(invalid("dh", format!("{} joints: a DH chain has at most {MAX_AXES}", self.dh.len())));
        }
        let mut headings = 0;
        let mut mandrels = 0;
        for (i, a) in self.axes.iter().enumerate() {
            let key = |k: &str| format!("axis[{i}].{k}");
            if a.label.is_empty() || !a.label.chars().all(|c| c.is_ascii_alphanumeric()) {
                return Err(invalid(
                    key("label"),
                    format!("{:?} is not a valid axis label (letters and digits)", a.label),
                ));
            }
            if let Some(j) = self.axes[..i].iter().position(|b| b.label.eq_ignore_ascii_case(&a.label)) {
                return Err(invalid(key("label"), format!("axis {:?} is defined twice (also axis[{j}])", a.label)));
            }
            if !(a.weight.is_finite() && a.weight >= 0.0) {
                return Err(invalid(key("weight"), format!("{} is not a finite weight ≥ 0", num(a.weight))));
            }
            if a.weight > MAX_WEIGHT {
                return Err(invalid(
                    key("weight"),
                    format!(
                        "{} is above {MAX_WEIGHT:e}: weights are relative, keep them within 0 to {MAX_WEIGHT:e}",
                        num(a.weight)
                    ),
                ));
            }
            for (k, v, (lo, hi), unit) in [
                ("max_velocity", a.max_velocity, VELOCITY_RANGE, "mm/s or deg/s"),
                ("max_acceleration", a.max_acceleration, ACCELERATION_RANGE, "mm/s² or deg/s²"),
            ] {
                if let Some(v) = v {
                    if !(v.is_finite() && v > 0.0) {
                        return Err(invalid(key(k), format!("{} is not a finite value > 0", num(v))));
                    }
                    if !(lo..=hi).contains(&v) {
                        return Err(invalid(key(k), format!("{} is outside {lo:e} to {hi:e} {unit}", num(v))));
                    }
                }
            }
            position(&key("home"), a.home)?;
            for (k, v) in [("min", a.min), ("max", a.max)] {
                if let Some(v) = v {
                    position(&key(k), v)?;
                    if a.kind.wraps() {
                        return Err(invalid(key(k), "continuous and mandrel axes have no travel limits"));
                    }
                }
            }
            if let (Some(lo), Some(hi)) = (a.min, a.max) {
                if lo > hi {
                    return Err(invalid(key("min"), format!("min {lo} is above max {hi}")));
                }
            }
            if a.heading {
                headings += 1;
                if !matches!(a.kind, AxisKind::Rotary | AxisKind::Continuous) {
                    return Err(invalid(key("heading"), "the heading axis must be rotary or continuous"));
                }
                if headings > 1 {
                    return Err(invalid(key("heading"), "only one axis can be the heading axis"));
                }
            }
            if a.kind == AxisKind::Mandrel {
                mandrels += 1;
                if mandrels > 1 {
                    return Err(invalid(key("kind"), "only one axis can be the mandrel"));
                }
            } else if a.direction.is_some() || a.origin.is_some() {
                return Err(invalid(key("direction"), "direction and origin are for the mandrel axis only"));
            }
            if let Some(d) = a.direction {
                if !d.iter().all(|v| v.is_finite() && v.abs() <= MAX_AXIS_VALUE) {
                    return Err(invalid(
                        key("direction"),
                        format!("the mandrel direction must be a vector of finite numbers within ±{MAX_AXIS_VALUE:e}"),
                    ));
                }
                let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                if n <= 1e-9 {
                    return Err(invalid(key("direction"), "the mandrel direction must be a non-zero vector"));
                }
            }
            if let Some(o) = a.origin {
                for v in o {
                    position(&key("origin"), v)?;
                }
            }
        }
        let mut driven = vec![false; self.axes.len()];
        for (j, joint) in self.dh.iter().enumerate() {
            let key = |k: &str| format!("dh[{j}].{k}");
            for (k, v) in [("a", joint.a), ("d", joint.d)] {
                position(&key(k), v)?;
            }
            for (k, v) in [("alpha", joint.alpha), ("theta", joint.theta)] {
                if !(v.is_finite() && v.abs() <= MAX_DH_ANGLE) {
                    return Err(invalid(
                        key(k),
                        format!("{} is not an angle within ±{MAX_DH_ANGLE:e} degrees", num(v)),
                    ));
                }
            }
            if let Some(label) = &joint.axis {
                let Some(i) = self.axis_index(label) else {
                    return Err(invalid(key("axis"), format!("no axis is labelled {label:?}")));
                };
                if self.axes[i].kind == AxisKind::Mandrel {
                    return Err(invalid(
                        key("axis"),
                        "the mandrel turns the part, not the head: leave it out of the chain",
                    ));
                }
                if driven[i] {
                    return Err(invalid(key("axis"), format!("axis {label:?} drives two joints")));
                }
                driven[i] = true;
            }
        }
        if let Some(t) = self.tool_offset {
            for v in t {
                position("tool_offset", v)?;
            }
        }
        Ok(())
    }

    /// Number of axes (the length of a state).
    pub fn dim(&self) -> usize {
        self.axes.len()
    }

    /// Index of the axis with this label (case-insensitive).
    pub fn axis_index(&self, label: &str) -> Option<usize> {
        self.axes.iter().position(|a| a.label.eq_ignore_ascii_case(label))
    }

    /// Index of the heading axis, if any.
    pub fn heading_axis(&self) -> Option<usize> {
        self.axes.iter().position(|a| a.heading)
    }

    /// Index of the mandrel axis, if any.
    pub fn mandrel_axis(&self) -> Option<usize> {
        self.axes.iter().position(|a| a.kind == AxisKind::Mandrel)
    }

    /// The home state: every axis at its `home` value.
    pub fn home(&self) -> Vec<f64> {
        self.axes.iter().map(|a| a.home).collect()
    }

    /// The travel of axis `i` on a move from `from` to `to`: the plain difference, or for
    /// continuous and mandrel axes the short way round, in (−180, 180].
    #[inline]
    pub fn short_delta(&self, i: usize, from: f64, to: f64) -> f64 {
        let d = to - from;
        if self.axes[i].kind.wraps() {
            wrap_degrees(d)
        } else {
            d
        }
    }

    /// Forward kinematics, if the machine has any (a DH chain, or X/Y/Z linear axes).
    pub fn kinematics(&self) -> Option<Kinematics> {
        Kinematics::new(self)
    }
}

/// A position value (mm or degrees) must be finite and within ±[`MAX_AXIS_VALUE`].
fn position(key: &str, v: f64) -> Result<(), MachineError> {
    if v.is_finite() && v.abs() <= MAX_AXIS_VALUE {
        Ok(())
    } else {
        Err(invalid(key, format!("{} is not a number within ±{MAX_AXIS_VALUE:e}", num(v))))
    }
}

/// A number for a message: plain when it reads well, else in exponent form (`1e308`, not 309
/// digits).
fn num(v: f64) -> String {
    if v == 0.0 || (1e-3..1e7).contains(&v.abs()) || !v.is_finite() {
        v.to_string()
    } else {
        format!("{v:e}")
    }
}

/// Wraps an angle in degrees to (−180, 180].
#[inline]
pub(crate) fn wrap_degrees(d: f64) -> f64 {
    let r = d - 360.0 * (d / 360.0).round();
    if r <= -180.0 {
        r + 360.0
    } else if r > 180.0 {
        r - 360.0
    } else {
        r
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const GANTRY: &str = r#"
name = "gantry-afp"
[[axis]]
label = "X"
kind = "linear"
weight = 1.0
max_velocity = 1000.0
max_acceleration = 2000.0
[[axis]]
label = "C"
kind = "continuous"
heading = true
"#;

    #[test]
    fn head_table_is_read_and_checked() {
        let base = "name = \"g\"\n[[axis]]\nlabel = \"X\"\nkind = \"linear\"\n";
        let m = Machine::from_toml_str(&format!("{base}[head]\nradius = 40.0\nbottom = 45.0\ntop = 300.0\n")).unwrap();
        assert_eq!(m.head, Some(Head { radius: 40.0, bottom: 45.0, top: 300.0 }));
        let e =
            Machine::from_toml_str(&format!("{base}[head]\nradius = 40.0\nbottom = 10.0\ntop = 300.0\n")).unwrap_err();
        assert_eq!(e.to_string().split(':').take(2).collect::<Vec<_>>(), ["line 7", " head.bottom"], "{e}");
        assert!(Machine::from_toml_str(&format!(
            "{base}[head]\nradius = 40.0\nbottom = 45.0\ntop = 300.0\nlength = 2\n"
        ))
        .is_err());
        for bad in [
            "radius = 0.0\nbottom = 1.0\ntop = 2.0",
            "radius = 1.0\nbottom = 10.0\ntop = 5.0",
            "radius = 1.0\nbottom = nan\ntop = 5.0",
        ] {
            assert!(Machine::from_toml_str(&format!("{base}[head]\n{bad}\n")).is_err(), "{bad}");
        }
    }

    #[test]
    fn reads_the_documented_shape() {
        let m = Machine::from_toml_str(GANTRY).unwrap();
        assert_eq!(m.name, "gantry-afp");
        assert_eq!(m.dim(), 2);
        assert_eq!(m.axes[0].max_velocity, Some(1000.0));
        assert_eq!(m.axes[1].weight, 1.0);
        assert_eq!(m.heading_axis(), Some(1));
        assert_eq!(m.axis_index("c"), Some(1));
        let again = Machine::from_toml_str(&m.to_toml_string()).unwrap();
        assert_eq!(again, m);
    }

    #[test]
    fn refuses_bad_files_with_the_key_or_line() {
        let e = Machine::from_toml_str("name = \"m\"\n[[axis]]\nlabel = \"X\"\nkind = \"lineer\"\n").unwrap_err();
        assert!(matches!(e, MachineError::Syntax { line: 4, .. }), "{e}");
        let e = Machine::from_toml_str("name = \"m\"\n[[axis]]\nlabel = \"X\"\nkind = \"linear\"\nwieght = 2\n")
            .unwrap_err();
        assert!(matches!(e, MachineError::Syntax { line: 5, .. }), "{e}");
        let e = Machine::from_toml_str(&GANTRY.replace("weight = 1.0", "weight = -1.0")).unwrap_err();
        assert_eq!(e.to_string(), "line 6: axis[0].weight: -1 is not a finite weight ≥ 0");
        let e = Machine::from_toml_str(&GANTRY.replace("\"C\"", "\"x\"")).unwrap_err();
        assert!(e.to_string().contains("defined twice"), "{e}");
        let e = Machine::from_toml_str(&GANTRY.replace("kind = \"continuous\"", "kind = \"linear\"")).unwrap_err();
        assert!(e.to_string().contains("heading axis must be rotary"), "{e}");
        let e = Machine::from_toml_str(&format!("{GANTRY}[[dh]]\naxis = \"Q\"\n")).unwrap_err();
        assert!(e.to_string().starts_with("line 14: dh[0].axis"), "{e}");
        let e = Machine::from_toml_str("name = \"m\"\naxis = []\n").unwrap_err();
        assert_eq!(e.to_string(), "line 2: axis: the machine has no axes");
        let e = Machine::from_toml_str(&GANTRY.replace("max_velocity = 1000.0", "max_velocity = nan")).unwrap_err();
        assert!(e.to_string().contains("max_velocity"), "{e}");
    }

    /// Numbers that are finite but absurd (a weight of 1e308 overflows every cost; a velocity of
    /// 1e-300 makes every move take forever) are refused with the line that sets them, each
    /// against its documented range; values just inside the ranges are accepted.
    #[test]
    fn numbers_outside_their_ranges_are_refused_with_their_line() {
        let refused = |from: &str, to: &str, says: &str| {
            let text = GANTRY.replace(from, to);
            assert_ne!(text, GANTRY, "{from}");
            let e = Machine::from_toml_str(&text).unwrap_err().to_string();
            assert!(e.contains(says), "{to}: {e}");
        };
        refused("weight = 1.0", "weight = 1e308", "line 6: axis[0].weight: 1e308 is above 1e6");
        refused(
            "max_velocity = 1000.0",
            "max_velocity = 1e-300",
            "line 7: axis[0].max_velocity: 1e-300 is outside 1e-3 to 1e7 mm/s or deg/s",
        );
        refused("max_velocity = 1000.0", "max_velocity = 1e300", "line 7: axis[0].max_velocity");
        refused("max_acceleration = 2000.0", "max_acceleration = 1e10", "line 8: axis[0].max_acceleration");
        refused(
            "heading = true",
            "heading = true\nhome = 1e8",
            "line 13: axis[1].home: 1e8 is not a number within ±1e7",
        );
        refused("heading = true", "heading = true\nkind2 = 1", "line 13");
        let with = |extra: &str| Machine::from_toml_str(&format!("{GANTRY}{extra}"));
        let e = with("[[dh]]\na = 2e7\n").unwrap_err().to_string();
        assert!(e.starts_with("line 14: dh[0].a: 2e7 is not a number within ±1e7"), "{e}");
        let e = with("[[dh]]\nalpha = 1e300\n").unwrap_err().to_string();
        assert!(e.starts_with("line 14: dh[0].alpha: 1e300 is not an angle"), "{e}");
        let e = Machine::from_toml_str(&format!("tool_offset = [0, 0, 1e9]{GANTRY}")).unwrap_err().to_string();
        assert_eq!(e, "line 1: tool_offset: 1e9 is not a number within ±1e7");
        let mandrel = "[[axis]]\nlabel = \"A\"\nkind = \"mandrel\"\norigin = [0, 1e300, 0]\n";
        let e = with(mandrel).unwrap_err().to_string();
        assert!(e.starts_with("line 16: axis[2].origin: 1e300"), "{e}");
        let e = with(&mandrel.replace("origin = [0, 1e300, 0]", "direction = [1e-300, 0, 0]")).unwrap_err().to_string();
        assert!(e.starts_with("line 16: axis[2].direction"), "{e}");
        // At the edges of the ranges: accepted.
        let edge = GANTRY
            .replace("weight = 1.0", "weight = 1e6")
            .replace("max_velocity = 1000.0", "max_velocity = 1e7")
            .replace("max_acceleration = 2000.0", "max_acceleration = 1e-3");
        Machine::from_toml_str(&edge).unwrap();
        // A machine built in code has no line to name.
        let mut x = Axis::new("X", AxisKind::Linear);
        x.weight = 1e7;
        assert_eq!(
            Machine::new("m", vec![x]).unwrap_err().to_string(),
            "axis[0].weight: 1e7 is above 1e6: weights are relative, keep them within 0 to 1e6"
        );
    }

    /// Every key a machine file can hold, collected from a machine that sets them all.
    fn keys(value: &toml::Value, out: &mut Vec<String>) {
        match value {
            toml::Value::Table(t) => {
                for (k, v) in t {
                    out.push(k.clone());
                    keys(v, out);
                }
            }
            toml::Value::Array(a) => a.iter().for_each(|v| keys(v, out)),
            _ => {}
        }
    }

    /// "document every key": each key the machine file accepts has a row in docs/machine.md,
    /// and the example at the top of that page is a valid machine.
    #[test]
    fn every_key_is_documented() {
        let docs = include_str!("../../../docs/machine.md");
        let mut full = Machine::from_toml_str(GANTRY).unwrap();
        full.axes[0].min = Some(-10.0);
        full.axes[0].max = Some(10.0);
        full.axes[0].home = 1.0;
        let mut mandrel = Axis::new("A", AxisKind::Mandrel);
        mandrel.direction = Some([1.0, 0.0, 0.0]);
        mandrel.origin = Some([0.0, 0.0, 1.0]);
        full.axes.push(mandrel);
        full.dh = vec![DhJoint { a: 1.0, d: 1.0, alpha: 1.0, theta: 1.0, axis: Some("X".into()) }];
        full.tool_offset = Some([0.0, 0.0, 1.0]);
        full.validate().unwrap();
        let value: toml::Value = toml::from_str(&full.to_toml_string()).unwrap();
        let mut all = Vec::new();
        keys(&value, &mut all);
        all.sort();
        all.dedup();
        assert!(all.len() >= 18, "{all:?}");
        for k in &all {
            let table = k == "axis" || k == "dh";
            let documented =
                if table { docs.contains(&format!("`[[{k}]]`")) } else { docs.contains(&format!("`{k}`")) };
            assert!(documented, "key {k} is not documented in docs/machine.md");
        }
        let example = docs.split("```toml\n").nth(1).and_then(|s| s.split("```").next()).unwrap();
        let m = Machine::from_toml_str(example).unwrap();
        assert_eq!(m.heading_axis(), m.axis_index("C"));
    }

    #[test]
    fn short_way_round() {
        assert_eq!(wrap_degrees(350.0), -10.0);
        assert_eq!(wrap_degrees(-350.0), 10.0);
        assert_eq!(wrap_degrees(180.0), 180.0);
        assert_eq!(wrap_degrees(-180.0), 180.0);
        assert_eq!(wrap_degrees(720.5), 0.5);
        let m = Machine::from_toml_str(GANTRY).unwrap();
        assert_eq!(m.short_delta(1, 350.0, 10.0), 20.0);
        assert_eq!(m.short_delta(0, 350.0, 10.0), -340.0);
    }
}
