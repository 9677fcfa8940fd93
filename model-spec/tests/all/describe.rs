//! `model_spec::describe`: the text of `rtest machines`.

use model_spec::describe::describe;
use model_spec::{all_builtin, builtin, parse_machine};

/// What `rtest machines --machine seed-ac` prints.
const SEED_AC: &str = r#"seed-ac: Five-axis machine of the seed paper: X table, A tilting and C rotary table on the work side; Y and Z on the tool side.
  work chain: bed -> X -> A -> C -> ball
  tool chain: bed -> Y -> Z -> holder -> probe
  axes:
    X   linear  direction +x  stroke -500 .. 500 mm       work chain, offset [0, 0, 0] mm
    A   rotary  direction +x  range -120 .. 120 deg       work chain, offset [Xa, Ya, Za] mm
    C   rotary  direction +z  range unlimited             work chain, offset [0, 0, Zc] mm
    Y   linear  direction +y  stroke -400 .. 400 mm       tool chain, offset [0, 0, 0] mm
    Z   linear  direction +z  stroke -500 .. 500 mm       tool chain, offset [Xz, Yz, Zz] mm
  kinematic symbols (defaults, mm): Xa = 0, Ya = 0, Za = 0, Zc = 29.794, Xw = -217.504, Yw = -0.279, Zw = 211.537, Xz = 0, Yz = 0, Zz = 0, Xh = 0, Zh = 0, Zp = 184.67
  errors (44 of the 44 of its topology; translational in µm, angular in µrad): EXX EYX EZX EAX EBX ECX EXY EYY EZY EAY EBY ECY EXZ EYZ EZZ EAZ EBZ ECZ COX AOZ BOZ XOW YOW ZOW EXA EYA EZA EAA EBA ECA YOA ZOA BOA COA EXC EYC EZC EAC EBC ECC XOC YOC AOC BOC
  models:
    full (44 errors): every error of the machine's model
    reduced (11 errors): The seed's Table 2: ball set-up errors and the location errors of A and C.
      XOW YOW ZOW YOA ZOA BOA COA XOC YOC AOC BOC
"#;

#[test]
fn seed_ac() {
    let m = builtin("seed-ac").unwrap().unwrap();
    assert_eq!(describe(&m), SEED_AC);
}

#[test]
fn every_builtin() {
    for m in all_builtin() {
        let text = describe(&m);
        assert!(text.starts_with(&format!("{}: {}\n", m.name, m.description)));
        assert!(text.ends_with('\n'));
        assert_eq!(
            text.lines()
                .filter(|l| l.contains(" chain, offset ["))
                .count(),
            m.axes.len()
        );
        for name in m.models.keys() {
            assert!(text.contains(&format!("\n    {name} (")), "{name}");
        }
    }
}

#[test]
fn no_symbols_and_fractions() {
    let m = parse_machine(
        "m.toml",
        r#"name = "plain"
description = "no symbols"
[[work]]
end = "ball"
[[tool]]
axis = "X"
type = "linear"
direction = "-x"
offset = [0.1234567, -0.0, 1e-9]
stroke = [-0.5, 12.25]
[[tool]]
axis = "B"
type = "rotary"
direction = "+y"
range = [-90, 0]
[[tool]]
end = "probe"
"#,
    )
    .unwrap();
    assert_eq!(
        describe(&m),
        "plain: no symbols
  work chain: bed -> ball
  tool chain: bed -> X -> B -> probe
  axes:
    X   linear  direction -x  stroke -0.5 .. 12.25 mm     tool chain, offset [0.123457, 0, 0] mm
    B   rotary  direction +y  range -90 .. 0 deg          tool chain, offset [0, 0, 0] mm
  kinematic symbols: none
  errors (19 of the 19 of its topology; translational in µm, angular in µrad): EXX EYX EZX EAX EBX ECX XOW YOW ZOW EXB EYB EZB EAB EBB ECB XOB ZOB AOB COB
  models:
    full (19 errors): every error of the machine's model
"
    );
}
