//! The string's bridge force as sound: what a blow sounds like, from the same run.
//!
//! The hammer strikes a modal string ([`mbs_contact::StringContact`]); its lossless modal
//! amplitudes are part of the run's state. [`bridge_force`] samples them at 48 kHz (the
//! run's output grid and its events, interpolated linearly in between: the amplitudes only
//! change during a contact) and renders the force on the bridge with the string's losses
//! `σ_k = b₁ + b₃ ω_k²` ([`mbs_contact::BridgeForceRenderer`], `string_reference.md` §6).
//! After the run's end the string rings on freely: no damper is modelled. [`write_wav`]
//! writes it as a 16-bit mono WAV with a fixed full scale, so a soft and a loud blow keep
//! their levels and can be compared by ear.

use std::path::Path;

use mbs_contact::BridgeForceRenderer;

use crate::action::Action;
use crate::error::{PianoError, Result};
use crate::simulate::Run;

/// Sample rate of the sound (Hz): 48 kHz keeps every C4 mode of the model (to 17 kHz)
/// below 0.45 fs (`string_reference.md` §6).
pub const SAMPLE_RATE_HZ: u32 = 48_000;

/// The bridge force that is full scale in the WAV file (N) \[D\]: the C4 unison's peak
/// bridge force at a 6 m/s blow is about 60 N (`string_reference.md` §6: 14 N per string at
/// 4 m/s), so the loudest blows stay below clipping and a pianissimo is about 30 dB down.
pub const FULL_SCALE_N: f64 = 100.0;

/// The shortest sound written (s): a run of a few hundred milliseconds is extended so that
/// the note can be heard ringing.
pub const MIN_SOUND_S: f64 = 2.0;

/// Fade-out at the end of the sound (s), so that it does not end in a click.
const FADE_S: f64 = 0.05;

/// The bridge force of a run, sampled at [`SAMPLE_RATE_HZ`] from time 0 over
/// `max(run length, `[`MIN_SOUND_S`]`)` seconds (N). Fails when the action has no string.
pub fn bridge_force(action: &Action, run: &Run) -> Result<Vec<f64>> {
    let string = action.string_contact().ok_or_else(|| {
        PianoError::Simulation("this action has no string to render as sound".into())
    })?;
    let range = action.string_state_range().ok_or_else(|| {
        PianoError::Simulation("this action has no string to render as sound".into())
    })?;
    let modal = range.start..range.start + string.string().state_count();
    let sol = &run.solution;
    // The modal amplitudes at every time the run recorded: output grid and events.
    let mut knots: Vec<(f64, &[f64])> = (0..sol.len())
        .map(|i| (sol.t[i], &sol.state(i)[modal.clone()]))
        .chain(sol.events.iter().map(|e| (e.time, &e.state[modal.clone()])))
        .collect();
    knots.sort_by(|a, b| a.0.total_cmp(&b.0));
    let fs = f64::from(SAMPLE_RATE_HZ);
    let mut renderer = BridgeForceRenderer::new(string.string(), fs)?;
    let end = sol.t_final.max(MIN_SOUND_S);
    let count = (end * fs).ceil() as usize;
    let mut states = vec![0.0; modal.len()];
    let mut out = Vec::with_capacity(count);
    let mut k = 0;
    for i in 0..count {
        let t = i as f64 / fs;
        while k + 1 < knots.len() && knots[k + 1].0 <= t {
            k += 1;
        }
        match (knots.get(k), knots.get(k + 1)) {
            (Some(&(t0, a)), Some(&(t1, b))) if t >= t0 && t1 > t0 => {
                let w = (t - t0) / (t1 - t0);
                for ((s, x), y) in states.iter_mut().zip(a).zip(b) {
                    *s = x + w * (y - x);
                }
            }
            // Before the first knot the string is at rest; after the last it keeps its
            // last amplitudes (free vibration).
            (Some(&(t0, a)), _) if t >= t0 => states.copy_from_slice(a),
            _ => states.fill(0.0),
        }
        out.push(renderer.sample(t, &states));
    }
    Ok(out)
}

/// What [`write_wav`] wrote.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SoundLevels {
    /// Largest bridge force (N).
    pub peak_n: f64,
    /// RMS bridge force over the first 0.1 s after the sound begins (N).
    pub attack_rms_n: f64,
    /// Samples beyond full scale, clipped.
    pub clipped: usize,
    /// Length (s).
    pub seconds: f64,
}

/// Writes `force` (N, sampled at [`SAMPLE_RATE_HZ`]) to `path` as a 16-bit mono PCM WAV
/// with [`FULL_SCALE_N`] as full scale, fading out over the last 50 ms. Refuses a
/// non-finite sample (nothing is written then).
pub fn write_wav(path: &Path, force: &[f64]) -> Result<SoundLevels> {
    let fs = f64::from(SAMPLE_RATE_HZ);
    let fade = ((FADE_S * fs) as usize).min(force.len());
    if let Some(i) = force.iter().position(|f| !f.is_finite()) {
        return Err(PianoError::Simulation(format!(
            "the bridge force is not finite at sample {i} ({} s)",
            i as f64 / fs
        )));
    }
    let mut clipped = 0;
    let mut data = Vec::with_capacity(2 * force.len());
    for (i, f) in force.iter().enumerate() {
        let from_end = force.len() - i;
        let gain = if from_end <= fade {
            from_end as f64 / fade as f64
        } else {
            1.0
        };
        let x = f * gain / FULL_SCALE_N;
        if x.abs() > 1.0 {
            clipped += 1;
        }
        let sample = (x.clamp(-1.0, 1.0) * f64::from(i16::MAX)).round() as i16;
        data.extend_from_slice(&sample.to_le_bytes());
    }
    let mut bytes = Vec::with_capacity(44 + data.len());
    let too_long = || PianoError::file(path, "the sound is too long for a WAV file");
    let data_len = u32::try_from(data.len()).map_err(|_| too_long())?;
    let riff_len = data_len.checked_add(36).ok_or_else(too_long)?;
    bytes.extend_from_slice(b"RIFF");
    bytes.extend_from_slice(&riff_len.to_le_bytes());
    bytes.extend_from_slice(b"WAVE");
    bytes.extend_from_slice(b"fmt ");
    bytes.extend_from_slice(&16u32.to_le_bytes()); // size of the fmt chunk
    bytes.extend_from_slice(&1u16.to_le_bytes()); // PCM
    bytes.extend_from_slice(&1u16.to_le_bytes()); // mono
    bytes.extend_from_slice(&SAMPLE_RATE_HZ.to_le_bytes());
    bytes.extend_from_slice(&(2 * SAMPLE_RATE_HZ).to_le_bytes()); // bytes per second
    bytes.extend_from_slice(&2u16.to_le_bytes()); // bytes per frame
    bytes.extend_from_slice(&16u16.to_le_bytes()); // bits per sample
    bytes.extend_from_slice(b"data");
    bytes.extend_from_slice(&data_len.to_le_bytes());
    bytes.extend_from_slice(&data);
    std::fs::write(path, &bytes).map_err(|e| PianoError::io(path, "write", e))?;
    let peak_n = force.iter().fold(0.0f64, |m, f| m.max(f.abs()));
    let start = force.iter().position(|f| *f != 0.0).unwrap_or(0);
    let attack = &force[start..(start + (0.1 * fs) as usize).min(force.len())];
    let attack_rms_n = if attack.is_empty() {
        0.0
    } else {
        (attack.iter().map(|f| f * f).sum::<f64>() / attack.len() as f64).sqrt()
    };
    Ok(SoundLevels {
        peak_n,
        attack_rms_n,
        clipped,
        seconds: force.len() as f64 / fs,
    })
}
