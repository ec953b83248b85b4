//! Measuring and regulating the simulated action like a technician.

use piano_action::regulation::{BANDS, Targets, measure, regulate};
use piano_action::{ActionParams, ModelKind};

#[test]
fn the_screws_move_the_measurements_the_way_a_technician_expects() {
    let p = ActionParams::reference();
    let r = measure(&p, ModelKind::Double).unwrap();
    // Lowering the let-off button makes the jack escape earlier: more let-off distance,
    // more aftertouch, and (drop screw unchanged) less drop.
    let mut lower = p.clone();
    lower.regulation.let_off_button_y_mm -= 0.2;
    let l = measure(&lower, ModelKind::Double).unwrap();
    let (a, b) = (r.let_off_mm.unwrap(), l.let_off_mm.unwrap());
    assert!(b > a + 0.5, "let-off {a} -> {b}");
    assert!(l.aftertouch_mm.unwrap() > r.aftertouch_mm.unwrap());
    // Raising the front-rail punching shortens the dip about one to one.
    let mut raised = p.clone();
    raised.regulation.front_rail_top_y_mm += 0.5;
    let d = measure(&raised, ModelKind::Double).unwrap();
    let shorter = r.key_dip_mm - d.key_dip_mm;
    assert!((0.4..0.65).contains(&shorter), "dip shortened by {shorter}");
    // Turning the capstan up lifts the hammer: less blow distance.
    let mut up = p.clone();
    up.regulation.capstan_raise_mm += 0.3;
    let u = measure(&up, ModelKind::Double).unwrap();
    assert!(u.blow_distance_mm < r.blow_distance_mm - 1.0);
}

#[test]
fn regulation_brings_every_model_into_the_literature_bands() {
    // Start from a badly regulated action: every screw off by a turn or so.
    let mut p = ActionParams::reference();
    p.regulation.front_rail_top_y_mm -= 0.8;
    p.regulation.capstan_raise_mm -= 0.3;
    p.regulation.let_off_button_y_mm -= 0.4;
    p.regulation.drop_screw_y_mm += 0.2;
    p.regulation.backcheck_offset_mm -= 0.6;
    for kind in ModelKind::ALL {
        let before = measure(&p, kind).unwrap();
        let done = regulate(&p, kind, &Targets::default()).unwrap();
        let r = done.achieved;
        println!(
            "{kind:?}: {before:?}\n  -> {r:?} in {} measurements",
            done.measurements
        );
        assert!(
            done.out_of_band.is_empty(),
            "{kind:?}: {:?}",
            done.out_of_band
        );
        // Re-measured from the returned parameters, not taken on trust.
        let again = measure(&done.params, kind).unwrap();
        assert!(BANDS.violations(&again, kind).is_empty(), "{again:?}");
        assert!((9.5..=11.0).contains(&again.key_dip_mm));
        assert!((44.0..=48.0).contains(&again.blow_distance_mm));
        match kind {
            ModelKind::Simplified => {
                assert_eq!(again.let_off_mm, None);
                assert_eq!(again.check_mm, None);
            }
            _ => {
                assert!((1.5..=2.5).contains(&again.let_off_mm.unwrap()));
                assert!((12.0..=16.0).contains(&again.check_mm.unwrap()));
                assert!((0.5..=1.5).contains(&again.aftertouch_mm.unwrap()));
            }
        }
        if kind == ModelKind::Double {
            assert!((0.5..=2.0).contains(&again.drop_mm.unwrap()));
        }
        // Only the screws and rails moved.
        assert_eq!(done.params.hammer, p.hammer);
        assert_eq!(done.params.key, p.key);
    }
}
