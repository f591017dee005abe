use std::time::{Duration, Instant};
use towpath_nc::demo::*;
use towpath_nc::*;
fn main() {
    let plies: usize = std::env::args().nth(1).map_or(100, |s| s.parse().unwrap());
    let courses: usize = std::env::args().nth(2).map_or(100, |s| s.parse().unwrap());
    let tl: f64 = std::env::args().nth(3).map_or(3.0, |s| s.parse().unwrap());
    let t = Instant::now();
    let text = stacked_panel(plies, courses);
    eprintln!("generated {} lines in {:.2}s", text.lines().count(), t.elapsed().as_secs_f64());
    let d = Dialect::default();
    let m = gantry();
    let opts = OptimizeOptions {
        afp: AfpOptions { bidirectional: true, width: Some(Width::Tow(TOW_WIDTH)), ..Default::default() },
        time_limit: Some(Duration::from_secs_f64(tl)),
        ..Default::default()
    };
    let o = optimize(&text, &m, &d, &opts).unwrap();
    let (b, a) = o.verification.motion(towpath_machine::CostKind::Axis).unwrap();
    eprintln!(
        "courses {} edges {} sets {} timings {:?}",
        o.program.courses.len(),
        o.afp.edges,
        o.afp.sets.len(),
        o.timings
    );
    eprintln!(
        "off {:.0} -> {:.0} ({:.1}%) solver {:?}",
        b.off_part(),
        a.off_part(),
        100.0 * (1.0 - a.off_part() / b.off_part()),
        o.solver
    );
}
