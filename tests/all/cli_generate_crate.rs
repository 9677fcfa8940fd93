//! `rtest generate --crate DIR`: a ready `no_std` crate for a machine, checked by building it.
//!
//! The crates written here are built with cargo (offline; they have no dependency), their
//! documentation generated and their documentation examples run, every warning an error
//! (`RUSTFLAGS` and `RUSTDOCFLAGS` = `-D warnings`), with a target directory inside the test's
//! temporary directory. Then the failures: a directory that is not empty, a path that is not a
//! directory, a bad machine file, `--crate` with `-o`: one line naming the flag, and nothing
//! written.

use crate::common;

use common::{entries, fails, ok, temp_dir_tagged};
use std::path::Path;
use std::process::Command;

/// The example's machine description: a five-axis trunnion machine that is not built in.
const TRUNNION: &str = include_str!("../../examples/user-machine/machine.toml");

/// Runs `cargo args` on the crate in `dir` (offline, `-D warnings`, target directory
/// `target`), asserts success and returns its standard error.
fn cargo(dir: &Path, target: &Path, args: &[&str]) -> String {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let o = Command::new(cargo)
        .args(args)
        .arg("--offline")
        .arg("--manifest-path")
        .arg(dir.join("Cargo.toml"))
        .env("CARGO_TARGET_DIR", target)
        .env("RUSTFLAGS", "-D warnings")
        .env("RUSTDOCFLAGS", "-D warnings")
        .env_remove("CARGO_ENCODED_RUSTFLAGS")
        .env_remove("CARGO_BUILD_RUSTFLAGS")
        .env_remove("CARGO_BUILD_TARGET")
        .output()
        .expect("cargo runs");
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(
        o.status.success(),
        "cargo {args:?} in {}: {err}",
        dir.display()
    );
    assert!(!err.contains("warning"), "cargo {args:?}: {err}");
    err
}

/// Builds, documents and tests (its documentation examples) the crate in `dir`.
fn check_crate(dir: &Path, target: &Path) {
    cargo(dir, target, &["build"]);
    cargo(dir, target, &["doc", "--no-deps"]);
    let tested = cargo(dir, target, &["test", "--doc"]);
    assert!(tested.contains("Doc-tests"), "{tested}");
}

#[test]
fn a_crate_for_a_machine_file_builds_documents_and_runs_its_examples() {
    let tmp = temp_dir_tagged("generate-crate", "file");
    let machine = tmp.join("trunnion.toml");
    std::fs::write(&machine, TRUNNION).unwrap();
    let krate = tmp.join("deep/er/trunnion");
    let m = machine.to_str().unwrap();
    let args = [
        "generate",
        "--machine",
        m,
        "--model",
        "location",
        "--crate",
        krate.to_str().unwrap(),
    ];
    let said = ok(&tmp, &args);
    assert!(said.contains("Crate `trunnion-bc-error-model`"), "{said}");
    assert_eq!(
        entries(&krate),
        ["Cargo.toml", "README.md", "machine.toml", "src"]
    );
    assert_eq!(entries(&krate.join("src")), ["lib.rs"]);
    // The description it was generated from, byte for byte; the code that `generate` writes.
    assert_eq!(
        std::fs::read_to_string(krate.join("machine.toml")).unwrap(),
        TRUNNION
    );
    let code = ok(&tmp, &["generate", "--machine", m, "--model", "location"]);
    let lib = std::fs::read_to_string(krate.join("src/lib.rs")).unwrap();
    assert!(
        lib.ends_with(&code),
        "src/lib.rs ends with the generated code"
    );
    assert!(lib.starts_with("//! The geometric error model of the machine `trunnion-bc`"));
    assert!(lib.contains("\n#![no_std]\n"));
    assert!(lib.contains("//! - [`location`] (14 errors)") && !lib.contains("[`full`]"));
    let manifest = std::fs::read_to_string(krate.join("Cargo.toml")).unwrap();
    assert!(
        manifest.contains("name = \"trunnion-bc-error-model\""),
        "{manifest}"
    );
    assert!(manifest.contains("\n[dependencies]\n") && manifest.contains("\n[workspace]\n"));
    let readme = std::fs::read_to_string(krate.join("README.md")).unwrap();
    assert!(
        readme.starts_with("# trunnion-bc-error-model\n"),
        "{readme}"
    );
    check_crate(&krate, &tmp.join("target"));
    // An existing empty directory is taken.
    let empty = tmp.join("empty");
    std::fs::create_dir(&empty).unwrap();
    ok(
        &tmp,
        &["generate", "--machine", "seed-ac", "--crate", "empty"],
    );
    assert_eq!(
        std::fs::read_to_string(empty.join("machine.toml")).unwrap(),
        model_spec::BUILTIN
            .iter()
            .find(|(n, _)| *n == "seed-ac")
            .unwrap()
            .1
    );
}

#[test]
fn markup_in_a_description_and_a_machine_without_rotary_axes_give_clean_documentation() {
    let tmp = temp_dir_tagged("generate-crate", "markup");
    // A name that starts with a digit; a description with Markdown and HTML in it, and words
    // that would start a list or a heading wherever a line breaks.
    let description = "Mill [draft] <b>bold</b> *x* `y` | ~z~ _u_ \\\\ # - + = 1. 2) \
                       and a long tail of words so that the wrapping moves the marks around: - \
                       # 3. + = - # 4) end";
    let text = format!(
        "name = \"3ax_mill\"\ndescription = \"{description}\"\n\n[[work]]\nend = \"ball\"\n\n\
         [[tool]]\naxis = \"X\"\ntype = \"linear\"\ndirection = \"+x\"\nstroke = [-400, 400]\n\n\
         [[tool]]\naxis = \"Y\"\ntype = \"linear\"\ndirection = \"-y\"\nstroke = [-300, 300]\n\n\
         [[tool]]\naxis = \"Z\"\ntype = \"linear\"\ndirection = \"+z\"\nstroke = [-300, 300]\n\n\
         [[tool]]\nend = \"probe\"\n\n[models.square]\nerrors = [\"COY\", \"AOZ\", \"BOZ\"]\n\n\
         [models.said]\ndescription = \"<i>it</i> [x]\"\nerrors = [\"EXX\", \"AOZ\"]\n"
    );
    std::fs::write(tmp.join("mill.toml"), &text).unwrap();
    ok(
        &tmp,
        &["generate", "--machine", "mill.toml", "--crate", "mill"],
    );
    let manifest = std::fs::read_to_string(tmp.join("mill/Cargo.toml")).unwrap();
    assert!(
        manifest.contains("name = \"machine-3ax_mill-error-model\""),
        "{manifest}"
    );
    let lib = std::fs::read_to_string(tmp.join("mill/src/lib.rs")).unwrap();
    assert!(lib.contains("\\[draft\\] \\<b\\>bold\\</b\\>"), "{lib}");
    // The description's marks never start a line: the only headings and items are the
    // crate's own.
    let headings = [
        "# Models",
        "# Units",
        "# Gains",
        "# Compensation in single precision",
    ];
    let items = ["- [`", "- `", "- Gains:", "- Error values", "- Commands"];
    for line in lib.lines().filter_map(|l| l.strip_prefix("//! ")) {
        let body = line.trim_start();
        let ordered = ["1.", "2)", "3.", "4)"].iter().any(|m| body.starts_with(m));
        assert!(
            !(body.starts_with(['+', '=']) || ordered),
            "a line starts a block: {line}"
        );
        assert!(
            !body.starts_with('#') || headings.contains(&line),
            "a line starts a heading: {line}"
        );
        assert!(
            !body.starts_with('-') || (line == body && items.iter().any(|i| line.starts_with(i))),
            "a line starts an item: {line}"
        );
    }
    check_crate(&tmp.join("mill"), &tmp.join("target"));
}

#[test]
fn a_directory_that_is_not_empty_or_not_a_directory_is_refused_and_nothing_is_written() {
    let tmp = temp_dir_tagged("generate-crate", "refused");
    std::fs::create_dir(tmp.join("full")).unwrap();
    std::fs::write(tmp.join("full/notes.txt"), "mine").unwrap();
    fails(
        &tmp,
        &["generate", "--machine", "seed-ac", "--crate", "full"],
        1,
        &["--crate", "`full`", "not empty", "notes.txt"],
    );
    assert_eq!(entries(&tmp.join("full")), ["notes.txt"]);
    std::fs::write(tmp.join("file"), "x").unwrap();
    fails(
        &tmp,
        &["generate", "--machine", "seed-ac", "--crate", "file"],
        1,
        &["--crate", "`file`", "not a directory"],
    );
    fails(
        &tmp,
        &["generate", "--machine", "seed-ac", "--crate", "file/sub"],
        1,
        &["--crate", "file"],
    );
    fails(
        &tmp,
        &[
            "generate",
            "--machine",
            "seed-ac",
            "--crate",
            "new",
            "-o",
            "x.rs",
        ],
        2,
        &["--crate", "-o"],
    );
    assert_eq!(entries(&tmp), ["file", "full"]);
    assert_eq!(std::fs::read_to_string(tmp.join("file")).unwrap(), "x");
}

#[test]
fn a_bad_machine_file_is_named_with_its_line_and_nothing_is_written() {
    let tmp = temp_dir_tagged("generate-crate", "bad");
    let bad = TRUNNION.replace("range = [-110.0, 110.0]", "range = [110.0, -110.0]");
    std::fs::write(tmp.join("bad.toml"), bad).unwrap();
    fails(
        &tmp,
        &["generate", "--machine", "bad.toml", "--crate", "out"],
        1,
        &["--machine", "bad.toml:30:9", "axis B", "`range`"],
    );
    fails(
        &tmp,
        &[
            "generate",
            "--machine",
            "seed-ac",
            "--model",
            "nope",
            "--crate",
            "out",
        ],
        2,
        &["--model", "`nope`"],
    );
    // A text-direction control in the description (rustc refuses it in the crate's comments).
    let reordered = TRUNNION.replacen(
        "description = \"Five-axis",
        "description = \"x\\u202eFive-axis",
        1,
    );
    std::fs::write(tmp.join("reordered.toml"), reordered).unwrap();
    fails(
        &tmp,
        &["generate", "--machine", "reordered.toml", "--crate", "out"],
        1,
        &[
            "--machine",
            "reordered.toml:8:15",
            "description holds U+202E at character 2",
        ],
    );
    assert_eq!(entries(&tmp), ["bad.toml", "reordered.toml"]);
}
