//! The default demo (`cargo run --release`), until the piano action exists: a double
//! pendulum built from an embedded JSON model, integrated with classic RK4 through
//! `mbs_core::System`, once conservative and once with pivot friction, printing the motion
//! and the energy budget so the physics can be checked by eye.

use std::process::ExitCode;

use mbs_core::elements::{FrictionLaw, PivotFriction};
use mbs_core::{Model, System};

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

/// One classic RK4 step of the system's state derivative.
fn rk4_step(
    system: &System,
    ws: &mut mbs_core::Workspace,
    k: &mut [Vec<f64>; 5],
    t: f64,
    x: &mut [f64],
    h: f64,
) -> mbs_core::Result<()> {
    let [k1, k2, k3, k4, y] = k;
    system.derivative(ws, t, x, k1)?;
    y.iter_mut()
        .zip(x.iter())
        .zip(k1.iter())
        .for_each(|((y, x), k)| *y = x + 0.5 * h * k);
    system.derivative(ws, t + 0.5 * h, y, k2)?;
    y.iter_mut()
        .zip(x.iter())
        .zip(k2.iter())
        .for_each(|((y, x), k)| *y = x + 0.5 * h * k);
    system.derivative(ws, t + 0.5 * h, y, k3)?;
    y.iter_mut()
        .zip(x.iter())
        .zip(k3.iter())
        .for_each(|((y, x), k)| *y = x + h * k);
    system.derivative(ws, t + h, y, k4)?;
    for i in 0..x.len() {
        x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
    }
    Ok(())
}

fn simulate(title: &str, system: &System) -> mbs_core::Result<()> {
    let mut ws = system.workspace();
    // Released at rest with both rods horizontal.
    let mut x = system.initial_state(0.0, &[0.0, 0.0], &[0.0, 0.0])?;
    let n = x.len();
    let mut k = [
        vec![0.0; n],
        vec![0.0; n],
        vec![0.0; n],
        vec![0.0; n],
        vec![0.0; n],
    ];
    let e0 = system.energy(&mut ws, 0.0, &x)?.total();
    let lower = system.model().body_id("lower")?;
    println!("\n{title}");
    println!(
        "{:>6} {:>9} {:>9} {:>8} {:>8} {:>9} {:>9} {:>12}",
        "t (s)", "θ1 (deg)", "θ2 (deg)", "tip x", "tip y", "E_kin", "E_pot", "E − E0 (J)"
    );
    let h = 1e-4;
    let steps = 30_000;
    for step in 0..=steps {
        let t = step as f64 * h;
        if step % 2_500 == 0 {
            let e = system.energy(&mut ws, t, &x)?;
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
        if step < steps {
            rk4_step(system, &mut ws, &mut k, t, &mut x, h)?;
        }
    }
    Ok(())
}

fn run() -> mbs_core::Result<()> {
    let model = Model::from_json_str(DOUBLE_PENDULUM)?;
    println!("mbs-core demo: a double pendulum of two 0.5 kg, 0.4 m rods, released horizontal.");
    println!("Classic RK4, h = 0.1 ms. Energies in J, tip position in m (world frame, y up).");
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
