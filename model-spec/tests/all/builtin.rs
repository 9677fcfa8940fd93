//! The built-in machines, the error catalogue and its naming rules.

use model_spec::{
    AxisKind, BUILTIN, Dir, Direction, ErrorId, ErrorKind, FULL_MODEL, LoadError, Machine, Side,
    Value, all_builtin, builtin, canonical_name, load_machine, parse_machine,
};

fn names<'a>(m: &'a Machine, ids: &[ErrorId]) -> Vec<&'a str> {
    ids.iter().map(|&i| m.catalogue[i].name.as_str()).collect()
}

fn catalogue(m: &Machine) -> Vec<&str> {
    m.catalogue.iter().map(|e| e.name.as_str()).collect()
}

fn words(s: &str) -> Vec<&str> {
    s.split_whitespace().collect()
}

fn seed_ac() -> Machine {
    builtin("seed-ac").expect("listed").expect("valid")
}

const SEED_AC_TABLE_1: &str = "EXX EYX EZX EAX EBX ECX EXY EYY EZY EAY EBY ECY EXZ EYZ EZZ EAZ EBZ ECZ \
     COX AOZ BOZ XOW YOW ZOW EXA EYA EZA EAA EBA ECA YOA ZOA BOA COA EXC EYC EZC EAC EBC ECC \
     XOC YOC AOC BOC";

#[test]
fn every_builtin_validates() {
    for (name, text) in BUILTIN {
        let m = parse_machine(name, text).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(m.name, *name, "the name in the file is the built-in name");
        assert!(!m.description.is_empty());
    }
    let all = all_builtin();
    assert_eq!(
        all.iter().map(|m| m.name.as_str()).collect::<Vec<_>>(),
        [
            "seed-ac",
            "seed-3axis",
            "head-table-bc",
            "table-table-bc",
            "head-head-ca",
            "nutating-head-bc",
            "nutating-table-bc",
            "horizontal-4axis-b"
        ]
    );
    assert!(builtin("no-such-machine").is_none());
}

#[test]
fn seed_ac_has_the_44_errors_of_table_1_in_order() {
    let m = seed_ac();
    assert_eq!(catalogue(&m), words(SEED_AC_TABLE_1));
    assert_eq!(m.catalogue.len(), 44);
    assert_eq!(names(&m, &m.errors), words(SEED_AC_TABLE_1));
    assert_eq!(m.model_errors(FULL_MODEL), Some(&m.errors[..]));
}

#[test]
fn seed_ac_reduced_model_is_table_2() {
    let m = seed_ac();
    assert_eq!(m.model_names(), ["full", "reduced"]);
    let reduced = m.model_errors("reduced").unwrap();
    assert_eq!(
        names(&m, reduced),
        words("XOW YOW ZOW YOA ZOA BOA COA XOC YOC AOC BOC")
    );
    assert!(m.models["reduced"].description.contains("Table 2"));
    assert!(m.model_errors("nothing").is_none());
}

#[test]
fn seed_ac_axes_symbols_and_chains() {
    let m = seed_ac();
    let axes: Vec<(&str, AxisKind, Side, Direction)> = m
        .axes
        .iter()
        .map(|a| {
            (
                a.name.as_str(),
                a.kind,
                a.side,
                a.direction.as_coordinate().unwrap(),
            )
        })
        .collect();
    let plus = |dir| Direction {
        dir,
        negative: false,
    };
    assert_eq!(
        axes,
        [
            ("X", AxisKind::Linear, Side::Work, plus(Dir::X)),
            ("A", AxisKind::Rotary, Side::Work, plus(Dir::X)),
            ("C", AxisKind::Rotary, Side::Work, plus(Dir::Z)),
            ("Y", AxisKind::Linear, Side::Tool, plus(Dir::Y)),
            ("Z", AxisKind::Linear, Side::Tool, plus(Dir::Z)),
        ]
    );
    assert_eq!(m.axes[0].limits, [-500.0, 500.0]);
    assert_eq!(m.axes[1].limits, [-120.0, 120.0]);
    assert_eq!(m.axes[2].limits, [f64::NEG_INFINITY, f64::INFINITY]);
    assert_eq!(m.rotary_axes().collect::<Vec<_>>(), [1, 2]);
    assert_eq!(m.linear_axes().collect::<Vec<_>>(), [0, 3, 4]);

    // Symbols in the order of the file, with the seed's Table 3 values.
    let symbols: Vec<&str> = m.symbols.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(symbols, words("Xa Ya Za Zc Xw Yw Zw Xz Yz Zz Xh Zh Zp"));
    assert_eq!(
        m.default_parameters(),
        [
            0.0, 0.0, 0.0, 29.794, -217.504, -0.279, 211.537, 0.0, 0.0, 0.0, 0.0, 0.0, 184.670
        ]
    );
    let s = |n: &str| Value::Symbol(m.symbol_by_name(n).unwrap());
    let n = Value::Number;
    assert_eq!(m.axes[1].offset, [s("Xa"), s("Ya"), s("Za")]);
    assert_eq!(m.axes[2].offset, [n(0.0), n(0.0), s("Zc")]);
    assert_eq!(m.work.end_name, "ball");
    assert_eq!(m.work.end_offset, [s("Xw"), s("Yw"), s("Zw")]);
    assert_eq!(m.tool.end_name, "probe");
    assert_eq!(m.tool.end_offset, [n(0.0), n(0.0), s("Zp")]);
    assert_eq!(m.tool.links.len(), 3);
    assert_eq!(
        m.tool.links[2],
        model_spec::Link::Fixed {
            name: "holder".into(),
            offset: [s("Xh"), n(0.0), s("Zh")]
        }
    );
    assert_eq!(m.chain(Side::Work), &m.work);
    assert_eq!(m.chain(Side::Tool), &m.tool);
}

#[test]
fn seed_ac_squareness_order_is_y_x_z() {
    let m = seed_ac();
    let order: Vec<&str> = m
        .squareness_order
        .iter()
        .map(|&i| m.axes[i].name.as_str())
        .collect();
    assert_eq!(order, ["Y", "X", "Z"]);
    let kinds: Vec<ErrorKind> = ["COX", "AOZ", "BOZ"]
        .iter()
        .map(|n| m.catalogue[m.error_by_name(n).unwrap()].kind)
        .collect();
    assert_eq!(
        kinds,
        [
            ErrorKind::Squareness {
                axis: 0,
                about: Dir::Z
            },
            ErrorKind::Squareness {
                axis: 4,
                about: Dir::X
            },
            ErrorKind::Squareness {
                axis: 4,
                about: Dir::Y
            },
        ]
    );
}

#[test]
fn error_terms_kinds_and_units() {
    let m = seed_ac();
    let term = |n: &str| &m.catalogue[m.error_by_name(n).unwrap()];
    use model_spec::Motion::{Rotation, Translation};
    assert_eq!(
        term("EYX").kind,
        ErrorKind::Component {
            axis: 0,
            motion: Translation(Dir::Y)
        }
    );
    assert_eq!(
        term("ECC").kind,
        ErrorKind::Component {
            axis: 2,
            motion: Rotation(Dir::Z)
        }
    );
    assert_eq!(
        term("YOA").kind,
        ErrorKind::Location {
            axis: 1,
            motion: Translation(Dir::Y)
        }
    );
    assert_eq!(
        term("BOC").kind,
        ErrorKind::Location {
            axis: 2,
            motion: Rotation(Dir::Y)
        }
    );
    assert_eq!(term("ZOW").kind, ErrorKind::Setup { along: Dir::Z });
    assert_eq!((term("XOC").unit(), term("AOC").unit()), ("um", "urad"));
    assert_eq!((term("COX").unit(), term("ZOW").unit()), ("urad", "um"));
    assert_eq!(term("ZOW").axis(), None);
    assert_eq!(term("AOZ").axis(), Some(4));
}

#[test]
fn seed_3axis_has_21_errors() {
    let m = builtin("seed-3axis").unwrap().unwrap();
    let expected = words(
        "EXX EYX EZX EAX EBX ECX EXY EYY EZY EAY EBY ECY EXZ EYZ EZZ EAZ EBZ ECZ COX AOZ BOZ",
    );
    assert_eq!(names(&m, &m.errors), expected);
    // The catalogue still has the set-up errors; the [errors] table excludes them.
    assert_eq!(m.catalogue.len(), 24);
    assert_eq!(&catalogue(&m)[21..], ["XOW", "YOW", "ZOW"]);
    assert!(m.work.links.len() == 1 && m.axes.iter().all(|a| a.side == Side::Tool));
}

#[test]
fn head_table_bc_squareness_and_location_errors() {
    let m = builtin("head-table-bc").unwrap().unwrap();
    let all = catalogue(&m);
    let squareness: Vec<&str> = m
        .catalogue
        .iter()
        .filter(|e| matches!(e.kind, ErrorKind::Squareness { .. }))
        .map(|e| e.name.as_str())
        .collect();
    assert_eq!(squareness, ["COY", "AOZ", "BOZ"]);
    let location: Vec<&str> = m
        .catalogue
        .iter()
        .filter(|e| matches!(e.kind, ErrorKind::Location { .. }))
        .map(|e| e.name.as_str())
        .collect();
    assert_eq!(location, words("XOB ZOB AOB COB XOC YOC AOC BOC"));
    assert_eq!(all.len(), 44);
    assert_eq!(&all[18..24], words("COY AOZ BOZ XOW YOW ZOW"));
    assert_eq!(
        &all[24..34],
        words("EXB EYB EZB EAB EBB ECB XOB ZOB AOB COB")
    );
    assert_eq!(
        names(&m, m.model_errors("location").unwrap()),
        words("COY AOZ BOZ XOW YOW ZOW XOB ZOB AOB COB XOC YOC AOC BOC")
    );
}

#[test]
fn canonical_names() {
    assert_eq!(canonical_name("X0C"), "XOC");
    assert_eq!(canonical_name("c0x"), "COX");
    assert_eq!(canonical_name(" exx "), "EXX");
    // Only the middle letter of a three-letter name is read as O.
    assert_eq!(canonical_name("0XC"), "0XC");
    assert_eq!(canonical_name("X0CC"), "X0CC");
}

#[test]
fn digit_zero_alias_by_name() {
    let m = seed_ac();
    assert_eq!(m.error_by_name("X0C"), m.error_by_name("XOC"));
    assert_eq!(m.error_by_name("C0X"), m.error_by_name("COX"));
    assert_eq!(m.error_by_name("x0w"), m.error_by_name("XOW"));
    assert!(m.error_by_name("XOC").is_some());
    assert!(m.error_by_name("X0A").is_none());
}

#[test]
fn digit_zero_alias_in_the_description() {
    let text = BUILTIN[0].1.replace(
        r#"errors = ["XOW", "YOW", "ZOW", "YOA", "ZOA", "BOA", "COA", "XOC", "YOC", "AOC", "BOC"]"#,
        r#"errors = ["X0W", "Y0C", "C0X"]"#,
    ) + "\n[errors]\ninclude = [\"X0W\", \"XOC\", \"Y0C\", \"C0X\", \"A0Z\", \"EXX\"]\nexclude = [\"a0z\", \"X0C\"]\n";
    let m = parse_machine("alias.toml", &text).unwrap();
    assert_eq!(names(&m, &m.errors), ["EXX", "COX", "XOW", "YOC"]);
    assert_eq!(
        names(&m, m.model_errors("reduced").unwrap()),
        ["COX", "XOW", "YOC"]
    );
}

/// A three-axis machine: the tool chain carries Y, X, Z (like the seed's three-axis machine).
const THREE_AXIS: &str = r#"
name = "three"

[[work]]
end = "workpiece"

[[tool]]
axis = "Y"
type = "linear"
direction = "+y"
stroke = [-300, 300]

[[tool]]
axis = "X"
type = "linear"
direction = "+x"
stroke = [-400, 400]

[[tool]]
axis = "Z"
type = "linear"
direction = "+z"
stroke = [-300, 300]

[[tool]]
end = "tool"
"#;

fn squareness_names(m: &Machine) -> Vec<&str> {
    m.catalogue
        .iter()
        .filter(|e| matches!(e.kind, ErrorKind::Squareness { .. }))
        .map(|e| e.name.as_str())
        .collect()
}

#[test]
fn default_squareness_order_follows_the_chain() {
    let m = parse_machine("three.toml", THREE_AXIS).unwrap();
    assert_eq!(squareness_names(&m), ["COX", "AOZ", "BOZ"]);
    assert_eq!(m.squareness_order, [0, 1, 2]);
    assert_eq!(model_spec::default_squareness_order(&m.axes), [0, 1, 2]);
    assert_eq!(m.errors.len(), 24);
}

#[test]
fn explicit_squareness_order() {
    let text = format!("{THREE_AXIS}\n[errors]\nsquareness_order = [\"X\", \"Y\", \"Z\"]\n");
    let m = parse_machine("three.toml", &text).unwrap();
    assert_eq!(squareness_names(&m), ["COY", "AOZ", "BOZ"]);
    let order: Vec<&str> = m
        .squareness_order
        .iter()
        .map(|&i| m.axes[i].name.as_str())
        .collect();
    assert_eq!(order, ["X", "Y", "Z"]);

    let text = format!("{THREE_AXIS}\n[errors]\nsquareness_order = [\"Z\", \"X\", \"Y\"]\n");
    let m = parse_machine("three.toml", &text).unwrap();
    assert_eq!(squareness_names(&m), ["BOX", "AOY", "COY"]);
}

#[test]
fn explicit_squareness_order_on_seed_ac() {
    let text = format!(
        "{}\n[errors]\nsquareness_order = [\"X\", \"Y\", \"Z\"]\n",
        BUILTIN[0].1
    );
    let m = parse_machine("seed.toml", &text).unwrap();
    assert_eq!(squareness_names(&m), ["COY", "AOZ", "BOZ"]);
}

#[test]
fn squareness_of_parallel_axes() {
    // A second axis parallel to the reference gets two squareness errors.
    let text = THREE_AXIS.replace(
        r#"axis = "X"
type = "linear"
direction = "+x""#,
        r#"axis = "V"
type = "linear"
direction = "+y""#,
    );
    let m = parse_machine("par.toml", &text).unwrap();
    assert_eq!(squareness_names(&m), ["AOV", "COV", "AOZ", "BOZ"]);
}

#[test]
fn include_and_exclude() {
    let text = format!(
        "{THREE_AXIS}\n[errors]\ninclude = [\"BOZ\", \"EXX\", \"XOW\", \"COX\"]\nexclude = [\"XOW\"]\n"
    );
    let m = parse_machine("three.toml", &text).unwrap();
    // Catalogue order, whatever the order of the list.
    assert_eq!(names(&m, &m.errors), ["EXX", "COX", "BOZ"]);
}

#[test]
fn load_machine_by_name_and_by_path() {
    assert_eq!(load_machine("seed-ac").unwrap().name, "seed-ac");
    match load_machine("no/such/file.toml") {
        Err(LoadError::NotFound(n)) => assert_eq!(n, "no/such/file.toml"),
        other => panic!("{other:?}"),
    }
    let err = load_machine("no/such/file.toml").unwrap_err().to_string();
    assert_eq!(
        err,
        "no built-in machine and no file called `no/such/file.toml` (built-in: seed-ac, seed-3axis, head-table-bc, table-table-bc, head-head-ca, nutating-head-bc, nutating-table-bc, horizontal-4axis-b)"
    );

    let dir = std::env::temp_dir().join(format!("model-spec-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let good = dir.join("three.toml");
    std::fs::write(&good, THREE_AXIS).unwrap();
    let path = good.to_str().unwrap();
    assert_eq!(load_machine(path).unwrap().name, "three");
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, THREE_AXIS.replace("[-400, 400]", "[400, -400]")).unwrap();
    let path = bad.to_str().unwrap();
    let err = load_machine(path).unwrap_err();
    assert!(matches!(err, LoadError::Spec(_)));
    assert_eq!(
        err.to_string(),
        format!("{path}:17:10: axis X: `stroke` minimum 400 is not below maximum -400 (mm)")
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn builtin_errors_name_the_builtin() {
    // A built-in is read under the name `<built-in NAME>`; checked on a copy with an error.
    let text = BUILTIN[0].1.replace("Zc = 29.794", "Zc = nan");
    let err = parse_machine("<built-in seed-ac>", &text).unwrap_err();
    assert_eq!(
        err.to_string(),
        "<built-in seed-ac>:14:6: symbol `Zc` has the non-finite default NaN: give a number (mm)"
    );
}
