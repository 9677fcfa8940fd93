//! The emitted code reads like the gain table: inputs keep their names, the header is short,
//! unknown models are typed errors, and colliding symbol names still give code that compiles and
//! computes what the evaluator computes, bit for bit.

use codegen::emit::{GenerateError, generate_machine, generate_machine_with, names::snake_case};
use codegen::{GainModel, compile, compile_position};
use model_spec::{Machine, all_builtin, builtin, parse_machine};

use crate::support;

/// `(local, argument, field)` of every input load `let local = pose.field;` in `code`.
fn loads(code: &str) -> Vec<(String, String, String)> {
    code.lines()
        .filter_map(|l| {
            let rest = l.trim().strip_prefix("let ")?.strip_suffix(';')?;
            let (local, rhs) = rest.split_once(" = ")?;
            let (arg, field) = rhs.split_once('.')?;
            matches!(arg, "pose" | "params").then(|| (local.into(), arg.into(), field.into()))
        })
        .collect()
}

/// `true` for an old-style generated name such as `v4`.
fn is_v_name(s: &str) -> bool {
    s.strip_prefix('v')
        .is_some_and(|d| !d.is_empty() && d.bytes().all(|b| b.is_ascii_digit()))
}

#[test]
fn seed_ac_reduced_inputs_keep_their_names() {
    let m = builtin("seed-ac").unwrap().unwrap();
    let code = generate_machine(&m, &["reduced"]).unwrap();
    for line in [
        "let sin_a = pose.sin_a;",
        "let cos_c = pose.cos_c;",
        "let zc = params.Zc;",
        "let xw = params.Xw;",
        "let t0 = cos_a * sin_c;",
    ] {
        assert!(code.contains(line), "`{line}` in\n{code}");
    }
    let loads = loads(&code);
    assert!(loads.len() >= 16, "two functions load eight inputs each");
    for (local, _, field) in &loads {
        assert_eq!(*local, snake_case(field), "the local of `{field}`");
        assert!(!is_v_name(local), "generated name `{local}` for an input");
    }
    assert!(
        !code
            .split(|c: char| !c.is_ascii_alphanumeric() && c != '_')
            .any(is_v_name),
        "no `v` names left"
    );
}

#[test]
fn header_lines_are_short() {
    for m in all_builtin() {
        for code in [
            generate_machine(&m, &[]).unwrap(),
            generate_machine_with(&m, &[], 20).unwrap(),
        ] {
            let header: Vec<&str> = code.lines().take_while(|l| l.starts_with("//")).collect();
            assert!(header.len() >= 4, "{}: {header:?}", m.name);
            assert!(header[0].contains(&format!("machine `{}`", m.name)));
            for line in header {
                assert!(line.chars().count() <= 100, "{}: {line}", m.name);
            }
        }
    }
}

#[test]
fn an_unknown_model_is_a_typed_error() {
    let m = builtin("seed-ac").unwrap().unwrap();
    let e = generate_machine(&m, &["reduced", "nope"]).unwrap_err();
    assert_eq!(
        e,
        GenerateError::UnknownModel {
            machine: "seed-ac".into(),
            model: "nope".into(),
            models: m.model_names().iter().map(|s| s.to_string()).collect(),
        }
    );
    assert!(e.to_string().contains("no model `nope`"), "{e}");
}

/// An A-C table under an X-Y-Z tool chain whose symbols collide once snake-cased: with each other
/// (`Zc`, `ZC`), with pose inputs (`X`, `Sin_c`), with keywords (`In`), with the arguments
/// (`Out`, `Pose`) and with intermediates (`T0`).
const COLLIDING: &str = r#"
name = "colliding-names"
description = "A-C table under an X-Y-Z tool chain whose symbol names collide once snake-cased."

[symbols]
Zc = 10.0
ZC = 20.0
In = 5.0
T0 = 1.5
Out = -2.0
X = 3.0
Sin_c = 0.5
Pose = 70.0

[[work]]
axis = "A"
type = "rotary"
direction = "+x"

[[work]]
axis = "C"
type = "rotary"
direction = "+z"
offset = ["X", "T0", "Zc"]

[[work]]
end = "ball"
offset = ["In", "Out", "ZC"]

[[tool]]
axis = "Y"
type = "linear"
direction = "+y"
stroke = [-300.0, 300.0]

[[tool]]
axis = "X"
type = "linear"
direction = "+x"
stroke = [-300.0, 300.0]

[[tool]]
axis = "Z"
type = "linear"
direction = "+z"
stroke = [-300.0, 300.0]

[[tool]]
end = "tool"
offset = ["Sin_c", 0, "Pose"]
"#;

/// `count` pseudo-random `(commands, params)` of `m`, with the tool on the ball.
fn poses(m: &Machine, count: usize) -> Vec<(Vec<f64>, Vec<f64>)> {
    let mut rng = 0x9e37_79b9_7f4a_7c15u64;
    let mut uniform = move || {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        (rng >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..count)
        .map(|_| {
            let commands: Vec<f64> = (0..m.axes.len()).map(|_| 6.0 * uniform() - 3.0).collect();
            let params = m
                .symbols
                .iter()
                .map(|s| s.default + 40.0 * (uniform() - 0.5))
                .collect();
            (commands, params)
        })
        .collect()
}

/// Builds `main` (a whole program) with rustc and runs it; returns its standard output.
fn run_program(dir: &std::path::Path, main: &str) -> String {
    let file = dir.join("main.rs");
    std::fs::write(&file, main).unwrap();
    let exe = dir.join("main");
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
    support::compile(
        &rustc,
        &file,
        &["--crate-type", "bin", "-A", "dead_code"],
        &exe,
    );
    let o = std::process::Command::new(&exe)
        .output()
        .expect("the program runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8(o.stdout).unwrap()
}

#[test]
fn colliding_symbol_names_compile_and_equal_the_evaluator() {
    let m = parse_machine("colliding-names.toml", COLLIDING).unwrap();
    let code = generate_machine(&m, &[]).unwrap();
    let loads = loads(&code);
    for (local, field) in [
        ("zc", "Zc"),
        ("zc_2", "ZC"),
        ("in_", "In"),
        ("t0_", "T0"),
        ("out_", "Out"),
        ("x_2", "X"),
        ("sin_c_2", "Sin_c"),
        ("pose_", "Pose"),
        ("sin_c", "sin_c"),
        ("x", "x"),
    ] {
        assert!(
            loads.iter().any(|(l, _, f)| l == local && f == field),
            "`let {local} = ….{field};` in\n{code}"
        );
    }
    assert_eq!(support::allowed_lints(&code), codegen::emit::ALLOWED_LINTS);
    let dir = support::scratch("colliding");
    support::check_no_std_lib(&dir, &code);

    // Run the compiled code and compare with the evaluator, bit for bit.
    let model = GainModel::derive(&m, m.model_errors("full").unwrap());
    let (gains, position) = (compile(&m, &model), compile_position(&m, &model));
    let n = model.errors.len();
    let n_params = m.symbols.len();
    let inputs: Vec<Vec<f64>> = poses(&m, 8)
        .iter()
        .map(|(c, p)| model.atoms.values(c, p))
        .collect();
    let n_pose = inputs[0].len() - n_params;
    let literal = |v: &[f64]| {
        let bits: Vec<String> = v
            .iter()
            .map(|x| format!("f64::from_bits({:#x})", x.to_bits()))
            .collect();
        format!("[{}]", bits.join(", "))
    };
    let rows: Vec<String> = inputs.iter().map(|i| literal(i)).collect();
    let main = format!(
        "mod machine {{\n{code}\n}}\n\
         fn main() {{\n\
             let inputs: [[f64; {}]; {}] = [{}];\n\
             for i in &inputs {{\n\
                 let (pose, params) = i.split_at({n_pose});\n\
                 let mut g = [0.0; {}];\n\
                 machine::full::gains_slice(pose, params, &mut g);\n\
                 let mut q = [0.0; {}];\n\
                 machine::full::position_gains_slice(pose, params, &mut q);\n\
                 for x in g.iter().chain(&q) {{ println!(\"{{}}\", x.to_bits()); }}\n\
             }}\n\
         }}\n",
        n_pose + n_params,
        inputs.len(),
        rows.join(",\n"),
        6 * n,
        3 * n,
    );
    let printed = run_program(&dir, &main);
    let mut compiled = printed.lines().map(|l| f64::from_bits(l.parse().unwrap()));
    for i in &inputs {
        let mut expected = vec![0.0; 6 * n];
        gains.eval(i, &mut Vec::new(), &mut expected);
        let mut pos = vec![0.0; 3 * n];
        position.eval(i, &mut Vec::new(), &mut pos);
        expected.extend(pos);
        for (k, e) in expected.iter().enumerate() {
            let c = compiled.next().expect("one line per output");
            assert_eq!(
                c.to_bits(),
                e.to_bits(),
                "output {k}: compiled {c} vs evaluator {e}"
            );
        }
    }
    assert!(compiled.next().is_none());
    let _ = std::fs::remove_dir_all(&dir);
}

use crate::support::chains;

/// The generated text is what `prettyplease` prints for it: the runs of `let` statements the
/// emitter writes as text (`codegen/src/emit/lets.rs`) are written exactly as `prettyplease`
/// writes them. Parsing the file (after its `//` header) and printing it again gives the same
/// text, for every built-in machine, split models, colliding names, a kinematic parameter
/// whose load is too long to be carried as text, and long synthetic chains.
#[test]
fn emitted_files_are_a_fixed_point_of_syn_and_prettyplease() {
    let long_name = "Xw".to_string() + &"x".repeat(60);
    let (_, seed_ac) = model_spec::builtin::BUILTIN[0];
    let long = seed_ac.replace("Xw", &long_name);
    let mut machines: Vec<Machine> = all_builtin();
    machines.push(parse_machine("colliding-names.toml", COLLIDING).unwrap());
    machines.push(parse_machine("long.toml", &long).unwrap());
    machines.extend([chains::synthetic(2, true), chains::synthetic(12, false)]);
    let mut files = Vec::new();
    for m in &machines {
        files.push((m.name.clone(), generate_machine(m, &[]).unwrap()));
        files.push((
            format!("{} split", m.name),
            generate_machine_with(m, &[], 40).unwrap(),
        ));
    }
    assert!(
        files
            .iter()
            .any(|(_, code)| code.contains(&format!("= params\n            .{long_name};"))),
        "a load too long for a run goes through syn, which wraps it"
    );
    for (name, code) in files {
        let body: String = code
            .lines()
            .skip_while(|l| l.starts_with("//") || l.is_empty())
            .map(|l| format!("{l}\n"))
            .collect();
        let again = prettyplease::unparse(&syn::parse_file(&body).unwrap());
        assert!(!body.contains("__rtest_lets"), "{name}: a marker is left");
        if again != body {
            let (a, b) = (again.lines(), body.lines());
            let (i, (x, y)) = a
                .zip(b)
                .enumerate()
                .find(|(_, (x, y))| x != y)
                .expect("texts of different lengths");
            panic!("{name}, line {i}: prettyplease prints\n{x}\nwhere the emitter wrote\n{y}");
        }
    }
}
