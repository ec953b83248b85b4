//! The string's bridge force as sound (`piano simulate --wav`): a valid WAV file, silent
//! before the blow, a harmonic spectrum with the strike point's missing partial, louder
//! and brighter for a louder blow.

use piano_action::simulate::prepare;
use piano_action::sound::{self, FULL_SCALE_N, MIN_SOUND_S, SAMPLE_RATE_HZ};
use piano_action::{ActionParams, Input, ModelKind, Run, simulate};

const F1_HZ: f64 = 262.2;
const B: f64 = 3.77e-4;

/// Bridge force of a constant key force held for 0.12 s.
fn blow(force_n: f64) -> (Run, Vec<f64>) {
    let params = ActionParams::reference();
    let input = Input::Force {
        force_n,
        release_s: None,
    };
    let run = simulate(&params, ModelKind::Double, &input, 0.12, 1e-3).expect("runs");
    let action = prepare(&params, ModelKind::Double, &input)
        .expect("prepares")
        .action;
    let force = sound::bridge_force(&action, &run).expect("renders");
    (run, force)
}

/// Amplitude (N) of the component at `f` Hz in `x` (Goertzel, Hann window).
fn amplitude(x: &[f64], f: f64) -> f64 {
    let fs = f64::from(SAMPLE_RATE_HZ);
    let w = 2.0 * std::f64::consts::PI * f / fs;
    let n = x.len() as f64;
    let (mut re, mut im) = (0.0, 0.0);
    for (i, v) in x.iter().enumerate() {
        let hann = 0.5 - 0.5 * (2.0 * std::f64::consts::PI * i as f64 / n).cos();
        let (s, c) = (w * i as f64).sin_cos();
        re += v * hann * c;
        im += v * hann * s;
    }
    4.0 * (re * re + im * im).sqrt() / n
}

fn partial(k: f64) -> f64 {
    k * F1_HZ * (1.0 + B * k * k).sqrt()
}

fn rms(x: &[f64]) -> f64 {
    (x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64).sqrt()
}

#[test]
fn the_bridge_force_is_silent_before_the_blow_and_rings_at_the_string_s_partials() {
    let (run, force) = blow(16.0);
    let fs = f64::from(SAMPLE_RATE_HZ);
    assert_eq!(force.len(), (MIN_SOUND_S * fs) as usize, "2 s at 48 kHz");
    let strike = run.strikes[0].time_s;
    let onset = force.iter().position(|f| *f != 0.0).expect("sounds") as f64 / fs;
    // (The output grid point just before the blow is read from the integrator's dense
    // output of the step that holds the onset, which spreads the first change of the
    // modes over that step: the sound may start up to a step early.)
    assert!(
        onset >= strike - 0.25e-3 && onset < strike + 1e-3,
        "sound from {onset} s, strike at {strike} s"
    );
    // 0.25 s of ringing after the blow: the inharmonic partials of the C4 unison, nothing
    // between them.
    let start = ((strike + 0.02) * fs) as usize;
    let seg = &force[start..start + (0.25 * fs) as usize];
    let a: Vec<f64> = (1..=9).map(|k| amplitude(seg, partial(k as f64))).collect();
    eprintln!("partials (N): {a:.3?}");
    for k in 1..=3 {
        let between = amplitude(seg, (k as f64 + 0.5) * F1_HZ);
        assert!(
            a[k - 1] > 20.0 * between,
            "partial {k}: {} N against {between} N between partials",
            a[k - 1]
        );
    }
    // The hammer strikes at 0.12 of the length: the 8th mode has a node close by
    // (sin 8 pi 0.12 = 0.13, against 0.48 for the 7th) and the 25th exactly there
    // (25 x 0.12 = 3): the 8th partial is weak and the 25th is absent.
    assert!(a[7] < 0.5 * a[6], "8th {} N vs 7th {} N", a[7], a[6]);
    let (a24, a25) = (amplitude(seg, partial(24.0)), amplitude(seg, partial(25.0)));
    assert!(a25 < 0.05 * a24, "25th {a25} N vs 24th {a24} N");
    // The string's losses make the sound decay (b1 = 0.5 1/s at the fundamental, more
    // above), and no more than the losses allow: T60 of the fundamental is about 13 s.
    let late = ((strike + 1.5) * fs) as usize;
    let (early_rms, late_rms) = (rms(seg), rms(&force[late..late + (0.25 * fs) as usize]));
    assert!(
        late_rms < 0.9 * early_rms && late_rms > 0.2 * early_rms,
        "rms {early_rms} N then {late_rms} N"
    );
}

#[test]
fn a_louder_blow_sounds_louder_and_brighter() {
    let (soft_run, soft) = blow(3.0);
    let (loud_run, loud) = blow(32.0);
    let (vs, vl) = (
        soft_run.strikes[0].hammer_velocity_m_s,
        loud_run.strikes[0].hammer_velocity_m_s,
    );
    let fs = f64::from(SAMPLE_RATE_HZ);
    let window = |run: &Run, x: &[f64]| {
        let start = ((run.strikes[0].time_s + 0.02) * fs) as usize;
        x[start..start + (0.25 * fs) as usize].to_vec()
    };
    let (s, l) = (window(&soft_run, &soft), window(&loud_run, &loud));

    // The string is linear: its level follows the hammer's momentum, a little more than
    // in proportion as the stiffening felt shortens the contact.
    let level = rms(&l) / rms(&s);
    eprintln!("hammer {vs:.2} -> {vl:.2} m/s, rms x{level:.2}");
    assert!(
        level > 0.8 * vl / vs && level < 2.0 * vl / vs,
        "rms ratio {level} for a speed ratio {}",
        vl / vs
    );
    // Brighter: the shorter, harder contact of the stiffening felt gives the 9th-20th
    // partials (2.4-5.5 kHz) more against the fundamental.
    let upper = |x: &[f64]| {
        (9..=20)
            .map(|k| amplitude(x, partial(k as f64)))
            .sum::<f64>()
            / amplitude(x, partial(1.0))
    };
    assert!(
        upper(&l) > 1.5 * upper(&s),
        "upper partials / fundamental {} (loud) vs {} (soft)",
        upper(&l),
        upper(&s)
    );
}

#[test]
fn the_wav_file_is_48_khz_16_bit_mono_at_a_fixed_full_scale() {
    let (_, force) = blow(16.0);
    let dir = std::env::temp_dir().join(format!("piano-sound-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("blow.wav");
    let levels = sound::write_wav(&path, &force).expect("writes");
    let bytes = std::fs::read(&path).unwrap();
    let u32_at = |i: usize| u32::from_le_bytes(bytes[i..i + 4].try_into().unwrap());
    let u16_at = |i: usize| u16::from_le_bytes(bytes[i..i + 2].try_into().unwrap());
    assert_eq!(&bytes[0..4], b"RIFF");
    assert_eq!(u32_at(4) as usize, bytes.len() - 8);
    assert_eq!(&bytes[8..16], b"WAVEfmt ");
    assert_eq!((u16_at(20), u16_at(22)), (1, 1), "PCM, mono");
    assert_eq!(u32_at(24), SAMPLE_RATE_HZ);
    assert_eq!(u16_at(34), 16, "bits per sample");
    assert_eq!(&bytes[36..40], b"data");
    assert_eq!(u32_at(40) as usize, 2 * force.len());
    // The samples are the force over the full scale (the last 50 ms fade out).
    let peak = force
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
        .map(|(i, _)| i)
        .unwrap();
    let sample = i16::from_le_bytes(bytes[44 + 2 * peak..46 + 2 * peak].try_into().unwrap());
    let expected = force[peak] / FULL_SCALE_N * f64::from(i16::MAX);
    assert!(
        (f64::from(sample) - expected).abs() <= 1.0,
        "{sample} vs {expected}"
    );
    assert!((levels.peak_n - force[peak].abs()).abs() < 1e-12);
    assert_eq!(
        levels.clipped, 0,
        "a 16 N blow stays below {FULL_SCALE_N} N"
    );
    assert_eq!(*bytes.last().unwrap(), 0, "faded out");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_non_finite_bridge_force_is_refused_and_nothing_is_written() {
    let path = std::env::temp_dir().join(format!("piano-nan-{}.wav", std::process::id()));
    let force = [0.0, 1.0, f64::NAN, 2.0];
    let e = sound::write_wav(&path, &force).unwrap_err().to_string();
    assert!(e.contains("not finite") && e.contains("sample 2"), "{e}");
    assert!(!path.exists());
}
