//! The README as a new user reads it (issue 11): everything it points to is in the
//! repository, its example runs write under `target/`, and it keeps its two set-up commands.

use std::path::Path;

fn readme() -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../README.md")).unwrap()
}

#[test]
fn the_readme_points_only_inside_the_repository() {
    let text = readme();
    assert!(!text.contains("../"), "a link outside the repository");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    // Every repository path it names in backticks exists.
    for path in text.split('`').skip(1).step_by(2) {
        let looks_like_path = (path.starts_with("docs/")
            || path.starts_with("piano-action/")
            || path.starts_with("mbs-"))
            && !path.contains(' ')
            && !path.contains('*');
        if looks_like_path {
            assert!(
                root.join(path).exists(),
                "README names {path}, which is not here"
            );
        }
    }
}

#[test]
fn the_readme_examples_write_under_target_and_set_up_takes_two_commands() {
    let text = readme();
    for line in text.lines().filter(|l| l.contains("--out ")) {
        let after = line.split("--out ").nth(1).unwrap_or("");
        let dir = after.split(['`', ' ']).next().unwrap_or("");
        assert!(
            dir.is_empty()
                || dir.starts_with("target/")
                || dir.contains("DIR")
                || dir.contains("FILE"),
            "an example writes {dir} into the checkout: {line}"
        );
    }
    let setup = text
        .split("## Set-up")
        .nth(1)
        .and_then(|s| s.split("\n## ").next())
        .unwrap();
    let commands: Vec<&str> = setup
        .split("```sh\n")
        .skip(1)
        .map(|block| block.split("```").next().unwrap().trim())
        .collect();
    assert_eq!(commands, ["cargo run --release", "cargo test --workspace"]);
    assert!(
        setup.contains("few minutes"),
        "the cold build's time is said"
    );
}
