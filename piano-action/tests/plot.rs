//! Static figures of a run (`piano plot`), SVG and PNG.

use piano_action::ActionParams;
use piano_action::plot::{Format, plot_run};
use piano_action::scenario::{Scenario, write_run_dir};

#[test]
fn a_run_is_drawn_as_svg_and_png() {
    let dir = std::env::temp_dir().join(format!("piano-plot-{}", std::process::id()));
    let scenario = Scenario::from_toml_str(
        "model = \"double\"\nduration_s = 0.06\n[input]\nkind = \"force\"\nforce_n = 12.0\n",
    )
    .unwrap();
    let params = ActionParams::reference();
    let run = scenario.run(&params).unwrap();
    write_run_dir(&dir, &scenario, &params, &run).unwrap();
    let svg = dir.join("figure.svg");
    if let Err(e) = plot_run(&dir, Format::Svg, &svg, None) {
        // Without any font on the machine the error says how to give one.
        assert!(e.to_string().contains("--font"), "{e}");
        return;
    }
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.starts_with("<svg"), "{}", &text[..40]);
    for label in [
        "double action, force 12 N",
        "Hammer angle (deg)",
        "Contact forces (N)",
        "hammer string",
        "time (ms)",
    ] {
        assert!(text.contains(label), "missing {label}");
    }
    let png = dir.join("figure.png");
    plot_run(&dir, Format::Png, &png, None).unwrap();
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    // IHDR: width and height, big-endian, after the 8-byte signature and 8-byte chunk head.
    let w = u32::from_be_bytes(bytes[16..20].try_into().unwrap());
    let h = u32::from_be_bytes(bytes[20..24].try_into().unwrap());
    assert_eq!((w, h), (1600, 1200));
    assert!(
        bytes.len() > 50_000,
        "{} bytes: an empty picture?",
        bytes.len()
    );
    // Bad inputs are named.
    assert!(
        Format::parse("jpg")
            .unwrap_err()
            .to_string()
            .contains("--format")
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// The texts of an SVG written by plotters: (x, y, font size, text); texts placed otherwise
/// (turned axis titles) are left out.
fn texts(svg: &str) -> Vec<(f64, f64, f64, String)> {
    let attr = |tag: &str, name: &str| -> Option<f64> {
        let key = format!(r#" {name}=""#);
        let a = tag.find(&key)? + key.len();
        tag[a..a + tag[a..].find('"')?].parse().ok()
    };
    svg.split("<text ")
        .skip(1)
        .filter_map(|t| {
            let (tag, rest) = t.split_once('>')?;
            let tag = format!(" {tag}");
            let tag = tag.as_str();
            let text = rest.split("</text>").next()?.trim().to_string();
            Some((
                attr(tag, "x")?,
                attr(tag, "y")?,
                attr(tag, "font-size")?,
                text,
            ))
        })
        .collect()
}

#[test]
fn every_strike_and_event_kind_is_marked_and_named_without_overlap() {
    let dir = std::env::temp_dir().join(format!("piano-plot-marks-{}", std::process::id()));
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/repeated_notes.toml");
    let scenario = Scenario::load(&path).unwrap();
    let params = ActionParams::reference();
    let run = scenario.run(&params).unwrap();
    assert!(run.strikes.len() >= 2, "{} strikes", run.strikes.len());
    write_run_dir(&dir, &scenario, &params, &run).unwrap();
    let svg = dir.join("figure.svg");
    if let Err(e) = plot_run(&dir, Format::Svg, &svg, None) {
        assert!(e.to_string().contains("--font"), "{e}");
        return;
    }
    let all = texts(&std::fs::read_to_string(&svg).unwrap());
    let count = |label: &str| all.iter().filter(|t| t.3 == label).count();
    // One named mark per strike, the second one too.
    for k in 1..=run.strikes.len() {
        assert_eq!(count(&format!("strike {k}")), 1, "strike {k}");
    }
    assert_eq!(count(&format!("strike {}", run.strikes.len() + 1)), 0);
    // Every kind of event the run has is named: the let-off of each blow (the jack is
    // reset between them), the key bottoms, the checks, the jack reset.
    for (label, times) in [
        ("let-off", 2),
        ("key bottom", 2),
        ("check", 2),
        ("jack reset", 1),
    ] {
        assert_eq!(count(label), times, "{label}");
    }
    // No two of these names overlap (their boxes estimated at 0.55 em a character).
    let marks: Vec<_> = all
        .iter()
        .filter(|t| {
            t.3.starts_with("strike")
                || ["let-off", "key bottom", "check", "drop", "jack reset"].contains(&t.3.as_str())
        })
        .collect();
    for (i, a) in marks.iter().enumerate() {
        for b in &marks[i + 1..] {
            let wa = 0.55 * a.2 * a.3.chars().count() as f64;
            let wb = 0.55 * b.2 * b.3.chars().count() as f64;
            let apart = a.0 + wa <= b.0 || b.0 + wb <= a.0 || a.1 + a.2 <= b.1 || b.1 + b.2 <= a.1;
            assert!(
                apart,
                "'{}' at {:?} overlaps '{}' at {:?}",
                a.3,
                (a.0, a.1),
                b.3,
                (b.0, b.1)
            );
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}
