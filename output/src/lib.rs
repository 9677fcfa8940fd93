//! Writing the files rtest produces (skeleton; filled in next).
#![warn(missing_docs)]
