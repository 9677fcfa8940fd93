//! Compiles this crate's machine description, `machine.toml`, into `OUT_DIR/trunnion_bc.rs`
//! (every model: `full` and `location`), through `codegen::build`. A bad description fails the
//! build with one line naming the file, line, column and field.

fn main() {
    let generated = codegen::build::Machine::from_file("machine.toml")
        .models(&["full", "location"])
        .write_to_out_dir("trunnion_bc.rs");
    if let Err(e) = generated {
        println!("cargo::error={e}");
    }
}
