//! What a verb hands back: its text for people, its outputs (not yet written) and, for a
//! verb that records, the check it records once they are written. [`Done::finish`] writes the
//! outputs (all or none), commits the check, and returns what to print where.

use crate::error::VerbResult;
use crate::verbs::record::{Recorder, history_error};
use crate::verbs::{write_error, wrote};
use history::Check;
use output::Outputs;

/// The result of a verb, before anything is written or printed.
pub struct Done {
    /// Notes for people that never go to standard output (printed first, on standard error).
    pub notes: String,
    /// The text for people, printed before the list of files written.
    pub text: String,
    /// The outputs, written all or none by [`Done::finish`].
    pub outputs: Outputs,
    /// Whether a `Wrote FILE` line is printed per file written (the demo lists its own).
    pub list_written: bool,
    /// The check recorded in the history once every output is written (`--record`).
    pub record: Option<(Recorder, Check)>,
    /// Whether the check is staged only after the outputs are written, for a history that
    /// lives in a directory the outputs make (the demo's); else it is staged first, so that a
    /// check the database refuses writes nothing.
    pub record_last: bool,
    /// Text printed after the list of files written.
    pub epilogue: String,
    /// Whether an output goes to standard output (`-o -`): the text then goes to standard
    /// error, so that the two never mix.
    pub stdout_taken: bool,
}

/// What to print once a verb is done: on standard error (first), then on standard output.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Shown {
    /// Text for standard error.
    pub stderr: String,
    /// Text for standard output.
    pub stdout: String,
}

impl Done {
    /// A verb that writes no file: `text` on standard output.
    pub fn text(text: impl Into<String>) -> Done {
        Done::new(text, Outputs::new(), false)
    }

    /// A verb that writes `outputs` and prints `text` (on standard error when `stdout_taken`:
    /// an output goes to standard output).
    pub fn new(text: impl Into<String>, outputs: Outputs, stdout_taken: bool) -> Done {
        Done {
            notes: String::new(),
            text: text.into(),
            outputs,
            list_written: true,
            record: None,
            record_last: false,
            epilogue: String::new(),
            stdout_taken,
        }
    }

    /// With `check` recorded by `recorder` once the outputs are written.
    pub fn recording(mut self, recorder: Recorder, check: Check) -> Done {
        self.record = Some((recorder, check));
        self
    }

    /// With `check` recorded by `recorder` after the outputs are written: for a history in a
    /// directory that the outputs make.
    pub fn recording_last(mut self, recorder: Recorder, check: Check) -> Done {
        self.record = Some((recorder, check));
        self.record_last = true;
        self
    }

    /// With `text` printed after the list of files written.
    pub fn then(mut self, text: impl Into<String>) -> Done {
        self.epilogue = text.into();
        self
    }

    /// With `notes` on standard error.
    pub fn noting(mut self, notes: impl Into<String>) -> Done {
        self.notes = notes.into();
        self
    }

    /// Without the `Wrote FILE` lines (the text lists the files itself).
    pub fn unlisted(mut self) -> Done {
        self.list_written = false;
        self
    }

    /// Writes the outputs (all or none) and then commits the check (staged before writing: a
    /// check is recorded only when every output was written, and a check the database refuses
    /// writes nothing; staged after writing with [`Done::recording_last`]); returns what to
    /// print.
    ///
    /// # Errors
    /// A bad input: an output that cannot be written, a history that cannot record the check.
    pub fn finish(self) -> VerbResult<Shown> {
        let (written, recorded) = match self.record {
            Some((mut recorder, check)) if self.record_last => {
                let written = self.outputs.write_all().map_err(write_error)?;
                let id = recorder
                    .stage(&check)?
                    .commit()
                    .map_err(|e| history_error("--db", e))?;
                (written, recorder.recorded(id))
            }
            Some((mut recorder, check)) => {
                let staged = recorder.stage(&check)?;
                let written = self.outputs.write_all().map_err(write_error)?;
                let id = staged.commit().map_err(|e| history_error("--db", e))?;
                (written, recorder.recorded(id))
            }
            None => (
                self.outputs.write_all().map_err(write_error)?,
                String::new(),
            ),
        };
        let mut text = self.text;
        if self.list_written {
            text.push_str(&wrote(&written));
        }
        text.push_str(&recorded);
        text.push_str(&self.epilogue);
        Ok(if self.stdout_taken {
            Shown {
                stderr: self.notes + &text,
                stdout: String::new(),
            }
        } else {
            Shown {
                stderr: self.notes,
                stdout: text,
            }
        })
    }
}
