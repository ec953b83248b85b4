//! The reduced swing model of `piano diagnose` against the multibody swing test, and its
//! Coulomb sticking.

use piano_action::identify::effects::FlangeEffects;
use piano_action::identify::swing_model::SwingModel;
use piano_action::params::ActionParams;
use piano_action::pendulum::{hanging_shank_angle_rad, swing};

/// The one-coordinate model and the `mbs-core` swing (regularised friction, tight
/// tolerances) turn at the same times and angles while the hammer swings freely.
#[test]
fn reduced_swing_matches_the_multibody_swing() {
    let mut params = ActionParams::reference();
    // Near-true Coulomb friction in the multibody model: a narrow tanh.
    params.numerics.pivot_friction_regularization_rad_s = 1e-5;
    let release_from_hanging = 60.0;
    let full = swing(&params, release_from_hanging, 1.5).expect("multibody swing");
    let hanging = hanging_shank_angle_rad(&params);
    let model = SwingModel::from_params(&params, FlangeEffects::default());
    let path = model.simulate(hanging + release_from_hanging.to_radians(), 1.5);
    assert!(full.turns.len() >= 3, "{} turns", full.turns.len());
    for (k, turn) in full.turns.iter().take(4).enumerate() {
        let (t, phi) = path.reversals[k];
        assert!(
            (t - turn.time_s).abs() < 2e-5,
            "turn {k}: reduced {t} s, multibody {} s",
            turn.time_s
        );
        assert!(
            (phi - hanging - turn.angle_rad).abs() < 1e-6,
            "turn {k}: reduced {} rad, multibody {} rad",
            phi - hanging,
            turn.angle_rad
        );
    }
    // Between turns, the interpolated angle follows the sampled one.
    for (t, a) in full.t.iter().zip(&full.angle_rad).step_by(37) {
        assert!((path.angle(*t) - hanging - a).abs() < 1e-6, "t = {t}");
    }
}

/// Coulomb friction takes a constant amount of amplitude per half swing, 2 T_c / (m g d)
/// for small swings, and the hammer sticks within the static friction for good.
#[test]
fn coulomb_swing_decays_linearly_and_sticks() {
    let params = ActionParams::reference();
    let model = SwingModel::from_params(&params, FlangeEffects::default());
    let hanging = hanging_shank_angle_rad(&params);
    let path = model.simulate(hanging + 0.3, 6.0);
    let k = model.gravity_torque(hanging - 1e-3).abs() / 1e-3;
    let loss = 2.0 * model.coulomb_n_m / k;
    let amps: Vec<f64> = path
        .reversals
        .iter()
        .map(|r| (r.1 - hanging).abs())
        .collect();
    let mut prev = 0.3;
    for a in &amps[..amps.len() - 1] {
        assert!(
            ((prev - a) / loss - 1.0).abs() < 0.02,
            "loss {} vs {loss}",
            prev - a
        );
        prev = *a;
    }
    let (t_stop, phi_stop) = path.stuck.expect("the hammer stops");
    assert!(t_stop < 6.0);
    assert!(model.gravity_torque(phi_stop).abs() <= model.static_friction_n_m());
    assert_eq!(path.angle(t_stop + 1.0), phi_stop);
    assert_eq!(path.angle(5.9), phi_stop);
}
