//! refuse_overwriting_inputs: every way of naming an input as an output is refused.

use std::fs;
use std::os::unix::fs::symlink;
use std::path::Path;

use crate::common::{TestDir, assert_only_changed, snapshot};
use output::{Target, refuse_overwriting_inputs};

fn check(input: &Path, output: &Path) -> Result<(), output::WriteError> {
    let out = Target::Path(output.to_path_buf());
    refuse_overwriting_inputs(&[("--data", input)], &[("--json", &out)])
}

#[test]
fn every_spelling_of_an_input_is_refused() {
    let dir = TestDir::new("inputs");
    let x = dir.file("x.csv", "data");
    fs::create_dir(dir.join("sub")).unwrap();
    fs::hard_link(&x, dir.join("hard.csv")).unwrap();
    symlink("x.csv", dir.join("soft.csv")).unwrap();
    symlink("../soft.csv", dir.join("sub/chain.csv")).unwrap();
    let before = snapshot(&dir.path);
    for name in [
        "x.csv",
        "./x.csv",
        "sub/../x.csv",
        "hard.csv",
        "soft.csv",
        "sub/chain.csv",
    ] {
        let out = dir.join(name);
        let err = check(&x, &out).unwrap_err();
        assert_eq!(
            err.to_string(),
            format!(
                "--json: `{}` is also the input of --data: refusing to overwrite an input",
                out.display()
            )
        );
        assert!(err.is_usage());
        // The input named through a link or another spelling is the same input.
        check(&out, &x).unwrap_err();
    }
    assert_only_changed(&before, &snapshot(&dir.path), &[]);
}

#[test]
fn other_files_are_accepted() {
    let dir = TestDir::new("not_inputs");
    let x = dir.file("x.csv", "data");
    let copy = dir.file("copy.csv", "data");
    symlink("gone.csv", dir.join("dangling")).unwrap();
    let before = snapshot(&dir.path);
    for out in [copy, dir.join("new.json"), dir.join("dangling")] {
        check(&x, &out).unwrap();
    }
    // Standard output is never an input file; a missing input is no file to protect.
    refuse_overwriting_inputs(&[("--data", &x)], &[("-o", &Target::Stdout)]).unwrap();
    check(&dir.join("missing.csv"), &dir.join("other.csv")).unwrap();
    assert_only_changed(&before, &snapshot(&dir.path), &[]);
}

#[test]
fn a_dangling_link_to_where_an_input_will_be_is_refused() {
    // A missing input and an output that would create it (through a link) are the same path.
    let dir = TestDir::new("dangling_input");
    symlink("later.csv", dir.join("link")).unwrap();
    check(&dir.join("later.csv"), &dir.join("link")).unwrap_err();
}

#[test]
fn the_first_clashing_output_and_its_input_are_named() {
    let dir = TestDir::new("several_inputs");
    let a = dir.file("a.csv", "a");
    let b = dir.file("b.csv", "b");
    let fine = Target::Path(dir.join("out.json"));
    let clash = Target::Path(dir.join("./b.csv"));
    let err = refuse_overwriting_inputs(
        &[("--data", &a), ("--validate", &b)],
        &[("--json", &fine), ("-o", &clash)],
    )
    .unwrap_err();
    assert_eq!(
        err.to_string(),
        format!(
            "-o: `{}` is also the input of --validate: refusing to overwrite an input",
            dir.join("./b.csv").display()
        )
    );
}

/// A file of an output directory (named only once the work is done) that is an input, under
/// its own name or through a link, is refused when the outputs are written, and nothing is
/// written; an output directory holding such a file is found before the work too.
#[test]
fn an_input_inside_an_output_directory_is_never_overwritten() {
    let dir = TestDir::new("inputs-in-dir");
    let x = dir.file("x.csv", "data");
    fs::create_dir(dir.join("plots")).unwrap();
    fs::hard_link(&x, dir.join("plots/a.svg")).unwrap();
    symlink("../x.csv", dir.join("plots/b.svg")).unwrap();
    let before = snapshot(&dir.path);
    for name in ["a.svg", "b.svg"] {
        let mut outputs = output::Outputs::new();
        outputs.protect(&[("--data", x.as_path())]);
        outputs.add_in_dir("--plot", dir.join("plots"), "other.svg", "<svg/>");
        outputs.add_in_dir("--plot", dir.join("plots"), name, "<svg/>");
        let err = outputs.write_all().unwrap_err();
        assert_eq!(
            err.to_string(),
            format!(
                "--plot: `{}` is also the input of --data: refusing to overwrite an input",
                dir.join("plots").join(name).display()
            )
        );
        assert!(err.is_usage());
        assert_only_changed(&before, &snapshot(&dir.path), &[]);
    }
    let svg = |n: &str| n.ends_with(".svg");
    let err = output::refuse_inputs_in_dir(&[("--data", &x)], "--plot", &dir.join("plots"), &svg)
        .unwrap_err();
    assert!(
        err.to_string().contains("is also the input of --data"),
        "{err}"
    );
    let csv = |n: &str| n.ends_with(".csv");
    assert!(
        output::refuse_inputs_in_dir(&[("--data", &x)], "--plot", &dir.join("plots"), &csv).is_ok()
    );
}
