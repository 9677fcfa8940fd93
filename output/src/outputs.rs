//! The outputs of one command, collected and then written all together.

use std::fmt;
use std::path::{Path, PathBuf};

use crate::check::{Planned, check_distinct, plan_in_dir, plan_target, refuse_overwriting_inputs};
use crate::commit;
use crate::error::{Shown, WriteError};
use crate::target::Target;

/// The outputs of one command: collected with [`add`](Outputs::add) and
/// [`add_in_dir`](Outputs::add_in_dir), then written all together (or none) by
/// [`write_all`](Outputs::write_all).
#[derive(Debug, Default)]
pub struct Outputs {
    items: Vec<Item>,
    /// The command's inputs, which no output may overwrite ([`Outputs::protect`]).
    inputs: Vec<(String, PathBuf)>,
}

#[derive(Debug)]
struct Item {
    label: String,
    place: Place,
    contents: Vec<u8>,
}

#[derive(Debug)]
enum Place {
    Target(Target),
    InDir { dir: PathBuf, name: String },
}

/// One output that was written, for a "Wrote …" message.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Written {
    /// The flag that named the output.
    pub label: String,
    /// Where it went, as the user named it (for [`Outputs::add_in_dir`], the directory joined
    /// with the file name).
    pub target: Target,
    /// How many bytes were written.
    pub bytes: usize,
}

/// `` `path` `` or `standard output`.
impl fmt::Display for Written {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", Shown(&self.target))
    }
}

impl Outputs {
    /// No outputs yet.
    pub fn new() -> Outputs {
        Outputs::default()
    }

    /// One output: `contents` to `target`; `label` names the flag in messages (`--json`, `-o`,
    /// `--plot`).
    pub fn add(&mut self, label: impl Into<String>, target: Target, contents: impl Into<Vec<u8>>) {
        self.items.push(Item {
            label: label.into(),
            place: Place::Target(target),
            contents: contents.into(),
        });
    }

    /// A file `name` inside directory `dir` (e.g. the plots of `--plot dir`): `dir` (and any
    /// missing parent of it) is created if missing, and removed again if writing then fails.
    /// `name` must be a plain file name (no `/`, not `.` or `..`).
    pub fn add_in_dir(
        &mut self,
        label: impl Into<String>,
        dir: impl AsRef<Path>,
        name: &str,
        contents: impl Into<Vec<u8>>,
    ) {
        self.items.push(Item {
            label: label.into(),
            place: Place::InDir {
                dir: dir.as_ref().to_path_buf(),
                name: name.to_string(),
            },
            contents: contents.into(),
        });
    }

    /// The command's inputs (`label` the flag, `path` as given): [`write_all`](Outputs::write_all)
    /// refuses an output that is one of them as [`refuse_overwriting_inputs`] does, for the
    /// files of an output directory too, whose names were not known before the work.
    pub fn protect(&mut self, inputs: &[(&str, &Path)]) {
        self.inputs
            .extend(inputs.iter().map(|(l, p)| (l.to_string(), p.to_path_buf())));
    }

    /// How many outputs were added.
    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// Whether no output was added.
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// Checks the outputs added so far without writing anything (the checks `write_all` starts
    /// with); see [`check_targets`](crate::check_targets) for checking before the contents
    /// exist.
    pub fn check(&self) -> Result<(), WriteError> {
        self.plan().map(|_| ())
    }

    /// Writes every output, or none: see the [crate documentation](crate) for what happens to
    /// each kind of target, in which order, and the limits of "none".
    ///
    /// Returns what was written, in the order the outputs were added.
    pub fn write_all(self) -> Result<Vec<Written>, WriteError> {
        let planned = self.plan()?;
        let contents: Vec<&[u8]> = self.items.iter().map(|i| i.contents.as_slice()).collect();
        commit::write(&planned, &contents)?;
        Ok(planned
            .into_iter()
            .zip(&contents)
            .map(|(p, c)| Written {
                label: p.label,
                target: p.target,
                bytes: c.len(),
            })
            .collect())
    }

    /// Every output checked, and no two naming one file.
    fn plan(&self) -> Result<Vec<Planned>, WriteError> {
        let planned = self
            .items
            .iter()
            .map(|item| match &item.place {
                Place::Target(target) => plan_target(&item.label, target),
                Place::InDir { dir, name } => plan_in_dir(&item.label, dir, name),
            })
            .collect::<Result<Vec<_>, _>>()?;
        check_distinct(&planned)?;
        let inputs: Vec<(&str, &Path)> = self
            .inputs
            .iter()
            .map(|(l, p)| (l.as_str(), p.as_path()))
            .collect();
        let targets: Vec<(&str, &Target)> = planned
            .iter()
            .map(|p| (p.label.as_str(), &p.target))
            .collect();
        refuse_overwriting_inputs(&inputs, &targets)?;
        Ok(planned)
    }
}
