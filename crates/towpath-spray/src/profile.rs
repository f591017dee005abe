//! Flux profiles of a spray cone across its footprint, normalised so that the profile integrates
//! to one over the footprint disk: the deposition rate is then the volume flow times the profile.
//!
//! - **β distribution** (Balkan & Arikan 1999; Conner et al. 2005): over the disk r ≤ R,
//!   `q(r) = β / (π R²) · (1 − r²/R²)^(β−1)`. β = 1 is a flat disk, β = 2 a paraboloid, larger β
//!   more peaked. Its integral along a line at distance y from the centre (the thickness one
//!   straight pass leaves, per unit speed) has the closed form
//!   `G(y) = β B(½, β) / (π R^(2β−2)) · c^(2β−1)` with `c = √(R² − y²)` and B the beta function.
//! - **Gaussian** truncated at the footprint radius: `q(r) = exp(−r²/2σ²) / (2πσ² (1 − e^(−R²/2σ²)))`
//!   for r ≤ R; along a line, `G(y) = exp(−y²/2σ²) erf(c/(σ√2)) / (√(2π) σ (1 − e^(−R²/2σ²)))`.

use std::f64::consts::PI;

use crate::error::SprayError;

/// The shape of the flux across the spray footprint.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum Profile {
    /// The β distribution `(1 − r²/R²)^(β−1)` (β ≥ 1).
    Beta {
        /// The exponent β.
        beta: f64,
    },
    /// A Gaussian of standard deviation σ (mm), truncated at the footprint radius.
    Gauss {
        /// The standard deviation in mm.
        sigma: f64,
    },
}

impl Default for Profile {
    /// β = 2, the paraboloid most painting studies fit.
    fn default() -> Self {
        Profile::Beta { beta: 2.0 }
    }
}

impl std::fmt::Display for Profile {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Profile::Beta { beta } => write!(f, "beta:{beta}"),
            Profile::Gauss { sigma } => write!(f, "gauss:{sigma}"),
        }
    }
}

impl Profile {
    /// Reads `beta:B` or `gauss:SIGMA`.
    pub fn parse(text: &str) -> Result<Profile, SprayError> {
        let fail = |m: &str| SprayError::BadProfile { text: text.to_string(), message: m.to_string() };
        let (kind, value) = text.split_once(':').ok_or_else(|| fail("expected beta:B or gauss:SIGMA"))?;
        let x: f64 = value.trim().parse().map_err(|_| fail("the value is not a number"))?;
        let p = match kind.trim().to_ascii_lowercase().as_str() {
            "beta" => Profile::Beta { beta: x },
            "gauss" | "gaussian" => Profile::Gauss { sigma: x },
            _ => return Err(fail("unknown profile (expected beta:B or gauss:SIGMA)")),
        };
        p.check().map_err(fail)?;
        Ok(p)
    }

    fn check(&self) -> Result<(), &'static str> {
        match *self {
            Profile::Beta { beta } if !(beta.is_finite() && (1.0..=50.0).contains(&beta)) => {
                Err("β must be a number from 1 to 50")
            }
            Profile::Gauss { sigma } if !(sigma.is_finite() && sigma > 0.0) => Err("σ must be a positive length"),
            _ => Ok(()),
        }
    }

    /// Checks the profile against a footprint radius.
    pub fn validate(&self, radius: f64) -> Result<(), SprayError> {
        self.check().map_err(|m| SprayError::BadProfile { text: self.to_string(), message: m.to_string() })?;
        if let Profile::Gauss { sigma } = *self {
            if sigma < radius * 0.02 {
                return Err(SprayError::BadProfile {
                    text: self.to_string(),
                    message: format!("σ must be at least 2 % of the spray radius {radius}"),
                });
            }
        }
        Ok(())
    }

    /// The evaluator of this profile for a footprint radius (constants precomputed).
    pub fn kernel(&self, radius: f64) -> Kernel {
        let r2 = radius * radius;
        match *self {
            Profile::Beta { beta } => {
                Kernel { inv_r2: 1.0 / r2, scale: beta / (PI * r2), exponent: beta - 1.0, gauss: 0.0, r2 }
            }
            Profile::Gauss { sigma } => {
                let s2 = 2.0 * sigma * sigma;
                let mass = 1.0 - (-r2 / s2).exp();
                Kernel { inv_r2: 1.0 / r2, scale: 1.0 / (PI * s2 * mass), exponent: 0.0, gauss: 1.0 / s2, r2 }
            }
        }
    }

    /// `G(y)`: the profile integrated along a straight line at distance `y` from the footprint
    /// centre (1/mm). A straight pass at speed v with flow F leaves `F·G(y)/v` at offset y.
    pub fn line_integral(&self, y: f64, radius: f64) -> f64 {
        let r2 = radius * radius;
        let c2 = r2 - y * y;
        if !(c2 > 0.0) {
            return 0.0;
        }
        let c = c2.sqrt();
        match *self {
            Profile::Beta { beta } => {
                // β/(πR²) ∫_{-c}^{c} (1 − (x²+y²)/R²)^(β−1) dx, x = c·s:
                // = β/(πR²) (c²/R²)^(β−1) c ∫_{-1}^{1} (1 − s²)^(β−1) ds, the last integral B(½, β).
                let b = beta_fn(0.5, beta);
                beta / (PI * r2) * (c2 / r2).powf(beta - 1.0) * c * b
            }
            Profile::Gauss { sigma } => {
                let s2 = 2.0 * sigma * sigma;
                let mass = 1.0 - (-r2 / s2).exp();
                (-y * y / s2).exp() * libm::erf(c / (sigma * std::f64::consts::SQRT_2))
                    / ((2.0 * PI).sqrt() * sigma * mass)
            }
        }
    }
}

/// The beta function B(a, b) = Γ(a)Γ(b)/Γ(a+b).
fn beta_fn(a: f64, b: f64) -> f64 {
    (libm::lgamma(a) + libm::lgamma(b) - libm::lgamma(a + b)).exp()
}

/// A profile ready to evaluate: `density(r²)` per unit area (1/mm²), zero outside the footprint.
#[derive(Debug, Clone, Copy)]
pub struct Kernel {
    inv_r2: f64,
    scale: f64,
    exponent: f64,
    /// 1/(2σ²) for a Gaussian, 0 for a β profile.
    gauss: f64,
    r2: f64,
}

impl Kernel {
    /// The profile at squared radial distance `r2` (mm²); 0 at and beyond the footprint radius.
    #[inline]
    pub fn density(&self, r2: f64) -> f64 {
        if !(r2 < self.r2) {
            return 0.0;
        }
        if self.gauss > 0.0 {
            return self.scale * (-r2 * self.gauss).exp();
        }
        let u = 1.0 - r2 * self.inv_r2;
        let e = self.exponent;
        let f = if e == 1.0 {
            u
        } else if e == 0.0 {
            1.0
        } else if e.fract() == 0.0 && e <= 16.0 {
            u.powi(e as i32)
        } else {
            u.powf(e)
        };
        self.scale * f
    }

    /// Squared footprint radius.
    pub fn radius2(&self) -> f64 {
        self.r2
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ∫∫ over the disk by polar midpoint sums.
    fn disk_integral(k: &Kernel, radius: f64) -> f64 {
        let n = 4000;
        let dr = radius / n as f64;
        (0..n).map(|i| (i as f64 + 0.5) * dr).map(|r| 2.0 * PI * r * k.density(r * r) * dr).sum()
    }

    #[test]
    fn profiles_integrate_to_one() {
        for p in [
            Profile::Beta { beta: 1.0 },
            Profile::Beta { beta: 2.0 },
            Profile::Beta { beta: 3.7 },
            Profile::Gauss { sigma: 12.0 },
        ] {
            let k = p.kernel(40.0);
            let total = disk_integral(&k, 40.0);
            assert!((total - 1.0).abs() < 1e-4, "{p}: {total}");
        }
    }

    #[test]
    fn line_integrals_match_numeric_quadrature() {
        let radius = 30.0;
        for p in [Profile::Beta { beta: 2.0 }, Profile::Beta { beta: 2.5 }, Profile::Gauss { sigma: 9.0 }] {
            let k = p.kernel(radius);
            for y in [0.0, 5.0, 17.0, 29.0, 31.0] {
                let n = 20000;
                let dx = 2.0 * radius / n as f64;
                let num: f64 =
                    (0..n).map(|i| -radius + (i as f64 + 0.5) * dx).map(|x| k.density(x * x + y * y) * dx).sum();
                let closed = p.line_integral(y, radius);
                assert!((num - closed).abs() < 1e-5 * (1.0 + closed), "{p} y={y}: {num} vs {closed}");
            }
            // The line integrals across all offsets add up to the whole profile.
            let n = 20000;
            let dy = 2.0 * radius / n as f64;
            let total: f64 =
                (0..n).map(|i| -radius + (i as f64 + 0.5) * dy).map(|y| p.line_integral(y, radius) * dy).sum();
            assert!((total - 1.0).abs() < 1e-4, "{p}: {total}");
        }
    }

    #[test]
    fn parses_and_refuses() {
        assert_eq!(Profile::parse("beta:2").unwrap(), Profile::Beta { beta: 2.0 });
        assert_eq!(Profile::parse("gauss:12.5").unwrap(), Profile::Gauss { sigma: 12.5 });
        for bad in ["beta", "beta:x", "beta:0.5", "gauss:-1", "cone:3", "beta:inf"] {
            assert!(Profile::parse(bad).is_err(), "{bad}");
        }
    }
}
