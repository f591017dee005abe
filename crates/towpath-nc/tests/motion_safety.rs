//! Motion safety of whole programs: the demo parts in a cell (a planar tool with a stringer
//! and a clamp; a mandrel with a flange), optimized with transits planned against the cell,
//! checked move by move, and a program edited to clip an obstacle caught.

use std::sync::Arc;

use towpath_geom::DVec3;
use towpath_machine::Machine;
use towpath_motion::Cell;
use towpath_nc::demo::{demo_parts, DemoPart};
use towpath_nc::{
    check_cell_under_path, check_program, optimize, parse, Dialect, NcError, OptimizeOptions, Safety, SafetyOptions,
};

fn part(name: &str) -> DemoPart {
    demo_parts().into_iter().find(|p| p.name == name).expect("demo part")
}

fn dialect() -> Dialect {
    Dialect { tow_width: Some(towpath_nc::demo::TOW_WIDTH), ..Dialect::default() }
}

fn cell_of(p: &DemoPart) -> Arc<Cell> {
    let tris = p.obstacles.iter().flat_map(|o| o.triangles.iter().map(|t| t.map(DVec3::from_array))).collect();
    Arc::new(Cell::from_triangles(tris))
}

fn safety(p: &DemoPart) -> Safety {
    Safety::new(&p.machine, &dialect(), cell_of(p), SafetyOptions::default()).unwrap()
}

/// A fixed work budget: the result depends only on the inputs.
fn opts(safety: Option<Safety>) -> OptimizeOptions {
    OptimizeOptions {
        afp: towpath_nc::AfpOptions { bidirectional: true, ..towpath_nc::AfpOptions::default() },
        time_limit: None,
        iterations: Some(2000),
        threads: 1,
        safety,
        ..OptimizeOptions::default()
    }
}

/// The value of an axis word on a line, if the line has one.
fn word(line: &str, letter: char) -> Option<f64> {
    line.split_whitespace().find_map(|w| w.strip_prefix(letter).and_then(|v| v.parse().ok()))
}

/// Rapid moves that lift above the program's 25 mm standoff (the header's and footer's Z100
/// aside): the levels of lifted transits, with their lines.
fn lifted_levels(text: &str, axis: char, standoff: f64, home: f64) -> Vec<(usize, f64)> {
    text.lines()
        .enumerate()
        .filter(|(_, l)| l.starts_with("G0"))
        .filter_map(|(i, l)| word(l, axis).map(|z| (i + 1, z)))
        .filter(|&(_, z)| z > standoff + 1e-6 && (z - home).abs() > 1e-6)
        .collect()
}

#[test]
fn the_stringer_part_collides_as_written_and_is_safe_optimized() {
    let p = part("planar-stringer");
    let s = safety(&p);
    let d = dialect();
    let input = parse(&p.program, &p.machine, &d).unwrap();
    let before = check_program(&input, &s);
    assert!(!before.collisions.is_empty(), "the input's transits cross the stringer: {}", before.summary());
    // Every collision of the input is a transit at the standoff crossing the stringer (x 575–625).
    for c in &before.collisions {
        assert!(c.at[0] > 570.0 && c.at[0] < 630.0, "{c:?}");
    }

    let o = optimize(&p.program, &p.machine, &d, &opts(Some(s.clone()))).unwrap();
    let pair = o.safety.as_ref().unwrap();
    assert_eq!(pair.before, before);
    assert!(pair.after.is_safe() && pair.after.near_misses.is_empty(), "{}", pair.after.summary());
    // Checked again from the text alone.
    let after = check_program(&parse(&o.text, &p.machine, &d).unwrap(), &s);
    assert!(after.collisions.is_empty() && after.near_misses.is_empty(), "{}", after.summary());

    // Lifted transits go over the 60 mm stringer at the least level that keeps the 5 mm
    // clearance, to within the planner's 1 mm step: 65 ≤ Z ≤ 66.
    let lifted = lifted_levels(&o.text, 'Z', 25.0, 100.0);
    assert!(!lifted.is_empty());
    for &(line, z) in &lifted {
        assert!((65.0..=66.0 + 1e-6).contains(&z), "line {line}: lifted to Z{z}");
    }
    // And only transits that cross the stringer are lifted: one up move to the level each (the
    // across move keeps Z and does not write it; the down move goes back to the standoff).
    let courses: Vec<&towpath_nc::Course> = o.order.iter().map(|pl| &o.program.courses[pl.course]).collect();
    let side = |x: f64| x > 600.0;
    let mut crossings = 0;
    for (w, pl) in courses.windows(2).zip(o.order.windows(2)) {
        let (a, b) = (w[0], w[1]);
        // Where the tool leaves course a and where it enters course b (reversed courses swap
        // their ends).
        let exit_x = if pl[0].reversed { a.span_start.phys[0] } else { a.exit.phys[0] };
        let entry_x = if pl[1].reversed { b.exit.phys[0] } else { b.insert.phys[0] };
        crossings += usize::from(side(exit_x) != side(entry_x));
    }
    assert!(crossings >= 1);
    assert_eq!(lifted.len(), crossings, "{lifted:?}");
}

#[test]
fn around_the_mandrel_transits_lift_radially_over_the_flange() {
    let p = part("cylinder-flange");
    let s = safety(&p);
    let d = dialect();
    let before = check_program(&parse(&p.program, &p.machine, &d).unwrap(), &s);
    assert!(!before.collisions.is_empty(), "{}", before.summary());
    let o = optimize(&p.program, &p.machine, &d, &opts(Some(s.clone()))).unwrap();
    let after = check_program(&parse(&o.text, &p.machine, &d).unwrap(), &s);
    assert!(after.collisions.is_empty() && after.near_misses.is_empty(), "{}", after.summary());
    // The lift is the radial axis Z: the flange's rim (radius 470, facets just inside it) plus
    // the 5 mm clearance, within the 1 mm step.
    let lifted = lifted_levels(&o.text, 'Z', 425.0, 500.0);
    assert!(!lifted.is_empty());
    for &(line, z) in &lifted {
        assert!((474.0..=476.0 + 1e-6).contains(&z), "line {line}: lifted to radius {z}");
    }
}

#[test]
fn a_program_edited_to_clip_an_obstacle_is_caught_at_its_line() {
    let p = part("planar-stringer");
    let s = safety(&p);
    let d = dialect();
    let o = optimize(&p.program, &p.machine, &d, &opts(Some(s.clone()))).unwrap();
    // Lower the up move of a lifted transit to 50 mm, below the stringer's 60 mm top: the
    // across move after it then runs through the stringer.
    let (line, _) = lifted_levels(&o.text, 'Z', 25.0, 100.0)[0];
    let edited: Vec<String> = o
        .text
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if i + 1 == line {
                l.split_whitespace()
                    .map(|w| if w.starts_with('Z') { "Z50".to_string() } else { w.to_string() })
                    .collect::<Vec<_>>()
                    .join(" ")
            } else {
                l.to_string()
            }
        })
        .collect();
    let edited = edited.join("\n") + "\n";
    let r = check_program(&parse(&edited, &p.machine, &d).unwrap(), &s);
    assert!(!r.is_safe());
    assert_eq!(r.collisions.len(), 1, "{:?}", r.collisions);
    let c = &r.collisions[0];
    assert_eq!(c.line, line + 1, "{c:?}");
    assert!(c.at[0] >= 575.0 && c.at[0] <= 625.0 && (c.at[2] - 50.0).abs() < 1e-9, "{c:?}");
}

#[test]
fn a_mold_that_is_not_under_the_laid_path_is_refused() {
    let p = part("planar-stringer");
    let d = dialect();
    // The tool 200 mm below the part (a wrong frame).
    let tris = towpath_nc::demo::plate_mesh([-100.0, 1300.0], [-100.0, 900.0], -200.0);
    let cell = Arc::new(Cell::from_triangles(tris.iter().map(|t| t.map(DVec3::from_array)).collect()));
    let s = Safety::new(&p.machine, &d, cell, SafetyOptions::default()).unwrap();
    let e = check_cell_under_path(&parse(&p.program, &p.machine, &d).unwrap(), &p.machine, &s, towpath_nc::MOLD_GAP)
        .unwrap_err();
    assert!(e.to_string().contains("the mold does not lie under the laid path"), "{e}");
    let e = optimize(&p.program, &p.machine, &d, &opts(Some(s))).unwrap_err();
    assert!(e.to_string().contains("does not lie under"), "{e}");
}

#[test]
fn bad_clearances_are_refused() {
    let p = part("planar-stringer");
    for c in [0.0, -1.0, f64::NAN, f64::INFINITY, 1e9] {
        let e =
            Safety::new(&p.machine, &dialect(), cell_of(&p), SafetyOptions { clearance: c, step: 1.0 }).unwrap_err();
        assert!(matches!(e, NcError::Request(_)), "{c}: {e}");
    }
}

/// A machine with limits that the input keeps but a transit lifted over the stringer would
/// leave: no level within the limits clears, so the optimizer refuses rather than writing an
/// unsafe program.
#[test]
fn no_safe_transit_within_the_travel_limits_is_refused() {
    let p = part("planar-stringer");
    let mut m: Machine = p.machine.clone();
    let z = m.axis_index("Z").unwrap();
    m.axes[z].max = Some(40.0);
    // The demo's header and footer go to Z100: bring them within the limit.
    let program = p.program.replace("G0 Z100", "G0 Z30");
    let s = Safety::new(&m, &dialect(), cell_of(&p), SafetyOptions::default()).unwrap();
    // A small work budget: every kick of an infeasible search runs its descent to the end.
    let e = optimize(&program, &m, &dialect(), &OptimizeOptions { iterations: Some(50), ..opts(Some(s)) }).unwrap_err();
    assert!(matches!(e, NcError::Unsafe(_)), "{e}");
    assert!(e.to_string().contains("can be made safe (a clearance of 5 mm within the travel limits)"), "{e}");
}

#[test]
fn laid_points_on_the_mandrel_axis_are_refused() {
    let p = part("cylinder-flange");
    let d = dialect();
    // The mandrel axis moved 400 mm, onto the surface the program lays on.
    let mut m = p.machine.clone();
    let a = m.axis_index("A").unwrap();
    m.axes[a].origin = Some([0.0, 0.0, 400.0]);
    let s = Safety::new(&m, &d, cell_of(&p), SafetyOptions::default()).unwrap();
    let program = parse(&p.program, &m, &d).unwrap();
    let e = check_cell_under_path(&program, &m, &s, towpath_nc::MOLD_GAP).unwrap_err();
    assert!(e.to_string().contains("from the mandrel axis (at least 1 mm needed)"), "{e}");
}

#[test]
fn a_course_laid_outside_the_travel_limits_is_refused() {
    let p = part("planar-45");
    let mut m = p.machine.clone();
    let x = m.axis_index("X").unwrap();
    m.axes[x].max = Some(1000.0);
    let e = optimize(&p.program, &m, &dialect(), &opts(None)).unwrap_err();
    let text = e.to_string();
    assert!(matches!(e, NcError::Line { .. }), "{e}");
    assert!(
        text.contains("is laid outside the travel limits: axis X at") && text.contains("outside [none, 1000]"),
        "{e}"
    );
}

/// The machine file's `[head]` capsule is checked like the tool point: a head 30 mm in radius
/// standing over the last course before the stringer reaches into it, which the tool point
/// alone never does, and the optimizer will not write such a program.
#[test]
fn the_head_of_the_machine_file_is_checked_too() {
    let p = part("planar-stringer");
    let d = dialect();
    let mut m = p.machine.clone();
    m.head = Some(towpath_machine::Head { radius: 30.0, bottom: 30.0, top: 225.0 });
    m.validate().unwrap();
    let s = Safety::new(&m, &d, cell_of(&p), SafetyOptions::default()).unwrap();
    let r = check_program(&parse(&p.program, &m, &d).unwrap(), &s);
    let head: Vec<_> = r.collisions.iter().filter(|c| c.body == "head").collect();
    assert!(!head.is_empty(), "{}", r.summary());
    // Without the head, the same program's only collisions are its two transits through the stringer.
    let bare = check_program(&parse(&p.program, &p.machine, &d).unwrap(), &safety(&p));
    assert!(bare.collisions.iter().all(|c| c.body == "tool") && bare.collisions.len() < r.collisions.len());
    let e = optimize(&p.program, &m, &d, &OptimizeOptions { iterations: Some(50), ..opts(Some(s)) }).unwrap_err();
    assert!(matches!(e, NcError::Unsafe(_)), "{e}");
}
