//! The pendulum (swing) test of the hammer on its flange: period from inertia and centre of
//! mass, decay from flange friction.

use std::f64::consts::PI;

use piano_action::ActionParams;
use piano_action::pendulum::swing;

const G: f64 = piano_action::params::GRAVITY_M_S2;

/// Arithmetic–geometric mean (exact large-amplitude pendulum period: T = T0 / AGM(1, cos θ/2)).
fn agm(mut a: f64, mut b: f64) -> f64 {
    for _ in 0..40 {
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
    }
    a
}

#[test]
fn the_swing_period_follows_from_inertia_and_centre_of_mass() {
    // Nearly frictionless flange, so the amplitude barely changes.
    let mut p = ActionParams::reference();
    p.hammer.pivot_friction_n_m = 1e-6;
    let s = swing(&p, 20.0, 2.0).unwrap();
    let m = p.hammer.mass_g * 1e-3;
    let t0 = 2.0 * PI * (s.inertia_pin_kg_m2 / (m * G * s.com_distance_m)).sqrt();
    let exact = t0 / agm(1.0, (10f64.to_radians()).cos());
    assert!(s.turns.len() >= 4, "{:?}", s.turns);
    // Successive turning points are half a period apart.
    for w in s.turns.windows(2) {
        let half = w[1].time_s - w[0].time_s;
        assert!(
            (half - 0.5 * exact).abs() < 1e-3 * exact,
            "half period {half} vs {}",
            0.5 * exact
        );
    }
    // The reference hammer swings with a period of about 0.72 s.
    assert!((0.70..0.74).contains(&t0), "T0 = {t0}");
}

#[test]
fn the_swing_decays_as_coulomb_flange_friction_predicts() {
    // Between turning points θ1 and θ2 the potential energy lost equals the work of the
    // Coulomb torque T_f over the arc: m g d (cos θ2 − cos θ1) = T_f (θ1 + θ2). For small
    // swings this takes 2 T_f / (m g d) off the amplitude every half swing.
    let p = ActionParams::reference();
    let s = swing(&p, 60.0, 3.0).unwrap();
    let m = p.hammer.mass_g * 1e-3;
    let tf = p.hammer.pivot_friction_n_m;
    let mgd = m * G * s.com_distance_m;
    let loss = 2.0 * tf / mgd;
    let mut amplitudes = vec![60f64.to_radians()];
    amplitudes.extend(s.turns.iter().map(|t| t.angle_rad.abs()));
    // Only the swings that clearly moved (the last turn may be where it sticks).
    let moving: Vec<f64> = amplitudes
        .iter()
        .copied()
        .take_while(|a| *a > 2.0 * loss)
        .collect();
    assert!(moving.len() >= 3, "{amplitudes:?}");
    for w in moving.windows(2) {
        let (t1, t2) = (w[0], w[1]);
        let lost = mgd * (t2.cos() - t1.cos());
        let work = tf * (t1 + t2);
        assert!(
            (lost - work).abs() < 0.03 * work,
            "energy lost {lost} vs friction work {work}"
        );
    }
    // Small swings: the decrement approaches 2 T_f / (m g d).
    let last = moving.windows(2).last().map(|w| w[0] - w[1]).unwrap();
    assert!(
        (last - loss).abs() < 0.1 * loss,
        "decrement {last} vs {loss}"
    );
}

#[test]
fn bad_release_angles_are_named() {
    let e = swing(&ActionParams::reference(), 0.0, 1.0).unwrap_err();
    assert!(e.to_string().contains("release_angle_deg"), "{e}");
}
