//! Runs the code generator over every built-in machine description
//! (`model-spec/machines/*.toml`) into `OUT_DIR`, through the same build-script API a user's
//! crate uses (`codegen::build`): one file per machine, and `machines.rs`, which declares a
//! module per machine and a lookup table of every compiled model. Generation is a pure
//! function (`codegen::emit::generate_machine`); this script only lists the descriptions and
//! writes the index.

use codegen::build::{Machine, write_to_out_dir};
use std::fmt::Write as _;
use std::path::PathBuf;

fn main() {
    if let Err(message) = run() {
        // One line naming the file (and for a bad description its line, column and field).
        println!("cargo::error={message}");
    }
}

fn run() -> Result<(), String> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../model-spec/machines");
    // The directory too, so that a description added or removed runs this script again.
    println!("cargo::rerun-if-changed={}", dir.display());
    let mut paths: Vec<PathBuf> = std::fs::read_dir(&dir)
        .map_err(|e| format!("cannot read `{}`: {e}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    paths.sort();
    let mut index = String::new();
    let mut table = String::new();
    for path in &paths {
        // Every model; `generate` prints the description's `cargo::rerun-if-changed`.
        let generated = Machine::from_file(path)
            .generate()
            .map_err(|e| e.to_string())?;
        let machine = &generated.machine;
        let module = machine.name.replace('-', "_");
        let file = format!("{module}.rs");
        generated
            .write_to_out_dir(&file)
            .map_err(|e| e.to_string())?;
        let _ = writeln!(
            index,
            "/// Machine `{}`: {}\npub mod {module} {{\n    include!(concat!(env!(\"OUT_DIR\"), \"/{file}\"));\n}}",
            machine.name, machine.description
        );
        for model in &generated.models {
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
    write_to_out_dir("machines.rs", &index).map_err(|e| e.to_string())?;
    Ok(())
}
