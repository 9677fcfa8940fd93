//! Runs the code generator over every built-in machine description
//! (`model-spec/machines/*.toml`) into `OUT_DIR`: one file per machine, and `machines.rs`
//! that declares a module per machine and a lookup table of every compiled model.
//! Generation is a pure function (`codegen::emit::generate_machine`); this script only reads
//! and writes files.

use std::fmt::Write as _;
use std::path::PathBuf;

fn main() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../model-spec/machines");
    let out = PathBuf::from(std::env::var("OUT_DIR").expect("cargo sets OUT_DIR"));
    println!("cargo:rerun-if-changed={}", dir.display());
    let mut paths: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| fail(&format!("cannot read {}: {e}", dir.display())))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    paths.sort();
    let mut index = String::new();
    let mut table = String::new();
    for path in &paths {
        println!("cargo:rerun-if-changed={}", path.display());
        let text = std::fs::read_to_string(path)
            .unwrap_or_else(|e| fail(&format!("cannot read {}: {e}", path.display())));
        let machine = model_spec::parse_machine(&path.display().to_string(), &text)
            .unwrap_or_else(|e| fail(&e.to_string()));
        let code =
            codegen::emit::generate_machine(&machine, &[]).unwrap_or_else(|e| fail(&e.to_string()));
        let module = machine.name.replace('-', "_");
        let file = format!("{module}.rs");
        std::fs::write(out.join(&file), code)
            .unwrap_or_else(|e| fail(&format!("cannot write {file}: {e}")));
        let _ = writeln!(
            index,
            "/// Machine `{}`: {}\npub mod {module} {{\n    include!(concat!(env!(\"OUT_DIR\"), \"/{file}\"));\n}}",
            machine.name, machine.description
        );
        for model in machine.model_names() {
            let _ = writeln!(
                table,
                "    CompiledModel {{ machine: \"{}\", model: \"{model}\", errors: &{module}::{model}::ERRORS, pose_inputs: &{module}::POSE_INPUTS, parameters: &{module}::PARAMETERS, operations: {module}::{model}::OPERATIONS, gains: {module}::{model}::gains_slice, position_gains: {module}::{model}::position_gains_slice, position_operations: {module}::{model}::POSITION_OPERATIONS, compensate: {module}::{model}::compensation::compensate_slice, first_order_f32: {module}::{model}::compensation::first_order_f32_slice }},",
                machine.name
            );
        }
    }
    let _ = writeln!(
        index,
        "/// Every compiled model of every built-in machine.\npub const MODELS: &[CompiledModel] = &[\n{table}];"
    );
    std::fs::write(out.join("machines.rs"), index)
        .unwrap_or_else(|e| fail(&format!("cannot write machines.rs: {e}")));
}

fn fail(message: &str) -> ! {
    eprintln!("error: {message}");
    std::process::exit(1)
}
