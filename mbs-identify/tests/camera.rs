//! The camera's measurement model: exposure averaging and clock offset.

use mbs_identify::Camera;

#[test]
fn a_frame_averages_the_motion_over_its_exposure_from_the_offset_start() {
    // A marker on a circle of radius r at angular speed w: over an exposure e the average
    // is the midpoint position scaled by sin(w e/2)/(w e/2) (a chord, nearer the centre).
    let (r, w) = (0.13, 2.0 * std::f64::consts::PI * 50.0);
    let circle = |t: f64| Some([r * (w * t).cos(), r * (w * t).sin()]);
    let cam = Camera {
        exposure_s: 2e-3,
        offset_s: 3e-4,
    };
    for t in [0.0, 1.7e-3, 0.0123] {
        let f = cam.frame(t, circle).unwrap();
        let mid = t + cam.offset_s + 0.5 * cam.exposure_s;
        let x = 0.5 * w * cam.exposure_s;
        let k = x.sin() / x;
        let expected = [k * r * (w * mid).cos(), k * r * (w * mid).sin()];
        for i in 0..2 {
            assert!(
                (f[i] - expected[i]).abs() < 1e-12,
                "{t}: {f:?} vs {expected:?}"
            );
        }
        // The averaging is visible: a 50 Hz swing over 2 ms pulls the marker in by 0.66 %.
        assert!((1.0 - k) > 6e-3);
    }
    // No exposure: the position at t + offset, exactly.
    let sharp = Camera {
        exposure_s: 0.0,
        offset_s: -1e-4,
    };
    assert_eq!(sharp.frame(0.01, circle), circle(0.01 - 1e-4));
    // The weights sum to one; the samples lie inside the exposure.
    let sum: f64 = cam.samples(0.5).map(|(_, w)| w).sum();
    assert!((sum - 1.0).abs() < 1e-14);
    assert!(
        cam.samples(0.5)
            .all(|(t, _)| t > 0.5 + 3e-4 && t < 0.5 + 3e-4 + 2e-3)
    );
    // A motion not known at a sample gives no frame.
    assert_eq!(cam.frame(0.0, |t| (t < 1e-3).then_some([0.0, 0.0])), None);
}
