//! Static touchweight of the reference action (literature.md §2: down weight 45–60 gf, up
//! weight 20–35 gf), and the effect of hammer-flange friction technicians measure.

use piano_action::touchweight::measure;
use piano_action::{ActionParams, ModelKind};

#[test]
fn touchweight_is_in_the_literature_bands_and_flange_friction_widens_it() {
    let p = ActionParams::reference();
    let w = measure(&p, ModelKind::Double).unwrap();
    println!("{w:#?}");
    assert!((45.0..=60.0).contains(&w.down_weight_gf), "{w:?}");
    assert!((20.0..=35.0).contains(&w.up_weight_gf), "{w:?}");
    // The layout was sized for a balance weight of 38 gf.
    assert!((w.balance_weight_gf - 38.0).abs() < 2.0, "{w:?}");
    // 0.75 mN·m more at the hammer flange raises the down weight and lowers the up weight.
    let mut stiff = p.clone();
    stiff.hammer.pivot_friction_n_m += 0.75e-3;
    let s = measure(&stiff, ModelKind::Double).unwrap();
    println!("{s:#?}");
    assert!(s.down_weight_gf > w.down_weight_gf + 1.0, "{s:?}");
    assert!(s.up_weight_gf < w.up_weight_gf - 1.0, "{s:?}");
    assert!((s.balance_weight_gf - w.balance_weight_gf).abs() < 1.0);
}
