//! Helpers every benchmark shares: the median, time formats, the process's CPU time, a line
//! describing the machine, and replacing a section of a Markdown file.

/// The median of the values (mean of the middle two for an even count; NaN if there are none).
pub fn median(v: &[f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let k = s.len();
    if k % 2 == 1 {
        s[k / 2]
    } else {
        0.5 * (s[k / 2 - 1] + s[k / 2])
    }
}

/// Seconds as a number of milliseconds, with a precision that suits the value (for tables whose
/// header says "ms").
pub fn ms(seconds: f64) -> String {
    let m = seconds * 1e3;
    if m < 1.0 {
        format!("{m:.2}")
    } else if m < 100.0 {
        format!("{m:.1}")
    } else {
        format!("{m:.0}")
    }
}

/// Seconds as milliseconds or seconds, whichever reads better, with the unit.
pub fn duration(seconds: f64) -> String {
    if seconds < 0.1 {
        format!("{:.1} ms", seconds * 1e3)
    } else {
        format!("{seconds:.2} s")
    }
}

/// CPU time (user + system) of this process so far, seconds, from `/proc/self/stat` (Linux;
/// NaN elsewhere).
pub fn cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else { return f64::NAN };
    let after = stat.rsplit_once(')').map_or("", |x| x.1);
    let f: Vec<&str> = after.split_whitespace().collect();
    // Fields 14 and 15 of stat are utime and stime; after the command name they are 12 and 13.
    let ticks = |i: usize| f.get(i).and_then(|x| x.parse::<f64>().ok()).unwrap_or(f64::NAN);
    (ticks(11) + ticks(12)) / 100.0
}

/// A one-line description of the machine for a table's caption: `TOWPATH_BENCH_MACHINE` if set
/// (say the CPU there), and the cores this process may use.
pub fn machine() -> String {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    match std::env::var("TOWPATH_BENCH_MACHINE") {
        Ok(m) if !m.trim().is_empty() => format!("{}, {cores} cores visible", m.trim()),
        _ => format!("{cores} cores visible"),
    }
}

/// Replaces the section of `doc` that starts with `heading` (up to the next `## ` heading) by
/// `section`, or appends it (after a `# Benchmarks` title if `doc` is empty).
pub fn replace_section(doc: &str, heading: &str, section: &str) -> String {
    let body = section.trim_end();
    let Some(start) = doc.find(heading) else {
        let pre = doc.trim_end();
        let pre = if pre.is_empty() { "# Benchmarks".to_string() } else { pre.to_string() };
        return format!("{pre}\n\n{body}\n");
    };
    let after = start + heading.len();
    match doc.get(after..).and_then(|rest| rest.find("\n## ")) {
        Some(k) => format!("{}{body}\n\n{}", &doc[..start], &doc[after + k + 1..]),
        None => format!("{}{body}\n", &doc[..start]),
    }
}

/// Writes `section` into the Markdown file `path` (see [`replace_section`]).
pub fn write_section(path: &std::path::Path, heading: &str, section: &str) -> anyhow::Result<()> {
    use anyhow::Context;
    let old = match std::fs::read_to_string(path) {
        Ok(s) => s,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => String::new(),
        Err(e) => return Err(e).with_context(|| format!("reading {}", path.display())),
    };
    std::fs::write(path, replace_section(&old, heading, section))
        .with_context(|| format!("writing {}", path.display()))?;
    eprintln!("tables written to {}", path.display());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sections_are_replaced_or_appended() {
        let h = "## Seed baselines";
        let sec = format!("{h}\n\nnew\n\n");
        assert_eq!(replace_section("", h, &sec), format!("# Benchmarks\n\n{h}\n\nnew\n"));
        let old = format!("# B\n\n## Other\n\nx\n\n{h}\n\nold\n\n## Later\n\ny\n");
        assert_eq!(replace_section(&old, h, &sec), format!("# B\n\n## Other\n\nx\n\n{h}\n\nnew\n\n## Later\n\ny\n"));
        let old = format!("# B\n\n{h}\n\nold\n");
        assert_eq!(replace_section(&old, h, &sec), format!("# B\n\n{h}\n\nnew\n"));
        let old = "# B\n\n## Other\n\nx\n";
        assert_eq!(replace_section(old, h, &sec), format!("# B\n\n## Other\n\nx\n\n{h}\n\nnew\n"));
    }

    #[test]
    fn medians_against_sorting_by_hand() {
        assert!(median(&[]).is_nan());
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
        assert_eq!(median(&[5.0]), 5.0);
    }
}
