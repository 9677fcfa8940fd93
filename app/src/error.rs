//! The error of a verb: one line for people and the class that decides the exit code.

use std::fmt;

/// What went wrong, as the exit code tells it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Class {
    /// A bad input: a file that cannot be read, is malformed, implausible, or does not belong
    /// to the machine; an output that cannot be written. Exit code 1.
    Input,
    /// A usage error: the command line itself is wrong. Exit code 2 (clap's own errors too).
    Usage,
    /// A computation that failed: a refinement that does not converge, a non-finite or
    /// implausible result. No result file is written. Exit code 3.
    Computation,
}

impl Class {
    /// The process exit code of this class: 1, 2 or 3.
    pub fn exit_code(self) -> u8 {
        match self {
            Class::Input => EXIT_INPUT,
            Class::Usage => EXIT_USAGE,
            Class::Computation => EXIT_COMPUTATION,
        }
    }
}

/// Exit code of a bad input ([`Class::Input`]).
pub const EXIT_INPUT: u8 = 1;
/// Exit code of a usage error ([`Class::Usage`]).
pub const EXIT_USAGE: u8 = 2;
/// Exit code of a failed computation ([`Class::Computation`]).
pub const EXIT_COMPUTATION: u8 = 3;

/// The exit-code rule, shown after every verb's help.
pub const EXIT_CODES: &str = "\
Exit codes: 0 success; 1 bad input (a machine, truth, measurement CSV or JSON file that cannot \
be read, is malformed, holds implausible readings, poses or values, or belongs to another \
machine; an output that cannot be written); 2 the command line is wrong (missing or unknown flag; unknown \
machine, model, path, truth, axis, symbol, error or term name; a malformed or out-of-range \
value; an output that names an input); 3 a computation failed (a refinement that does not \
converge, a non-finite result, identified values beyond the plausibility bounds). Errors are \
one line on stderr naming the flag at fault (a malformed file is named with its line and \
column). Outputs are all written or none; on exit code 3 none is written.";

/// A failure of a verb: a one-line message and its class.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Error {
    /// Bad input, usage or failed computation.
    pub class: Class,
    /// One line, naming the flag and the offending item.
    pub message: String,
}

impl Error {
    /// A usage error (exit code 2).
    pub fn usage(message: impl Into<String>) -> Error {
        Error {
            class: Class::Usage,
            message: message.into(),
        }
    }

    /// A bad input (exit code 1).
    pub fn input(message: impl Into<String>) -> Error {
        Error {
            class: Class::Input,
            message: message.into(),
        }
    }

    /// A failed computation (exit code 3).
    pub fn computation(message: impl Into<String>) -> Error {
        Error {
            class: Class::Computation,
            message: message.into(),
        }
    }

    /// The process exit code: 1, 2 or 3.
    pub fn exit_code(&self) -> u8 {
        self.class.exit_code()
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for Error {}

/// The result of a verb.
pub type VerbResult<T = ()> = Result<T, Error>;
