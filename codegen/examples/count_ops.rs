//! Prints the instruction-list size and operation counts of every model of every built-in machine.
fn main() {
    for m in model_spec::all_builtin() {
        for name in m.model_names() {
            let g = codegen::GainModel::derive(&m, m.model_errors(name).unwrap());
            let p = codegen::compile(&m, &g);
            let q = codegen::compile_position(&m, &g);
            println!(
                "{} {name}: {} instructions, {} outputs, {}; position: {} instructions, {}",
                m.name,
                p.ops.len(),
                p.outputs.len(),
                p.op_counts(),
                q.ops.len(),
                q.op_counts()
            );
        }
    }
}
