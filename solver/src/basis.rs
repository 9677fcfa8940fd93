//! The basis vocabulary of position-dependent errors and other effects; defined with the
//! machine description in `model_spec::basis` and re-exported here.

pub use model_spec::basis::*;
