//! The emitted code: unknown models are typed errors.

use codegen::emit::{GenerateError, generate_machine};
use model_spec::builtin;

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
