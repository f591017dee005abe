//! Length units of a layup's inputs. towpath computes and writes in millimetres; a surface and
//! the lengths that go with it may be given in other units and are converted on the way in.

use serde::Serialize;

/// A unit of length.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Units {
    /// Millimetres (towpath's own unit).
    #[default]
    Mm,
    /// Inches (25.4 mm).
    In,
    /// Metres.
    M,
    /// Feet (304.8 mm).
    Ft,
}

impl Units {
    /// Every unit, in the order messages list them.
    pub const ALL: [Units; 4] = [Units::Mm, Units::In, Units::M, Units::Ft];

    /// Millimetres in one of this unit.
    pub fn mm(self) -> f64 {
        match self {
            Units::Mm => 1.0,
            Units::In => 25.4,
            Units::M => 1000.0,
            Units::Ft => 304.8,
        }
    }

    /// The unit's symbol (`mm`, `in`, `m`, `ft`).
    pub fn name(self) -> &'static str {
        match self {
            Units::Mm => "mm",
            Units::In => "in",
            Units::M => "m",
            Units::Ft => "ft",
        }
    }

    /// The unit of a symbol (`mm`, `in`, `m`, `ft`; also `inch`, `feet`), if any.
    pub fn parse(s: &str) -> Option<Units> {
        match s.trim().to_ascii_lowercase().as_str() {
            "mm" | "millimetre" | "millimeter" | "millimetres" | "millimeters" => Some(Units::Mm),
            "in" | "inch" | "inches" | "\"" => Some(Units::In),
            "m" | "metre" | "meter" | "metres" | "meters" => Some(Units::M),
            "ft" | "foot" | "feet" | "'" => Some(Units::Ft),
            _ => None,
        }
    }

    /// A length with an optional unit suffix (`0.25in`, `6.35 mm`, `6.35`): the number and its
    /// unit (`None` without a suffix). `None` overall when the text is not such a length.
    pub fn parse_length(text: &str) -> Option<(f64, Option<Units>)> {
        let t = text.trim();
        let split = t.find(|c: char| c.is_ascii_alphabetic() || c == '"' || c == '\'').unwrap_or(t.len());
        let (num, unit) = t.split_at(split);
        // An exponent (`1e-3`) is part of the number, not a unit.
        if let Ok(x) = t.parse::<f64>() {
            return Some((x, None));
        }
        let x: f64 = num.trim().parse().ok()?;
        Some((x, Some(Units::parse(unit)?)))
    }
}

impl std::fmt::Display for Units {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lengths_with_and_without_units() {
        assert_eq!(Units::parse_length("6.35"), Some((6.35, None)));
        assert_eq!(Units::parse_length("1e-3"), Some((1e-3, None)));
        assert_eq!(Units::parse_length("0.25in"), Some((0.25, Some(Units::In))));
        assert_eq!(Units::parse_length("6.35 mm"), Some((6.35, Some(Units::Mm))));
        assert_eq!(Units::parse_length("2ft"), Some((2.0, Some(Units::Ft))));
        assert_eq!(Units::parse_length("2 parsecs"), None);
        assert_eq!(Units::parse_length("in"), None);
        for u in Units::ALL {
            assert_eq!(Units::parse(u.name()), Some(u));
        }
        assert!((Units::In.mm() * 0.25 - 6.35).abs() < 1e-12);
    }
}
