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
