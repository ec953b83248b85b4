//! Keystrokes on the double-escapement action, the work of issue 16: a loud keystroke
//! (30 N on the key front, 0.2 s; target ≤ 2 ms and ≤ 2 000 derivative evaluations), a
//! soft pressed touch (1 N peak, 0.2 s) and the 1 kg mass placed on the key (0.4 s), which
//! must not get slower. Run with `cargo bench -p piano-action --bench keystroke`; each
//! case prints its work counts once before timing. The action's rest is settled once (about
//! 4 ms) and remembered, as in a sweep; each timed keystroke starts from it.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use piano_action::{ActionParams, Finger, Input, ModelKind, TouchStyle, simulate};

fn keystroke(c: &mut Criterion) {
    let params = ActionParams::reference();
    let cases = [
        (
            "double_loud_keystroke_0.2s",
            Input::Force {
                force_n: 30.0,
                release_s: None,
            },
            0.2,
        ),
        (
            "double_soft_pressed_1N_0.2s",
            Input::Touch {
                style: TouchStyle::Pressed { peak_force_n: 1.0 },
                finger: Finger::default(),
            },
            0.2,
        ),
        (
            "double_1kg_on_key_0.4s",
            Input::MassDrop {
                mass_kg: 1.0,
                height_m: 0.0,
            },
            0.4,
        ),
    ];
    for (name, input, duration_s) in &cases {
        match simulate(&params, ModelKind::Double, input, *duration_s, 1e-3) {
            Ok(run) => eprintln!("{name}: {:?}", run.solution.stats),
            Err(e) => eprintln!("{name}: {e}"),
        }
        c.bench_function(name, |b| {
            b.iter(|| {
                simulate(
                    black_box(&params),
                    ModelKind::Double,
                    input,
                    *duration_s,
                    1e-3,
                )
                .map(|r| r.strikes.len())
                .unwrap_or(0)
            })
        });
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = keystroke
}
criterion_main!(benches);
