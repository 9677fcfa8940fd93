//! LinuxCNC's table-table kinematics modules (`compensation::controllers::linuxcnc`): which
//! descriptions they cover, the joint map read off the description, and pins that put the tool
//! on the workpiece point of the machine with its location translations, checked here against
//! the modules' documented inverse kinematics (the real LinuxCNC runs the same check in the
//! root package's `linuxcnc` tests).

use crate::common::{Rng, builtin, random_rotary};
use crate::identified::errors_of;
use compensation::controllers::linuxcnc::{TrtModule, module_joints, trt_kinematics};
use compensation::kinematics::corrected_description;
use model_spec::{Machine, Side, parse_machine};
use nalgebra::Vector3;
use simulation::exact::VirtualMachine;

#[test]
fn seed_ac_maps_onto_xyzac_with_its_table_side_x_negated() {
    let m = builtin("seed-ac");
    let k = trt_kinematics(&m, &m.default_parameters()).unwrap();
    assert_eq!(k.module, TrtModule::Xyzac);
    let map: Vec<(char, &str, f64)> = k
        .joints
        .iter()
        .map(|j| (j.letter, j.axis_name.as_str(), j.sign))
        .collect();
    // X moves the table: the tool moves the other way relative to it.
    assert_eq!(map[0], ('X', "X", -1.0));
    assert_eq!(map[1], ('Y', "Y", 1.0));
    assert_eq!(map[2], ('Z', "Z", 1.0));
    assert_eq!((map[3].0, map[3].1), ('A', "A"));
    assert_eq!((map[4].0, map[4].1), ('C', "C"));
    assert!(k.check_mm < 1e-9, "{}", k.check_mm);
}

#[test]
fn table_table_bc_maps_onto_xyzbc() {
    let m = builtin("table-table-bc");
    let k = trt_kinematics(&m, &m.default_parameters()).unwrap();
    assert_eq!(k.module, TrtModule::Xyzbc);
    let letters: String = k.joints.iter().map(|j| j.letter).collect();
    assert_eq!(letters, "XYZBC");
    assert_eq!(k.pins.y_offset, 0.0);
    assert!(k.check_mm < 1e-9, "{}", k.check_mm);
}

#[test]
fn other_topologies_are_not_covered_and_say_why() {
    for (name, why) in [
        ("head-table-bc", "is on the tool side"),
        ("nutating-table-bc", "is inclined"),
        ("head-head-ca", "is on the tool side"),
        ("seed-3axis", "three linear and two rotary"),
        ("horizontal-4axis-b", "three linear and two rotary"),
    ] {
        let m = builtin(name);
        let e = trt_kinematics(&m, &m.default_parameters()).unwrap_err();
        let text = e.to_string();
        assert!(
            text.contains(&format!("machine `{name}` is not covered")) && text.contains(why),
            "{name}: {text}"
        );
    }
}

/// The largest miss (mm) of the module, with the pins of the corrected description, against
/// the original machine with `truth` (catalogue values by name) at random poses: the joints the
/// module computes for the tool point's world position must be the machine's own commands.
fn largest_miss(m: &Machine, truth: &[(&str, f64)]) -> f64 {
    let errors = errors_of(m, truth);
    let source = model_spec::write::source_text(&m.name).unwrap();
    let corrected = corrected_description(m, &source, &errors).unwrap();
    let folded = parse_machine("corrected.toml", &corrected.toml).unwrap();
    assert!(
        corrected.not_folded.is_empty(),
        "{:?}",
        corrected.not_folded
    );
    let k = trt_kinematics(&folded, &folded.default_parameters()).unwrap();

    let mut values = vec![0.0; m.catalogue.len()];
    for (n, v) in truth {
        values[m.error_by_name(n).unwrap()] = *v;
    }
    let vm = VirtualMachine::new(m);
    let params = m.default_parameters();
    let origin = Vector3::from(k.world_origin);
    let mut rng = Rng::new(5);
    let mut largest = 0.0f64;
    for _ in 0..50 {
        let mut q = random_rotary(m, &mut rng);
        for i in m.linear_axes() {
            q[i] = rng.range(-200.0, 200.0);
        }
        let tool = vm.chain_transform(Side::Tool, &q, &params, &values);
        let work = vm.chain_transform(Side::Work, &q, &params, &values);
        let p = work
            .inverse_transform_point(&tool.translation.vector.into())
            .coords
            - origin;
        let angle = |j: usize| k.joints[j].sign * q[k.joints[j].axis];
        let got = module_joints(k.module, &k.pins, &p, angle(3), angle(4));
        for j in 0..3 {
            let want = k.joints[j].sign * q[k.joints[j].axis];
            largest = largest.max((got[j] - want).abs());
        }
    }
    largest
}

#[test]
fn the_pins_of_the_corrected_seed_ac_put_the_tool_where_the_machine_with_its_location_translations_does()
 {
    let m = builtin("seed-ac");
    let truth = [
        ("XOC", 0.021),
        ("YOC", -0.014),
        ("YOA", 0.035),
        ("ZOA", -0.027),
    ];
    let miss = largest_miss(&m, &truth);
    assert!(miss < 1e-9, "{miss}");
    // Without the errors folded, the same poses miss by the errors' size: the check can fail.
    let nominal = trt_kinematics(&m, &m.default_parameters()).unwrap();
    assert_ne!(nominal.pins, {
        let errors = errors_of(&m, &truth);
        let source = model_spec::write::source_text(&m.name).unwrap();
        let c = corrected_description(&m, &source, &errors).unwrap();
        let f = parse_machine("c.toml", &c.toml).unwrap();
        trt_kinematics(&f, &f.default_parameters()).unwrap().pins
    });
}

#[test]
fn the_pins_of_the_corrected_table_table_bc_put_the_tool_where_the_machine_does() {
    let m = builtin("table-table-bc");
    let truth = [
        ("XOC", -0.018),
        ("YOC", 0.025),
        ("XOB", 0.031),
        ("ZOB", -0.022),
    ];
    let miss = largest_miss(&m, &truth);
    assert!(miss < 1e-9, "{miss}");
}

#[test]
fn an_unfolded_translation_misses_by_its_size() {
    // The check of `largest_miss` against the nominal pins: YOC of 25 µm (it moves the C line
    // and the table it carries) is missed by 25 µm, so a wrong pin formula would not pass the
    // tests above.
    let m = builtin("seed-ac");
    let k = trt_kinematics(&m, &m.default_parameters()).unwrap();
    let mut values = vec![0.0; m.catalogue.len()];
    values[m.error_by_name("YOC").unwrap()] = 0.025;
    let vm = VirtualMachine::new(&m);
    let params = m.default_parameters();
    let mut q = vec![0.0; m.axes.len()];
    q[m.axis_by_name("C").unwrap()] = 90f64.to_radians();
    let tool = vm.chain_transform(Side::Tool, &q, &params, &values);
    let work = vm.chain_transform(Side::Work, &q, &params, &values);
    let p = work
        .inverse_transform_point(&tool.translation.vector.into())
        .coords
        - Vector3::from(k.world_origin);
    let got = module_joints(
        k.module,
        &k.pins,
        &p,
        0.0,
        k.joints[4].sign * q[k.joints[4].axis],
    );
    let miss = got.norm();
    assert!((miss - 0.025).abs() < 1e-9, "{miss}");
}

#[test]
fn a_table_side_x_described_along_minus_x_is_its_joint_as_written() {
    // The docs' advice for LinuxCNC machines: describe the table-side X in its joint's
    // direction, and the joint map is the identity.
    let text = model_spec::write::source_text("seed-ac").unwrap();
    let at = text.find("direction = \"+x\"").unwrap();
    let flipped = format!("{}direction = \"-x\"{}", &text[..at], &text[at + 16..]);
    let m = parse_machine("seed-ac-joints.toml", &flipped).unwrap();
    assert_eq!(
        m.axes[m.axis_by_name("X").unwrap()].direction.own.sign(),
        -1.0
    );
    let k = trt_kinematics(&m, &m.default_parameters()).unwrap();
    assert!(k.joints.iter().all(|j| j.sign == 1.0), "{:?}", k.joints);
}
