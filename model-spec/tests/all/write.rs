//! `model_spec::write`: a machine's text, and the text with a model appended, read back.

use model_spec::basis::Basis;
use model_spec::terms::{Effect, Term};
use model_spec::text::TextError;
use model_spec::write::{AppendError, append_model, source_text};
use model_spec::{BUILTIN, LoadError, Machine, builtin, parse_machine};

fn machine(name: &str) -> Machine {
    builtin(name).unwrap().unwrap()
}

fn strings(v: &[&str]) -> Vec<String> {
    v.iter().map(|s| s.to_string()).collect()
}

/// Every term the built-in machine `m` can have with a few bases: each error of its full
/// model constant, the component errors of each axis with their axis's own basis of order 2,
/// and the sensor offsets drifting.
fn many_terms(m: &Machine) -> Vec<String> {
    let mut out: Vec<String> = m
        .errors
        .iter()
        .map(|&e| m.catalogue[e].name.clone())
        .collect();
    for &e in &m.errors {
        let term = Term::parse(m, &format!("{}@harmonic:2", m.catalogue[e].name))
            .or_else(|_| Term::parse(m, &format!("{}@poly:2", m.catalogue[e].name)));
        if let Ok(t) = term {
            out.push(t.spelling(m));
        }
    }
    out.extend(strings(&["dx0@time:1", "dy0", "dz0@time:2"]));
    out
}

#[test]
fn source_text_of_the_builtins() {
    for (name, text) in BUILTIN {
        assert_eq!(source_text(name).unwrap(), *text);
    }
    assert!(matches!(
        source_text("no/such/machine.toml"),
        Err(LoadError::NotFound(_))
    ));
}

#[test]
fn source_text_of_a_file() {
    let dir = std::env::temp_dir().join(format!(
        "model-spec-write-{}-{}",
        std::process::id(),
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .unwrap()
            .as_nanos()
    ));
    std::fs::create_dir(&dir).unwrap();
    let p = dir.join("m.toml");
    std::fs::write(
        &p,
        [b"\xef\xbb\xbf".as_slice(), BUILTIN[1].1.as_bytes()].concat(),
    )
    .unwrap();
    let path = p.to_str().unwrap();
    // The byte-order mark is dropped, as when the machine is loaded.
    assert_eq!(source_text(path).unwrap(), BUILTIN[1].1);
    std::fs::write(&p, b"name = \"x\"\n# \xff\n").unwrap();
    let e = source_text(path).unwrap_err();
    assert!(
        matches!(
            e,
            LoadError::Io(TextError::NotUtf8 {
                line: 2,
                column: 3,
                ..
            })
        ),
        "{e:?}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn round_trip_on_every_builtin() {
    for (name, text) in BUILTIN {
        let m = machine(name);
        let terms = many_terms(&m);
        assert!(terms.len() > 20, "{name}");
        let (model, out) = append_model(&m, text, &terms, "  found by a test  ").unwrap();
        assert_eq!(model, "extended", "{name}");
        assert!(
            out.starts_with(text),
            "{name}: the original text is kept as it is"
        );
        let back = parse_machine("back.toml", &out).unwrap();
        let sub = &back.models["extended"];
        assert_eq!(sub.description, "found by a test");
        let spelled: Vec<String> = sub.terms.iter().map(|t| t.spelling(&back)).collect();
        assert_eq!(spelled, terms, "{name}: the terms in the order given");
        let mut without = back.clone();
        without.models.remove("extended");
        assert_eq!(without, m, "{name}: the same machine");
        for line in out[text.len()..].lines() {
            assert!(line.chars().count() < 100, "{name}: line too long: {line}");
        }
        // The appended part, term lines included, is as documented.
        let appended = &out[text.len()..];
        assert!(
            appended.starts_with("\n# Model extended, appended by rtest.\n[models.extended]\ndescription = \"found by a test\"\nerrors = [\n    \""),
            "{appended}"
        );
        assert!(appended.ends_with("\"\n]\n"), "{appended}");
    }
}

#[test]
fn exact_layout() {
    let m = machine("seed-ac");
    let terms = strings(&["XOC", "x0c@const", "ECC@harmonic:2", "dz0@time:1"]);
    // `x0c@const` is `XOC`: given twice.
    let e = append_model(&m, BUILTIN[0].1, &terms, "d").unwrap_err();
    assert!(
        matches!(&e, AppendError::Duplicate { term } if term == "x0c@const"),
        "{e:?}"
    );
    assert_eq!(e.to_string(), "term `x0c@const` is given twice");

    let terms = strings(&["x0c", "ECC@harmonic:2", "dz0@time:1"]);
    let (_, out) = append_model(&m, BUILTIN[0].1, &terms, "d").unwrap();
    assert_eq!(
        &out[BUILTIN[0].1.len()..],
        "\n# Model extended, appended by rtest.\n[models.extended]\ndescription = \"d\"\nerrors = [\n    \"XOC\", \"ECC@harmonic:2\", \"dz0@time:1\"\n]\n"
    );
}

#[test]
fn name_taken() {
    let m = machine("seed-ac");
    let terms = strings(&["XOC", "YOC"]);
    let (first, text) = append_model(&m, BUILTIN[0].1, &terms, "first").unwrap();
    assert_eq!(first, "extended");
    let m2 = parse_machine("m.toml", &text).unwrap();
    let (second, text) = append_model(&m2, &text, &terms, "second").unwrap();
    assert_eq!(second, "extended2");
    let m3 = parse_machine("m.toml", &text).unwrap();
    assert_eq!(m3.models["extended"].description, "first");
    assert_eq!(m3.models["extended2"].description, "second");
    let (third, _) = append_model(&m3, &text, &terms, "third").unwrap();
    assert_eq!(third, "extended3");
}

#[test]
fn descriptions_with_quotes_and_non_ascii_text() {
    let m = machine("head-table-bc");
    let text = BUILTIN[2].1;
    for description in [
        r#"reduced + "ECC" twice per revolution \ drift"#,
        "Maschine «Fräse» — Δ 3 µm, 角度 ✓ 🛠",
        "two\nlines\tand a tab, a bell \u{7} and a delete \u{7f}",
        "'single' and '''triple''' quotes, \"\"\" too",
        "",
    ] {
        let (name, out) =
            append_model(&m, text, &strings(&["XOC", "ECC@harmonic:1"]), description).unwrap();
        let back = parse_machine("m.toml", &out).unwrap();
        // Control characters are written as `<U+XXXX>`: a description may not hold them.
        let visible = description
            .trim()
            .replace('\u{7}', "<U+0007>")
            .replace('\u{7f}', "<U+007F>");
        assert_eq!(back.models[&name].description, visible, "{out}");
    }
}

#[test]
fn text_without_final_newline() {
    let m = machine("seed-3axis");
    let text = BUILTIN[1].1.trim_end();
    let (_, out) = append_model(&m, text, &strings(&["EXX"]), "d").unwrap();
    assert!(out.contains("\nexclude = [\"XOW\", \"YOW\", \"ZOW\"]\n\n# Model extended"));
    parse_machine("m.toml", &out).unwrap();
}

#[test]
fn empty_model() {
    let m = machine("seed-ac");
    let (name, out) = append_model(&m, BUILTIN[0].1, &[], "nothing").unwrap();
    let back = parse_machine("m.toml", &out).unwrap();
    assert!(back.models[&name].terms.is_empty());
}

#[test]
fn refused_terms() {
    let m = machine("seed-3axis");
    let e = append_model(&m, BUILTIN[1].1, &strings(&["EXX", "XOC"]), "d").unwrap_err();
    assert!(
        matches!(&e, AppendError::Term { term, .. } if term == "XOC"),
        "{e:?}"
    );
    assert_eq!(
        e.to_string(),
        "term `XOC`: `XOC` is neither an error of machine seed-3axis nor dx0/dy0/dz0 nor an instrument term SXX … SZY"
    );
    // In the catalogue but left out of the full model by `exclude`.
    let e = append_model(&m, BUILTIN[1].1, &strings(&["XOW"]), "d").unwrap_err();
    assert_eq!(
        e.to_string(),
        "term `XOW`: error XOW is not in the full model of machine seed-3axis"
    );
    let e = append_model(&m, BUILTIN[1].1, &strings(&["EXX@harmonic:1"]), "d").unwrap_err();
    assert_eq!(
        e.to_string(),
        "term `EXX@harmonic:1`: EXX: `harmonic:1` needs an error of a rotary axis"
    );
}

#[test]
fn text_of_another_machine() {
    let m = machine("seed-ac");
    // Another machine's text.
    let e = append_model(&m, BUILTIN[2].1, &strings(&["XOC"]), "d").unwrap_err();
    assert!(matches!(e, AppendError::NotSameMachine { .. }), "{e:?}");
    assert_eq!(
        e.to_string(),
        "the machine description with the model `extended` appended does not read back as machine `seed-ac` with that model: is the text that of the machine?"
    );
    // The same machine with another symbol value.
    let moved = BUILTIN[0].1.replace("Zc = 29.794", "Zc = 30");
    let e = append_model(&m, &moved, &strings(&["XOC"]), "d").unwrap_err();
    assert!(matches!(e, AppendError::NotSameMachine { .. }), "{e:?}");
    // Not a description at all.
    let e = append_model(&m, "name = ", &strings(&["XOC"]), "d").unwrap_err();
    assert!(matches!(e, AppendError::Reparse { .. }), "{e:?}");
    assert!(
        e.to_string().starts_with("the machine description with the model `extended` appended does not read back: <seed-ac with model extended>:1:"),
        "{e}"
    );
}

#[test]
fn terms_as_the_solver_spells_them() {
    // The spellings `Term::spelling` gives are accepted back.
    let m = machine("seed-ac");
    let ecc = m.error_by_name("ECC").unwrap();
    let t = Term::new(&m, Effect::Error(ecc), Basis::Harmonic(3)).unwrap();
    let (name, out) = append_model(&m, BUILTIN[0].1, &[t.spelling(&m)], "d").unwrap();
    assert_eq!(
        parse_machine("m.toml", &out).unwrap().models[&name].terms,
        [t]
    );
}
