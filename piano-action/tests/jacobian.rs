//! The action's own Jacobian (`System::jacobian`, what the integrator uses) against central
//! differences of its derivative, on the states of a loud keystroke's first 50 ms: the
//! velocity columns throughout, and the string's modal rows while the hammer is on the
//! string. (The coordinate columns leave out the slips' convective part and the contacts'
//! geometric stiffness, see `mbs_core::LoadJacobian`, so they are not compared.)

use nalgebra::DMatrix;
use piano_action::simulate::prepare;
use piano_action::*;

/// Central difference of the derivative along state `c`.
fn fd_column(
    sys: &mbs_core::System,
    ws: &mut mbs_core::Workspace,
    t: f64,
    x: &[f64],
    c: usize,
) -> Vec<f64> {
    let n = x.len();
    let h = 1e-7 * x[c].abs().max(1e-3);
    let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
    let mut xp = x.to_vec();
    xp[c] = x[c] + h;
    sys.derivative(ws, t, &xp, &mut fp).unwrap();
    xp[c] = x[c] - h;
    sys.derivative(ws, t, &xp, &mut fm).unwrap();
    fp.iter()
        .zip(&fm)
        .map(|(p, m)| (p - m) / (2.0 * h))
        .collect()
}

/// Largest difference over `rows`, relative to the largest entry there or to `floor`,
/// whichever is larger.
fn error(a: &[f64], f: &[f64], rows: std::ops::Range<usize>, floor: f64) -> f64 {
    let scale = rows.clone().map(|r| f[r].abs()).fold(floor, f64::max);
    rows.map(|r| (a[r] - f[r]).abs()).fold(0.0, f64::max) / scale
}

#[test]
fn the_loud_keystroke_jacobian_matches_differences_where_it_should() {
    let params = ActionParams::reference();
    let input = Input::Force {
        force_n: 30.0,
        release_s: None,
    };
    let prep = prepare(&params, ModelKind::Double, &input).unwrap();
    let sys = &prep.action.system;
    assert!(
        sys.has_jacobian(),
        "every element of the action differentiates its loads"
    );
    let run = simulate(&params, ModelKind::Double, &input, 0.05, 1e-4).unwrap();
    let strike = *run.strikes.first().expect("a loud blow strikes");
    let (n, nv) = (run.solution.n, sys.model().nv());
    let hammer = sys.model().coordinate_id("hammer").unwrap();
    let modes = prep.action.string_state_range().unwrap();
    let mut ws = sys.workspace();
    let mut ja = DMatrix::zeros(n, n);
    let mut checked_string = 0;
    for (i, &t) in run.solution.t.iter().enumerate() {
        let x = &run.solution.y[i * n..(i + 1) * n];
        sys.jacobian(&mut ws, t, x, &mut ja).unwrap();
        // The velocity columns: the contacts' damping, the friction's regularization and
        // the velocity products of the levers carried by the wippen. The gap rate and the
        // slip are linear in the velocities, so these columns are exact.
        for c in nv..2 * nv {
            let f = fd_column(sys, &mut ws, t, x, c);
            let a: Vec<f64> = ja.column(c).iter().copied().collect();
            let e = error(&a, &f, nv..2 * nv, 1.0);
            assert!(
                e < 0.1,
                "t = {t}: column {} off by {e:.2e}\n{:?}\n{:?}",
                sys.state_meaning(c),
                &a[nv..2 * nv],
                &f[nv..2 * nv]
            );
        }
        // On the string: the modal amplitudes' rates follow the felt force, so their rows
        // in the hammer's column are the series stiffness of felt and string.
        let on_string = t > strike.time_s + 1e-4 && t < strike.time_s + 5e-4;
        if on_string {
            let f = fd_column(sys, &mut ws, t, x, hammer);
            let a: Vec<f64> = ja.column(hammer).iter().copied().collect();
            let e = error(&a, &f, modes.clone(), 0.0);
            assert!(e < 1e-2, "t = {t}: modal rows off by {e:.2e}");
            checked_string += 1;
        }
    }
    assert!(checked_string >= 3, "{checked_string} states on the string");
}
