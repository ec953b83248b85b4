//! Probe (ignored): synthesise key-drive data with an effect and diagnose it.
use piano_action::identify::action_effects::ActionEffect;
use piano_action::identify::key_diagnose::{KeyDiagnoseOptions, diagnose_key_drive};
use piano_action::identify::key_drive::{KeyDriveOptions, synthesize};
use piano_action::params::ActionParams;

#[test]
#[ignore]
fn probe_key_drive_diagnosis() {
    let params = ActionParams::reference();
    let effect = std::env::var("EFFECT").ok().filter(|s| !s.is_empty());
    let seed: u64 = std::env::var("SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    let options = KeyDriveOptions {
        seed,
        effect: effect.as_deref().map(|e| ActionEffect::parse(e).unwrap()),
        ..Default::default()
    };
    let (mut dataset, runs, truth) = synthesize(&params, &options).unwrap();
    let dir = std::env::temp_dir().join(format!(
        "probe_kd_{seed}_{}",
        effect
            .as_deref()
            .unwrap_or("none")
            .replace([':', '=', ','], "_")
    ));
    let _ = std::fs::remove_dir_all(&dir);
    dataset.write(&dir, &runs).unwrap();
    dataset = mbs_identify::Dataset::load(&dir).unwrap();
    let lib = std::env::var("LIB").ok();
    let mut o = KeyDiagnoseOptions::default();
    if let Some(l) = lib {
        o.library = l
            .split(',')
            .map(|id| piano_action::identify::action_effects::action_effect_spec(id).unwrap())
            .collect();
    }
    let t = std::time::Instant::now();
    let d = diagnose_key_drive(&params, &dataset, &o, &|m, f| {
        eprintln!("[{:.1}s] {m} {f:.2}", t.elapsed().as_secs_f64())
    })
    .unwrap();
    eprintln!("truth: {:?} {:?}", truth.effect, truth.effect_params);
    eprintln!("decision: {} — {}", d.decision, d.summary);
    eprintln!(
        "noise {:.1} µm rho {:.2}; fit rms {:.1} -> {:.1} µm; heldout {:?} -> {:?}",
        d.noise_floor_m * 1e6,
        d.data.rho,
        d.before_rms_m * 1e6,
        d.after_rms_m * 1e6,
        d.heldout_before_rms_m,
        d.heldout_after_rms_m
    );
    eprintln!(
        "flagged {} / {}; onset {:?}",
        d.flagged_phase, d.flagged_marker, d.onset
    );
    eprintln!("calibrated {:?}\nrise {:?}", d.calibrated, d.rise_calibrated);
    for c in &d.candidates {
        eprintln!(
            "  {:22} dBIC {:9.1} fit {:7.1} flagged {:7.1} {:?} {}",
            c.id,
            c.delta_bic,
            c.fit_rms_m * 1e6,
            c.flagged_rms_m * 1e6,
            c.params,
            c.why
        );
    }
    for p in d.phases.iter() {
        eprintln!(
            "  {:9} {:15} {:13} {:6.1} -> {:6.1}",
            p.run,
            p.phase,
            p.marker,
            p.before_rms_m * 1e6,
            p.after_rms_m * 1e6
        );
    }
    eprintln!("timing {:?}", d.timing);
}
