//! `docs/model-spec.md` stays true: its complete TOML examples are valid (the annotated
//! `seed-ac` is the built-in machine), and every example message it shows is one the tests in
//! `errors.rs`, `limits.rs` or `text.rs` check.

use model_spec::{ErrorKind, builtin, parse_machine};

const DOC: &str = include_str!("../../../docs/model-spec.md");
/// The tests that check messages in full.
const MESSAGE_TESTS: [&str; 3] = [
    include_str!("errors.rs"),
    include_str!("limits.rs"),
    include_str!("text.rs"),
];

/// The ```toml blocks of the page that are complete machines (fragments start with
/// `# fragment`).
fn toml_machines() -> Vec<&'static str> {
    DOC.split("```toml\n")
        .skip(1)
        .map(|rest| rest.split("\n```").next().unwrap())
        .filter(|block| !block.starts_with("# fragment"))
        .collect()
}

#[test]
fn complete_examples_are_valid() {
    let blocks = toml_machines();
    assert_eq!(
        blocks.len(),
        2,
        "the seed-ac example and the three-axis example"
    );
    for block in &blocks {
        parse_machine("docs/model-spec.md", block).unwrap_or_else(|e| panic!("{e}\n{block}"));
    }
}

#[test]
fn annotated_seed_ac_is_the_builtin() {
    let block = toml_machines()
        .into_iter()
        .find(|b| b.starts_with("name = \"seed-ac\""))
        .expect("the worked example");
    let doc = parse_machine("docs/model-spec.md", block).unwrap();
    assert_eq!(doc, builtin("seed-ac").unwrap().unwrap());
}

#[test]
fn three_axis_example_is_as_described() {
    let block = toml_machines()
        .into_iter()
        .find(|b| b.starts_with("name = \"mill3\""))
        .expect("the three-axis example");
    let m = parse_machine("docs/model-spec.md", block).unwrap();
    assert_eq!(m.catalogue.len(), 24);
    assert_eq!(m.errors, (0..21).collect::<Vec<_>>());
    let squareness: Vec<&str> = m
        .catalogue
        .iter()
        .filter(|e| matches!(e.kind, ErrorKind::Squareness { .. }))
        .map(|e| e.name.as_str())
        .collect();
    assert_eq!(squareness, ["COY", "AOZ", "BOZ"]);

    let reordered = block.replace(
        "[errors]\n",
        "[errors]\nsquareness_order = [\"Y\", \"X\", \"Z\"]\n",
    );
    let m = parse_machine("docs/model-spec.md", &reordered).unwrap();
    assert!(
        ["COX", "AOZ", "BOZ"]
            .iter()
            .all(|n| m.error_by_name(n).is_some())
    );
}

#[test]
fn example_messages_are_tested() {
    let tests = MESSAGE_TESTS.concat().replace("\\\"", "\"");
    let mut count = 0;
    for cell in DOC.split("``").chain(DOC.split('`')) {
        let cell = cell.trim();
        if cell.starts_with("m.toml:") && cell.len() > 12 {
            count += 1;
            assert!(
                tests.contains(cell),
                "the message `{cell}` of docs/model-spec.md is not checked in tests/all/errors.rs, limits.rs or text.rs"
            );
        }
    }
    assert!(count >= 50, "found only {count} example messages");
}
