//! SHA-256 of the input files of a check: [`model_spec::sha256`], where every reader of rtest
//! finds it, re-exported for the history's users.

pub use model_spec::sha256::{Digest, HashingReader, Sha256, sha256_hex};
