//! `cargo run --release --example double_pendulum`: a double
//! pendulum built from an embedded JSON model, integrated with Dormand–Prince 5(4) from
//! `mbs-integrators`, once conservative and once with pivot friction, printing the motion
//! and the energy budget so the physics can be checked by eye.

use std::process::ExitCode;

use mbs_core::elements::{FrictionLaw, PivotFriction};
use mbs_core::{Model, System};
use mbs_integrators::{Method, MultibodyOde, Options, solve};

/// Two 0.5 kg, 0.4 m rods (inertia m l²/12 about their centres) hanging from the ground.
const DOUBLE_PENDULUM: &str = r#"{
  "gravity": [0.0, -9.81],
  "joints": [
    {"name": "upper", "parent": null, "kind": "revolute",
     "placement": {"angle": 0.0, "x": 0.0, "y": 0.0},
     "body": {"mass": 0.5, "com": [0.2, 0.0], "inertia": 0.006666666666666667}},
    {"name": "lower", "parent": "upper", "kind": "revolute",
     "placement": {"angle": 0.0, "x": 0.4, "y": 0.0},
     "body": {"mass": 0.5, "com": [0.2, 0.0], "inertia": 0.006666666666666667}}
  ]
}"#;

fn simulate(title: &str, system: &System) -> Result<(), Box<dyn std::error::Error>> {
    let mut ws = system.workspace();
    // Released at rest with both rods horizontal.
    let x0 = system.initial_state(0.0, &[0.0, 0.0], &[0.0, 0.0])?;
    let e0 = system.energy(&mut ws, 0.0, &x0)?.total();
    let lower = system.model().body_id("lower")?;
    // Dormand–Prince 5(4) at tight tolerance, reported every 0.25 s.
    let opts = Options::with_tolerances(1e-10, 1e-12).output_every(0.25);
    let mut ode = MultibodyOde::new(system);
    let sol = solve(&mut ode, Method::DormandPrince54, 0.0, &x0, 3.0, &opts)?;
    println!("\n{title}");
    println!(
        "{:>6} {:>9} {:>9} {:>8} {:>8} {:>9} {:>9} {:>12}",
        "t (s)", "θ1 (deg)", "θ2 (deg)", "tip x", "tip y", "E_kin", "E_pot", "E − E0 (J)"
    );
    for i in 0..sol.len() {
        let (t, x) = (sol.t[i], sol.state(i));
        let e = system.energy(&mut ws, t, x)?;
        let tip = mbs_core::point_position(ws.data(), lower, [0.4, 0.0]);
        println!(
            "{:>6.2} {:>9.2} {:>9.2} {:>8.3} {:>8.3} {:>9.5} {:>9.5} {:>12.3e}",
            t,
            x[0].to_degrees(),
            x[1].to_degrees(),
            tip[0],
            tip[1],
            e.kinetic,
            e.gravity,
            e.total() - e0
        );
    }
    let s = sol.stats;
    println!(
        "({} steps, {} rejected, {} derivative evaluations)",
        s.steps, s.rejected, s.derivative_evals
    );
    Ok(())
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let model = Model::from_json_str(DOUBLE_PENDULUM)?;
    println!("mbs-core demo: a double pendulum of two 0.5 kg, 0.4 m rods, released horizontal.");
    println!("Dormand–Prince 5(4), rtol 1e-10. Energies in J, tip position in m (world, y up).");
    let conservative = System::new(model.clone());
    simulate(
        "Frictionless: the total energy stays constant (E − E0 is integration error).",
        &conservative,
    )?;
    let mut rubbing = System::new(model.clone());
    for joint in ["upper", "lower"] {
        let law = FrictionLaw::coulomb(0.005, 1e-3).with_viscous(0.0005);
        rubbing.add_element(PivotFriction::new(&model, joint, law)?)?;
    }
    simulate(
        "With 5 mN·m Coulomb + viscous friction at each pivot: energy drains away.",
        &rubbing,
    )?;
    println!(
        "\nNext: `cargo run --release -p mbs-core --example inspect -- MODEL.json STATES.json`"
    );
    println!("evaluates any model's mass matrix, RNEA and ABA for comparison with another engine.");
    Ok(())
}

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
