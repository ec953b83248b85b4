//! The example scenarios shipped in `piano-action/scenarios/` all run and do what their
//! comments say.

use std::path::PathBuf;

use piano_action::ActionParams;
use piano_action::scenario::{InputSpec, PendulumSpec, Scenario};

fn dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenarios")
}

#[test]
fn every_example_scenario_runs() {
    let params = ActionParams::reference();
    let mut names = Vec::new();
    for entry in std::fs::read_dir(dir()).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "toml") {
            continue;
        }
        let name = path.file_stem().unwrap().to_string_lossy().into_owned();
        let scenario = Scenario::load(&path).unwrap();
        if let InputSpec::Pendulum(PendulumSpec { release_angle_deg }) = scenario.input {
            let swing =
                piano_action::pendulum::swing(&params, release_angle_deg, scenario.duration_s)
                    .unwrap();
            assert!(swing.turns.len() >= 2, "{name}: {:?}", swing.turns);
            names.push(name);
            continue;
        }
        let run = scenario.run(&params).unwrap();
        let speeds: Vec<f64> = run.strikes.iter().map(|s| s.hammer_velocity_m_s).collect();
        let has = |event: &str| run.events.iter().any(|e| e.name == event);
        eprintln!("{name}: {speeds:?}");
        assert!(!speeds.is_empty(), "{name}: no strike");
        match name.as_str() {
            "repeated_notes" => assert_eq!(speeds.len(), 2, "{name}: {speeds:?}"),
            "struck_forte" => assert!(speeds[0] > 4.0, "{name}: {speeds:?}"),
            "pressed_piano" => assert!(speeds[0] < 1.2, "{name}: {speeds:?}"),
            "force_ramp_release" => {
                assert!(
                    has("check_catch") && has("key_lift") && has("jack_reset"),
                    "{name}"
                )
            }
            "mass_drop_1kg" => assert!(run.check_time_s.is_some(), "{name}"),
            "key_motion_csv" => {
                assert_eq!(speeds.len(), 1, "{name}: {speeds:?}");
                assert!(run.key_drive_force_n.iter().any(|&f| f > 1.0), "{name}");
            }
            _ => {}
        }
        names.push(name);
    }
    names.sort();
    assert_eq!(
        names,
        [
            "force_ramp_release",
            "key_motion_csv",
            "mass_drop_1kg",
            "pendulum",
            "pressed_piano",
            "repeated_notes",
            "struck_forte"
        ]
    );
}
