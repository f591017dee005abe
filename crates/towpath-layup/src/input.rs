//! Reading the designer's CSV inputs: curves (guide curves, ply boundaries) as `x,y,z` rows and
//! orientation samples as `x,y,z,dx,dy,dz` rows. Separators: commas, semicolons, tabs or spaces;
//! blank lines and lines starting with `#` are skipped; a first line that is not numeric is taken
//! as a header. Errors name the line and the problem.

use glam::DVec3;

/// A CSV input that could not be read.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("line {line}: {message}")]
pub struct CsvError {
    /// 1-based line number.
    pub line: usize,
    /// What is wrong.
    pub message: String,
}

fn rows(text: &str, width: usize) -> Result<Vec<(usize, Vec<f64>)>, CsvError> {
    let mut out = Vec::new();
    let mut first_data = true;
    for (i, raw) in text.lines().enumerate() {
        let line = raw.trim().trim_start_matches('\u{feff}');
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = line.split([',', ';', '\t', ' ']).map(str::trim).filter(|f| !f.is_empty()).collect();
        let parsed: Result<Vec<f64>, _> = fields.iter().map(|f| f.parse::<f64>()).collect();
        let Ok(vals) = parsed else {
            if first_data && out.is_empty() {
                first_data = false;
                continue; // header
            }
            let bad = fields.iter().find(|f| f.parse::<f64>().is_err()).copied().unwrap_or("");
            return Err(CsvError { line: i + 1, message: format!("'{bad}' is not a number") });
        };
        first_data = false;
        if vals.len() < width {
            return Err(CsvError { line: i + 1, message: format!("expected {width} numbers, found {}", vals.len()) });
        }
        if let Some(v) = vals.iter().find(|v| !v.is_finite()) {
            return Err(CsvError { line: i + 1, message: format!("{v} is not finite") });
        }
        out.push((i + 1, vals));
    }
    Ok(out)
}

/// Reads a curve: one `x,y,z` point per line (extra columns ignored). At least two points.
pub fn read_curve(text: &str) -> Result<Vec<DVec3>, CsvError> {
    let r = rows(text, 3)?;
    if r.len() < 2 {
        return Err(CsvError {
            line: text.lines().count().max(1),
            message: format!("a curve needs at least 2 points, found {}", r.len()),
        });
    }
    Ok(r.into_iter().map(|(_, v)| DVec3::new(v[0], v[1], v[2])).collect())
}

/// Reads orientation samples: `x,y,z,dx,dy,dz` per line; the direction must not be zero.
pub fn read_orientations(text: &str) -> Result<Vec<(DVec3, DVec3)>, CsvError> {
    let r = rows(text, 6)?;
    if r.is_empty() {
        return Err(CsvError { line: 1, message: "no orientation samples".into() });
    }
    let mut out = Vec::with_capacity(r.len());
    for (line, v) in r {
        let d = DVec3::new(v[3], v[4], v[5]);
        if d.length() == 0.0 {
            return Err(CsvError { line, message: "the direction (dx, dy, dz) is zero".into() });
        }
        out.push((DVec3::new(v[0], v[1], v[2]), d));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_with_header_comments_and_separators() {
        let c = read_curve("x,y,z\n# a comment\n0,0,0\n1;2;3\n\n4 5\t6\n").unwrap();
        assert_eq!(c, vec![DVec3::ZERO, DVec3::new(1.0, 2.0, 3.0), DVec3::new(4.0, 5.0, 6.0)]);
    }

    #[test]
    fn errors_name_the_line() {
        let e = read_curve("0,0,0\n1,2\n").unwrap_err();
        assert_eq!(e.line, 2);
        let e = read_curve("0,0,0\n1,2,x\n").unwrap_err();
        assert_eq!((e.line, e.message.as_str()), (2, "'x' is not a number"));
        assert!(read_curve("0,0,0\n").is_err());
        assert!(read_orientations("0,0,0,0,0,0\n").is_err());
        assert!(read_curve("0,0,0\n1,1,inf\n").is_err());
    }
}
