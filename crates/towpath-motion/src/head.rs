//! The head model: a capsule along the tool axis, above the tool point.

use serde::{Deserialize, Serialize};

use crate::error::HeadError;

/// A simple model of the head (the roller and compaction unit, the cutter housing): a capsule
/// whose axis runs along the tool axis, away from the part, from `bottom` to `top` mm above the
/// tool point, with radius `radius`. It is checked like the tool point, with the same clearance.
///
/// It is the optional `[head]` table of a machine file (documented in `docs/motion.md`):
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
    /// Checks every value.
    pub fn validate(&self) -> Result<(), HeadError> {
        let bad = |key: &str, message: String| Err(HeadError::Invalid { key: format!("head.{key}"), message });
        for (k, v) in [("radius", self.radius), ("bottom", self.bottom), ("top", self.top)] {
            if !v.is_finite() {
                return bad(k, format!("{v} is not a finite number"));
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_and_refuses() {
        let h: Head = toml::from_str("radius = 40.0\nbottom = 45.0\ntop = 300.0\n").unwrap();
        assert_eq!(h, Head { radius: 40.0, bottom: 45.0, top: 300.0 });
        h.validate().unwrap();
        assert!(toml::from_str::<Head>("radius = 40.0\nbottom = 45.0\ntop = 300.0\nlength = 2\n").is_err());
        let e = Head { radius: 40.0, bottom: 10.0, top: 300.0 }.validate().unwrap_err();
        assert!(e.to_string().starts_with("head.bottom: 10 is below the radius 40"), "{e}");
        let e = Head { radius: 0.0, bottom: 10.0, top: 300.0 }.validate().unwrap_err();
        assert!(e.to_string().starts_with("head.radius"), "{e}");
        let e = Head { radius: 1.0, bottom: 10.0, top: 5.0 }.validate().unwrap_err();
        assert!(e.to_string().starts_with("head.top"), "{e}");
        let e = Head { radius: 1.0, bottom: f64::NAN, top: 5.0 }.validate().unwrap_err();
        assert!(e.to_string().starts_with("head.bottom"), "{e}");
    }

    /// Every key of the head is documented in docs/motion.md, and its example is a valid head.
    #[test]
    fn keys_are_documented() {
        let docs = include_str!("../../../docs/motion.md");
        for k in ["radius", "bottom", "top"] {
            assert!(docs.contains(&format!("`{k}`")), "head key {k} is not documented");
        }
        let example = docs.split("```toml\n").nth(1).and_then(|s| s.split("```").next()).unwrap();
        let table: toml::Table = toml::from_str(example).unwrap();
        let head: Head = table["head"].clone().try_into().unwrap();
        head.validate().unwrap();
    }
}
