//! Golden files: the gain tables people read (the seed's Tables 1 and 2, the three-axis machine,
//! the head-table machine) and the emitted code of `seed-ac reduced`. Operation counts are part
//! of every snapshot, so a regression of the common-subexpression elimination shows as a diff.

use codegen::table::{Format, render};
use codegen::{GainModel, compile};
use model_spec::builtin;

fn table(machine: &str, model: &str) -> String {
    let m = builtin(machine).unwrap().unwrap();
    let g = GainModel::derive(&m, m.model_errors(model).unwrap());
    let p = compile(&m, &g);
    format!(
        "{}\ncompiled: {} errors, {}\n",
        render(&m, &g, &format!("{machine}, model {model}"), Format::Text),
        g.errors.len(),
        p.op_counts()
    )
}

#[test]
fn seed_ac_full_table_1() {
    insta::assert_snapshot!(table("seed-ac", "full"));
}

#[test]
fn seed_ac_reduced_table_2() {
    insta::assert_snapshot!(table("seed-ac", "reduced"));
}

#[test]
fn seed_3axis_full() {
    insta::assert_snapshot!(table("seed-3axis", "full"));
}

#[test]
fn head_table_bc_full() {
    insta::assert_snapshot!(table("head-table-bc", "full"));
}

#[test]
fn seed_ac_reduced_markdown_and_latex() {
    let m = builtin("seed-ac").unwrap().unwrap();
    let g = GainModel::derive(&m, m.model_errors("reduced").unwrap());
    insta::assert_snapshot!(
        "seed_ac_reduced_markdown",
        render(&m, &g, "seed-ac reduced", Format::Markdown)
    );
    insta::assert_snapshot!(
        "seed_ac_reduced_latex",
        render(&m, &g, "seed-ac reduced", Format::Latex)
    );
}

#[test]
fn seed_ac_reduced_emitted_code() {
    let m = builtin("seed-ac").unwrap().unwrap();
    insta::assert_snapshot!(codegen::emit::generate_machine(&m, &["reduced"]).unwrap());
}
