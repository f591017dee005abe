//! Bad input to the library is refused with a clear error, never a panic.

mod common;

use common::*;
use towpath_geom::{BuildOptions, Mesh, Soup};
use towpath_spray::{plan, Profile, SprayError};

#[test]
fn bad_parameters_and_meshes_are_refused() {
    let mesh = analytic("plane:a=200,b=100", 200);
    let check = |f: &dyn Fn(&mut towpath_spray::SprayParams), needle: &str| {
        let mut p = params(20.0);
        f(&mut p);
        let e = plan(&mesh, &p).expect_err(needle);
        assert!(e.to_string().contains(needle), "expected '{needle}' in: {e}");
    };
    check(&|p| p.gun.radius = 0.0, "spray radius");
    check(&|p| p.gun.standoff = 0.0, "standoff");
    check(&|p| p.gun.standoff = -1.0, "standoff");
    check(&|p| p.gun.standoff = f64::NAN, "standoff");
    check(&|p| p.target_thickness = 0.0, "target thickness");
    check(&|p| p.target_thickness = -2.0, "target thickness");
    check(&|p| p.gun.flow = 0.0, "flow");
    check(&|p| p.gun.profile = Profile::Beta { beta: 0.5 }, "β");
    check(&|p| p.spacing = Some(500.0), "spacing");
    check(&|p| p.max_deviation_deg = 95.0, "deviation");
    check(&|p| p.max_speed_change = 0.5, "speed change");
    check(&|p| p.max_speed_change = f64::INFINITY, "speed change");
    // An empty mesh and a mesh whose only triangle has no area.
    // (The mesh builder may refuse them first; either way there is an error, not a panic.)
    let refuse = |soup: &Soup| match Mesh::build(soup, &BuildOptions::default()) {
        Ok((m, _)) => assert_eq!(plan(&m, &params(20.0)).unwrap_err(), SprayError::NoArea),
        Err(e) => assert!(!e.to_string().is_empty()),
    };
    refuse(&Soup { positions: Vec::new(), triangles: Vec::new() });
    let flat = Soup {
        positions: vec![[0.0, 0.0, 0.0].into(), [1.0, 1.0, 1.0].into(), [2.0, 2.0, 2.0].into()],
        triangles: vec![[0, 1, 2]],
    };
    refuse(&flat);
}
