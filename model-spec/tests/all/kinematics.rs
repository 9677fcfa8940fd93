//! The composition order of the kinematic chains: `offset · location · component(command)`.

use model_spec::kinematics::{Step, chain_steps};
use model_spec::{Machine, Side, Value, builtin};

fn seed_ac() -> Machine {
    builtin("seed-ac").unwrap().unwrap()
}

/// Shorthands for the expected steps.
struct S<'a>(&'a Machine);

impl S<'_> {
    fn e(&self, name: &str) -> Option<usize> {
        Some(
            self.0
                .error_by_name(name)
                .unwrap_or_else(|| panic!("{name}")),
        )
    }
    fn sym(&self, name: &str) -> Value {
        Value::Symbol(self.0.symbol_by_name(name).unwrap())
    }
    fn t(&self, [x, y, z]: [&str; 3]) -> Step {
        Step::ErrorTranslation([x, y, z].map(|n| if n == "-" { None } else { self.e(n) }))
    }
    fn r(&self, [x, y, z]: [&str; 3]) -> Step {
        Step::ErrorRotation([x, y, z].map(|n| if n == "-" { None } else { self.e(n) }))
    }
    fn motion(&self, axis: &str, positioning_error: Option<&str>) -> Step {
        Step::Motion {
            axis: self.0.axis_by_name(axis).unwrap(),
            positioning_error: positioning_error.map(|n| self.e(n).unwrap()),
        }
    }
}

#[test]
fn seed_ac_work_chain_steps() {
    let m = seed_ac();
    let s = S(&m);
    let n = Value::Number;
    let expected = vec![
        // X (linear, +x, zero offset dropped): squareness, motion, component errors.
        s.r(["-", "-", "COX"]),
        s.motion("X", None),
        s.t(["EXX", "EYX", "EZX"]),
        s.r(["EAX", "EBX", "ECX"]),
        // A (rotary, +x): offset, location, component translations and tilts, motion + EAA.
        Step::Offset([s.sym("Xa"), s.sym("Ya"), s.sym("Za")]),
        s.t(["-", "YOA", "ZOA"]),
        s.r(["-", "BOA", "COA"]),
        s.t(["EXA", "EYA", "EZA"]),
        s.r(["-", "EBA", "ECA"]),
        s.motion("A", Some("EAA")),
        // C (rotary, +z).
        Step::Offset([n(0.0), n(0.0), s.sym("Zc")]),
        s.t(["XOC", "YOC", "-"]),
        s.r(["AOC", "BOC", "-"]),
        s.t(["EXC", "EYC", "EZC"]),
        s.r(["EAC", "EBC", "-"]),
        s.motion("C", Some("ECC")),
        // The ball: its offset, then the set-up errors.
        Step::Offset([s.sym("Xw"), s.sym("Yw"), s.sym("Zw")]),
        s.t(["XOW", "YOW", "ZOW"]),
    ];
    assert_eq!(chain_steps(&m, Side::Work), expected);
}

#[test]
fn seed_ac_tool_chain_steps() {
    let m = seed_ac();
    let s = S(&m);
    let n = Value::Number;
    let expected = vec![
        // Y: reference of the squareness order, zero offset: both dropped.
        s.motion("Y", None),
        s.t(["EXY", "EYY", "EZY"]),
        s.r(["EAY", "EBY", "ECY"]),
        // Z.
        Step::Offset([s.sym("Xz"), s.sym("Yz"), s.sym("Zz")]),
        s.r(["AOZ", "BOZ", "-"]),
        s.motion("Z", None),
        s.t(["EXZ", "EYZ", "EZZ"]),
        s.r(["EAZ", "EBZ", "ECZ"]),
        // The holder, then the probe end (no set-up errors on the tool side).
        Step::Offset([s.sym("Xh"), n(0.0), s.sym("Zh")]),
        Step::Offset([n(0.0), n(0.0), s.sym("Zp")]),
    ];
    assert_eq!(chain_steps(&m, Side::Tool), expected);
}

#[test]
fn head_table_bc_rotary_about_y() {
    let m = builtin("head-table-bc").unwrap().unwrap();
    let s = S(&m);
    let steps = chain_steps(&m, Side::Tool);
    let b = steps
        .iter()
        .position(|st| *st == s.motion("B", Some("EBB")))
        .expect("B's motion carries EBB");
    assert_eq!(
        steps[b - 5..b],
        [
            Step::Offset([s.sym("Xb"), s.sym("Yb"), s.sym("Zb")]),
            s.t(["XOB", "-", "ZOB"]),
            s.r(["AOB", "-", "COB"]),
            s.t(["EXB", "EYB", "EZB"]),
            s.r(["EAB", "-", "ECB"]),
        ]
    );
    // X is the reference of the squareness order; Y gets COY, Z gets AOZ BOZ.
    assert!(steps.contains(&s.r(["-", "-", "COY"])));
    assert!(steps.contains(&s.r(["AOZ", "BOZ", "-"])));
}

#[test]
fn chains_use_the_whole_catalogue_and_drop_identities() {
    // seed-3axis excludes XOW YOW ZOW from its model; the chain still carries them (the steps
    // describe the topology; a model picks its errors out of it).
    let m = builtin("seed-3axis").unwrap().unwrap();
    let s = S(&m);
    let work = chain_steps(&m, Side::Work);
    assert_eq!(
        work,
        [
            Step::Offset([s.sym("Xwo"), s.sym("Ywo"), s.sym("Zwo")]),
            Step::Offset([s.sym("Xw"), s.sym("Yw"), s.sym("Zw")]),
            s.t(["XOW", "YOW", "ZOW"]),
        ]
    );
    for m in model_spec::all_builtin() {
        for side in [Side::Work, Side::Tool] {
            let steps = chain_steps(&m, side);
            assert!(steps.iter().all(|st| !st.is_identity()));
            // Every catalogue error appears in exactly one step of one chain.
            let mut seen = vec![0; m.catalogue.len()];
            for side in [Side::Work, Side::Tool] {
                for st in chain_steps(&m, side) {
                    match st {
                        Step::ErrorTranslation(e) | Step::ErrorRotation(e) => {
                            e.iter().flatten().for_each(|&i| seen[i] += 1)
                        }
                        Step::Motion {
                            positioning_error: Some(i),
                            ..
                        } => seen[i] += 1,
                        _ => {}
                    }
                }
            }
            assert!(seen.iter().all(|&c| c == 1), "{}: {seen:?}", m.name);
        }
    }
}
