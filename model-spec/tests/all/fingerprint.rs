//! `Machine::fingerprint`: stable, unchanged by what is not the machine (the ball's position,
//! sub-models, descriptions), changed by what is.

use model_spec::write::append_model;
use model_spec::{BUILTIN, Machine, builtin, parse_machine};

const SEED_AC: &str = BUILTIN[0].1;

fn machine(text: &str) -> Machine {
    parse_machine("m.toml", text).unwrap_or_else(|e| panic!("{e}"))
}

/// The fingerprint of `seed-ac` with `old` (once in its text) replaced by `new`.
fn edited(old: &str, new: &str) -> String {
    assert_eq!(SEED_AC.matches(old).count(), 1, "`{old}`");
    machine(&SEED_AC.replacen(old, new, 1)).fingerprint()
}

fn seed_ac() -> String {
    builtin("seed-ac").unwrap().unwrap().fingerprint()
}

#[test]
fn pinned_value_for_seed_ac() {
    // Pinned: a change here invalidates every fingerprint written before it.
    assert_eq!(seed_ac(), "fa038fe9e24c960a");
    let f = seed_ac();
    assert_eq!(f.len(), 16);
    assert!(
        f.chars()
            .all(|c| c.is_ascii_hexdigit() && !c.is_ascii_uppercase())
    );
}

#[test]
fn builtins_differ() {
    let all: Vec<String> = BUILTIN
        .iter()
        .map(|(n, _)| builtin(n).unwrap().unwrap().fingerprint())
        .collect();
    for i in 0..all.len() {
        for j in 0..i {
            assert_ne!(all[i], all[j]);
        }
    }
}

#[test]
fn workpiece_symbols() {
    let m = builtin("seed-ac").unwrap().unwrap();
    let names: Vec<&str> = m
        .workpiece_symbols()
        .into_iter()
        .map(|s| m.symbols[s].name.as_str())
        .collect();
    assert_eq!(names, ["Xw", "Yw", "Zw"]);
    // On seed-3axis the workpiece origin is a fixed link: its symbols are the machine's.
    let m = builtin("seed-3axis").unwrap().unwrap();
    let names: Vec<&str> = m
        .workpiece_symbols()
        .into_iter()
        .map(|s| m.symbols[s].name.as_str())
        .collect();
    assert_eq!(names, ["Xw", "Yw", "Zw"]);
}

#[test]
fn unchanged_by_what_is_not_the_machine() {
    let f = seed_ac();
    // The ball moved.
    assert_eq!(edited("Xw = -217.504", "Xw = 100"), f);
    assert_eq!(edited("Zw = 211.537", "Zw = 0"), f);
    // Descriptions, the name, comments, sub-models, the full model, strokes and ranges.
    assert_eq!(
        edited("description = \"Five-axis", "description = \"A five-axis"),
        f
    );
    assert_eq!(edited("name = \"seed-ac\"", "name = \"my-ac\""), f);
    assert_eq!(edited("# Work chain", "# The work chain"), f);
    assert_eq!(
        edited(
            "description = \"The seed's Table 2",
            "description = \"Table 2"
        ),
        f
    );
    assert_eq!(edited("[models.reduced]", "[models.small]"), f);
    let no_models = SEED_AC.split("[models.reduced]").next().unwrap();
    assert_eq!(machine(no_models).fingerprint(), f);
    assert_eq!(
        machine(&format!("{SEED_AC}\n[errors]\nexclude = [\"EXX\"]\n")).fingerprint(),
        f
    );
    assert_eq!(
        edited("stroke = [-400.0, 400.0]", "stroke = [-600.0, 600.0]"),
        f
    );
    assert_eq!(
        edited("range = [-120.0, 120.0]", "range = [-90.0, 120.0]"),
        f
    );
    assert_eq!(edited("link = \"holder\"", "link = \"spindle\""), f);
    // The same numbers written otherwise.
    assert_eq!(edited("Zc = 29.794", "Zc = 29.7940"), f);
    assert_eq!(
        edited("offset = [0, 0, \"Zc\"]", "offset = [-0.0, 0.0, \"Zc\"]"),
        f
    );
    assert_eq!(
        edited(
            "direction = \"+z\"\noffset = [0, 0",
            "direction = \"Z\"\noffset = [0, 0"
        ),
        f
    );
    // A model appended.
    let m = builtin("seed-ac").unwrap().unwrap();
    let terms = vec!["XOC".to_string(), "ECC@harmonic:2".to_string()];
    let (_, text) = append_model(&m, SEED_AC, &terms, "found").unwrap();
    assert_eq!(machine(&text).fingerprint(), f);
}

#[test]
fn changed_by_the_machine() {
    let f = seed_ac();
    let changes = [
        // C turns the other way.
        edited(
            "direction = \"+z\"\noffset = [0, 0",
            "direction = \"-z\"\noffset = [0, 0",
        ),
        // A machine-side symbol.
        edited("Zc = 29.794", "Zc = 29.795"),
        edited("Zp = 184.670", "Zp = 184"),
        edited("Xa = 0.0", "Xa = 0.001"),
        // An offset: a number instead of a symbol, or another number.
        edited("offset = [0, 0, \"Zc\"]", "offset = [0, 0, 29.794]"),
        edited(
            "offset = [\"Xh\", 0, \"Zh\"]",
            "offset = [\"Xh\", 1, \"Zh\"]",
        ),
        // A linear axis declared rotary.
        edited(
            "axis = \"Y\"\ntype = \"linear\"\ndirection = \"+y\"\nstroke = [-400.0, 400.0]",
            "axis = \"Y\"\ntype = \"rotary\"\ndirection = \"+y\"\nrange = [-400.0, 400.0]",
        ),
        // Another squareness order.
        machine(&format!(
            "{SEED_AC}\n[errors]\nsquareness_order = [\"X\", \"Y\", \"Z\"]\n"
        ))
        .fingerprint(),
        // A symbol renamed (and its uses).
        machine(&SEED_AC.replace("Zc", "Zt")).fingerprint(),
        // The symbols in another order.
        edited("Xa = 0.0\nYa = 0.0\n", "Ya = 0.0\nXa = 0.0\n"),
    ];
    for (i, g) in changes.iter().enumerate() {
        assert_ne!(*g, f, "change {i}");
    }
}

#[test]
fn changed_by_swapping_two_axes() {
    // Y and Z of the tool chain swapped (Z's offset stays with Z).
    let y =
        "[[tool]]\naxis = \"Y\"\ntype = \"linear\"\ndirection = \"+y\"\nstroke = [-400.0, 400.0]\n";
    let z = "[[tool]]\naxis = \"Z\"\ntype = \"linear\"\ndirection = \"+z\"\noffset = [\"Xz\", \"Yz\", \"Zz\"]\nstroke = [-500.0, 500.0]\n";
    let original = format!("{y}\n{z}");
    assert_eq!(SEED_AC.matches(&original).count(), 1);
    let swapped = SEED_AC.replace(&original, &format!("{z}\n{y}"));
    assert_ne!(machine(&swapped).fingerprint(), seed_ac());
    // A and C swapped on the work chain (each entry whole, with its offset and range).
    let a = "[[work]]\naxis = \"A\"\ntype = \"rotary\"\ndirection = \"+x\"\noffset = [\"Xa\", \"Ya\", \"Za\"]\nrange = [-120.0, 120.0]\n";
    let c =
        "[[work]]\naxis = \"C\"\ntype = \"rotary\"\ndirection = \"+z\"\noffset = [0, 0, \"Zc\"]\n";
    let original = format!("{a}\n{c}");
    assert_eq!(SEED_AC.matches(&original).count(), 1);
    let swapped = SEED_AC.replace(&original, &format!("{c}\n{a}"));
    assert_ne!(machine(&swapped).fingerprint(), seed_ac());
}

#[test]
fn a_ball_symbol_used_on_the_machine_too_is_the_machines() {
    // Xw also places the holder: it is machine-side, its value counts.
    let text = SEED_AC.replace(
        "offset = [\"Xh\", 0, \"Zh\"]",
        "offset = [\"Xw\", 0, \"Zh\"]",
    );
    let m = machine(&text);
    let names: Vec<&str> = m
        .workpiece_symbols()
        .into_iter()
        .map(|s| m.symbols[s].name.as_str())
        .collect();
    assert_eq!(names, ["Yw", "Zw"]);
    let moved = machine(&text.replace("Xw = -217.504", "Xw = 100"));
    assert_ne!(moved.fingerprint(), m.fingerprint());
    let moved = machine(&text.replace("Yw = -0.279", "Yw = 100"));
    assert_eq!(moved.fingerprint(), m.fingerprint());
}
