//! The scene `three-ports` (`trocar_sim::scene`): with its couplings every pair of shafts keeps
//! its safety distance at every row (measured from forward kinematics), every port holds and
//! every joint keeps its URDF range; without them the instruments' shafts come closer than the
//! safety distance, so the scene tests what the couplings do.

use trocar_sim::closed_chain::MechanismTrace;
use trocar_sim::scene::{safety, simulate, view_tolerance, ARMS};

fn column(trace: &MechanismTrace, name: &str) -> Vec<f64> {
    trace
        .column(name)
        .unwrap_or_else(|| panic!("column {name}"))
}

#[test]
fn three_ports_keeps_the_shafts_apart_and_the_ports_held() {
    let coupled = simulate("three-ports", true, |_| {}).unwrap();
    let free = simulate("three-ports", false, |_| {}).unwrap();
    let min = |t: &MechanismTrace| {
        column(t, "min_shaft_distance")
            .into_iter()
            .fold(f64::INFINITY, f64::min)
    };
    let (with, without) = (min(&coupled), min(&free));
    let active = column(&coupled, "coupling_active")
        .iter()
        .filter(|v| **v > 0.0)
        .count();
    let drift = ARMS
        .iter()
        .flat_map(|a| column(&coupled, &format!("{a}.rcm_drift")))
        .fold(0.0, f64::max);
    let tip = column(&coupled, "left.ep_norm");
    // The endoscope's camera keeps the instruments' midpoint on its view axis.
    let view = column(&coupled, "endoscope.view_error")
        .into_iter()
        .fold(0.0, f64::max);
    assert!(view <= view_tolerance().unwrap(), "view error {view} rad");
    println!(
        "min shaft distance {with:.3e} m coupled ({active} rows active), {without:.3e} m without; \
         max drift {drift:.2e} m; view error {view:.2e} rad; left tip error at the end {:.2e} m",
        tip.last().unwrap()
    );
    // The scene file's safety distance: 10 mm between the axes.
    let safety = safety("three-ports").unwrap();
    assert_eq!(safety, 0.010);
    assert!(without < safety, "without the couplings: {without} m");
    assert!(
        with >= safety * (1.0 - 1e-6),
        "with the couplings: {with} m"
    );
    assert!(active > 0);
    assert!(drift <= 1e-4, "drift {drift} m");
    // 21 joints and their rates, in the scene's order.
    assert_eq!(coupled.columns[1], "q1");
    assert_eq!(coupled.columns[43], "left.rcm_drift");
    // Every joint within the Panda's URDF ranges.
    let d = trocar_model::description::RobotDescription::preset("panda-laparoscope").unwrap();
    for k in 0..21 {
        let [lo, hi] = d.joints[k % 7].limits.unwrap();
        for v in column(&coupled, &format!("q{}", k + 1)) {
            assert!(v >= lo && v <= hi, "q{} = {v}", k + 1);
        }
    }
}

#[test]
fn an_unknown_scene_is_named() {
    let e = simulate("four-ports", true, |_| {}).unwrap_err();
    assert!(e.to_string().contains("unknown scene `four-ports`"), "{e}");
}

/// The drawn scene (`scene::geometry`) is the run's: at every 50th row each arm's drawn shaft
/// passes its port at the distance the trace measured as its drift, for both scenes (the
/// torso of `dia10-dual` in both arms).
#[test]
fn the_drawn_scene_is_the_run() {
    for name in trocar_sim::scene::scenario_names() {
        let trace = simulate(name, true, |_| {}).unwrap();
        let geometry = trocar_sim::scene::geometry(name).unwrap();
        for arm in &geometry.arms {
            let drift = column(&trace, &format!("{}.rcm_drift", arm.name));
            for (k, row) in trace.rows.iter().enumerate().step_by(50) {
                let pose = arm.pose(row);
                let off = (pose.trocar - arm.port_in_scene()).norm();
                assert!(
                    (off - drift[k]).abs() < 1e-9,
                    "{name} {} row {k}: drawn {off}, measured {}",
                    arm.name,
                    drift[k]
                );
            }
        }
    }
}
