//! Measuring the regulation on the simulated action.

use piano_action::regulation::measure;
use piano_action::{ActionParams, ModelKind};

#[test]
fn regulation_measurements_respond_to_the_screws_as_a_technician_expects() {
    let mut p = ActionParams::reference();
    // The layout's button height is on the edge (the hammer reaches the string before the
    // jack escapes in a slow press); 0.5 mm lower it lets off.
    p.regulation.let_off_button_y_mm -= 0.5;
    let r = measure(&p, ModelKind::Double).unwrap();
    println!("{r:#?}");
    // Blow from the layout (47 mm at the strike point), in the literature band 44–48.
    assert!((44.0..48.0).contains(&r.blow_distance_mm), "{r:?}");
    // A firm press bottoms the key near 10 mm, a little deeper as the punching compresses.
    assert!((9.5..12.0).contains(&r.key_dip_mm), "{r:?}");
    assert!(r.let_off_mm > 0.0 && r.aftertouch_mm > 0.0, "{r:?}");
    assert!(r.check_mm > 0.0);
    // Lowering the let-off button another 0.5 mm makes the jack escape earlier: more
    // let-off distance and more aftertouch.
    p.regulation.let_off_button_y_mm -= 0.5;
    let lower = measure(&p, ModelKind::Double).unwrap();
    assert!(
        lower.let_off_mm > r.let_off_mm + 0.5,
        "{} vs {}",
        lower.let_off_mm,
        r.let_off_mm
    );
    assert!(lower.aftertouch_mm > r.aftertouch_mm);
}
