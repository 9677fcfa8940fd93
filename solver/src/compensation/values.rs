//! The machine's geometric errors as identified, ready to be put back onto the machine: every
//! compensated term with its value, the value of every error at any pose, and the terms that
//! compensation leaves out, with why.
//!
//! **What is compensated** is the machine's geometric errors: the component errors of the
//! axes, the location errors of the rotary axes and the squareness errors, each with the
//! bases that are functions of the pose: `const`, `poly:K`, `harmonic:K`, `period:P` and
//! `step:V`. They are evaluated with [`Basis::values`] at a [`BasisContext`] that holds the
//! commands only (every axis moving in its positive direction, time zero), exactly the columns
//! the H matrix of the fit had at the same commands.
//!
//! **Left out and listed** ([`LeftOut`], with the value): the workpiece set-up errors
//! `XOW YOW ZOW` (where the ball was placed), the R-test's zero offsets `dx0 dy0 dz0` and
//! instrument terms `SXX` … `SZY` (the instrument, not the machine), terms on time bases
//! (`time:K`, `exp:TAU`, `rate`, `warmup:TAU`: a drift is no function of the pose),
//! `velocity` terms (servo lag: the controller's feed-forward takes it) and `reversal` terms
//! (backlash: it depends on the direction of approach, and the controller's backlash
//! compensation takes it).
//!
//! **Undetermined values are refused.** A compensated term whose value the report has as
//! `null` (the data could not determine it: a rank-deficient fit) is an error naming the terms
//! and what to do. A constrained fit gives every parameter a value: `zero: NAME, …` fixes the
//! named parameters to 0 (`fixed: true`), `minimum-norm` gives the undetermined ones the
//! minimum-norm choice (`determined: false`). Those values are taken, and listed
//! ([`MachineErrors::set_by_constraint`]): they come from the constraint, not from the data.
//!
//! Units inside: mm and rad, as everywhere in the solver.

use crate::io::report::IdentifiedValues;
use crate::model::{Basis, BasisContext, Effect, Term};
use model_spec::{ErrorId, ErrorKind, Machine};

/// Why compensation cannot go on. Every message names the file of the identified values (or
/// the machine description) and the term or field at fault.
#[derive(Debug, thiserror::Error)]
pub enum CompensationError {
    /// The identified values belong to another machine description.
    #[error(
        "{file}: the values were identified on machine `{machine}` (fingerprint {fingerprint}), not on this description of `{expected}` (fingerprint {expected_fingerprint}): they do not apply to it"
    )]
    OtherMachine {
        /// The file of the values.
        file: String,
        /// The machine they were identified on.
        machine: String,
        /// Its fingerprint.
        fingerprint: String,
        /// The machine given.
        expected: String,
        /// Its fingerprint.
        expected_fingerprint: String,
    },
    /// Compensated terms without a value: the data did not determine them.
    #[error(
        "{file}: no value for {}: the data do not determine {} (the fit was rank-deficient), and compensation needs a value for every term it puts onto the machine; identify again with a constraint that fixes what you know (`--constraint zero:{}`), or with a record from another path that separates them, or leave them out of the model",
        terms.join(", "),
        if terms.len() == 1 { "it" } else { "them" },
        parameters.join(",")
    )]
    Undetermined {
        /// The file of the values.
        file: String,
        /// The terms (`XOC`, `ECC@harmonic:2`).
        terms: Vec<String>,
        /// Their parameter names, as `--constraint zero:` takes them (`XOC`,
        /// `ECC@harmonic:2:cos`).
        parameters: Vec<String>,
    },
    /// Identified values whose parts do not fit together (built by hand, not read).
    #[error("{file}: {why}")]
    Inconsistent {
        /// The file of the values.
        file: String,
        /// What does not fit.
        why: String,
    },
    /// The machine description's text cannot be corrected (see
    /// [`super::kinematics::corrected_description`]).
    #[error("{file}: {why}")]
    Description {
        /// The description (file or `<built-in NAME>`).
        file: String,
        /// What is wrong.
        why: String,
    },
    /// A compensation table cannot be made at this pitch (see [`super::tables::axis_tables`]).
    #[error("axis {axis}: {why}")]
    Pitch {
        /// The axis.
        axis: String,
        /// What is wrong with the pitch.
        why: String,
    },
    /// A computed value that is not finite: the computation failed.
    #[error("{file}: {what} is not finite ({value}): the computation failed")]
    NonFinite {
        /// The file of the values.
        file: String,
        /// Which value.
        what: String,
        /// The value.
        value: f64,
    },
}

/// Where the value of a compensated term comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ValueSource {
    /// Determined by the data.
    Measured,
    /// Fixed to 0 by the constraint `zero: NAME, …`.
    FixedToZero,
    /// Not determined by the data: the minimum-norm choice of the constraint `minimum-norm`.
    MinimumNorm,
}

/// A compensated term and its value.
#[derive(Clone, Debug, PartialEq)]
pub struct CompensatedTerm {
    /// The term (an error of the machine times a basis of the pose).
    pub term: Term,
    /// Its spelling (`XOC`, `ECC@harmonic:2`).
    pub spelling: String,
    /// Its coefficients: one, two for `harmonic:K` and `period:P` (cos, sin); mm or rad.
    pub coefficients: Vec<f64>,
    /// Where the value comes from.
    pub source: ValueSource,
}

/// An identified change of a kinematic symbol (a length of the description, mm): no error
/// compensation holds it, the corrected description does
/// ([`crate::compensation::kinematics::corrected_description`]).
#[derive(Clone, Debug, PartialEq)]
pub struct KinematicChange {
    /// The term (`Effect::KinematicOffset` on the constant basis).
    pub term: Term,
    /// The symbol.
    pub symbol: model_spec::SymbolId,
    /// Its spelling (the symbol's name, `Zt`).
    pub spelling: String,
    /// The change of the symbol, mm; `None` where the data did not determine it.
    pub change_mm: Option<f64>,
    /// Where the value comes from.
    pub source: ValueSource,
}

/// A term of the identification that compensation leaves out, and why.
#[derive(Clone, Debug, PartialEq)]
pub struct LeftOut {
    /// Its spelling (`ECC@reversal`, `dz0@time:1`, `XOW`).
    pub term: String,
    /// Why it is left out, and what takes it instead where something does.
    pub reason: String,
    /// Its values as identified, one per H-matrix column (two for `harmonic:K` and
    /// `period:P`), in the term's unit inside: mm or rad, ms for `velocity`, 1 for instrument
    /// terms; `None` where the data did not determine it.
    pub values: Vec<Option<f64>>,
}

/// The machine's geometric errors as identified: every compensated term with its value.
#[derive(Clone, Debug, PartialEq)]
pub struct MachineErrors {
    file: String,
    machine: String,
    fingerprint: String,
    errors: Vec<ErrorId>,
    terms: Vec<CompensatedTerm>,
    /// The identified changes of kinematic symbols (left out of compensation).
    kinematic: Vec<KinematicChange>,
    /// Per term: its error's index in `errors`.
    slots: Vec<usize>,
    /// +1 per axis: the direction of motion the bases see (no compensated basis reads it).
    motion: Vec<i8>,
}

/// Why a term is left out of compensation; `None` for a term that is compensated.
fn left_out_reason(m: &Machine, term: &Term) -> Option<String> {
    let reason = match (term.effect, term.basis) {
        (Effect::SensorOffset(_), _) => {
            "a zero offset of the R-test's reading, not an error of the machine"
        }
        (Effect::Instrument { .. }, _) => {
            "an instrument term of the R-test (a sensor's gain or cross-talk), not an error of the machine"
        }
        (Effect::KinematicOffset(_), _) => {
            "a kinematic offset of the description (a length, mm): its identified value belongs in the description's [symbols] (--kinematics-out folds it) and the controller's kinematic parameters, not in an error compensation"
        }
        (Effect::Error(e), _) if matches!(m.catalogue[e].kind, ErrorKind::Setup { .. }) => {
            "a set-up error of the workpiece (where the ball was placed), not an error of the machine"
        }
        (_, b) if b.of_time() => {
            "it changes with time over the record (a drift, a rate, a warm-up, a settling), not with the pose: no geometric compensation holds it"
        }
        (_, Basis::Velocity) => {
            "servo lag (the coefficient is the lag in ms): the controller's feed-forward takes it, not a geometric compensation"
        }
        (_, Basis::Reversal) => {
            "backlash: it depends on the direction of approach, so the controller's backlash (reversal) compensation takes it; the lost motion between the two directions is twice this value"
        }
        _ => return None,
    };
    Some(reason.to_string())
}

impl MachineErrors {
    /// Reads the machine errors of an identification; the left-out terms are listed.
    ///
    /// # Errors
    /// [`CompensationError::OtherMachine`] when `id` was identified on another machine
    /// description than `m`; [`CompensationError::Undetermined`] when a compensated term has
    /// no value (see the module documentation); [`CompensationError::Inconsistent`] when the
    /// values are not one per column of the model.
    pub fn from_identified(
        m: &Machine,
        id: &IdentifiedValues,
    ) -> Result<(MachineErrors, Vec<LeftOut>), CompensationError> {
        let own = m.fingerprint();
        if id.machine != m.name || id.fingerprint != own {
            return Err(CompensationError::OtherMachine {
                file: id.file.clone(),
                machine: id.machine.clone(),
                fingerprint: id.fingerprint.clone(),
                expected: m.name.clone(),
                expected_fingerprint: own,
            });
        }
        let width = id.model.width();
        for (what, len) in [
            ("values", id.values.len()),
            ("determined flags", id.determined.len()),
            ("fixed flags", id.fixed.len()),
        ] {
            if len != width {
                return Err(CompensationError::Inconsistent {
                    file: id.file.clone(),
                    why: format!("{len} {what} for the {width} parameters of the model"),
                });
            }
        }
        let value_source = |cols: std::ops::Range<usize>| {
            if cols.clone().any(|j| id.fixed[j]) {
                ValueSource::FixedToZero
            } else if cols.clone().any(|j| !id.determined[j]) {
                ValueSource::MinimumNorm
            } else {
                ValueSource::Measured
            }
        };
        let mut compensated: Vec<CompensatedTerm> = Vec::new();
        let mut kinematic = Vec::new();
        let mut left_out = Vec::new();
        let mut missing = (Vec::new(), Vec::new());
        let mut column = 0;
        for term in &id.model.terms {
            let w = term.basis.width();
            let cols = column..column + w;
            column += w;
            let spelling = term.spelling(m);
            let values = id.values[cols.clone()].to_vec();
            if let Effect::KinematicOffset(symbol) = term.effect {
                kinematic.push(KinematicChange {
                    term: *term,
                    symbol,
                    spelling: spelling.clone(),
                    change_mm: values.iter().copied().flatten().next(),
                    source: value_source(cols.clone()),
                });
            }
            if let Some(reason) = left_out_reason(m, term) {
                left_out.push(LeftOut {
                    term: spelling,
                    reason,
                    values,
                });
                continue;
            }
            if values.iter().any(Option::is_none) {
                missing.0.push(spelling);
                missing
                    .1
                    .extend(cols.clone().filter(|&j| id.values[j].is_none()).map(|j| {
                        let k = j - (column - w);
                        crate::fitting::hmatrix::parameter_name(m, term, k)
                    }));
                continue;
            }
            compensated.push(CompensatedTerm {
                term: *term,
                spelling,
                coefficients: values.into_iter().flatten().collect(),
                source: value_source(cols),
            });
        }
        if !missing.0.is_empty() {
            return Err(CompensationError::Undetermined {
                file: id.file.clone(),
                terms: missing.0,
                parameters: missing.1,
            });
        }
        let mut errors: Vec<ErrorId> = compensated
            .iter()
            .filter_map(|t| match t.term.effect {
                Effect::Error(e) => Some(e),
                _ => None,
            })
            .collect();
        errors.sort_unstable();
        errors.dedup();
        let slots = compensated
            .iter()
            .map(|t| match t.term.effect {
                Effect::Error(e) => errors.binary_search(&e).unwrap_or(0),
                _ => 0,
            })
            .collect();
        Ok((
            MachineErrors {
                file: id.file.clone(),
                machine: m.name.clone(),
                fingerprint: own,
                errors,
                terms: compensated,
                kinematic,
                slots,
                motion: vec![1; m.axes.len()],
            },
            left_out,
        ))
    }

    /// The catalogue errors that have at least one compensated term, in catalogue order.
    pub fn errors(&self) -> &[ErrorId] {
        &self.errors
    }

    /// The compensated terms, in the order of the identification.
    pub fn terms(&self) -> &[CompensatedTerm] {
        &self.terms
    }

    /// The compensated terms whose value comes from the fit's constraint, not from the data
    /// (fixed to 0, or the minimum-norm choice), by spelling.
    pub fn set_by_constraint(&self) -> Vec<(&str, ValueSource)> {
        self.terms
            .iter()
            .filter(|t| t.source != ValueSource::Measured)
            .map(|t| (t.spelling.as_str(), t.source))
            .collect()
    }

    /// The identified changes of kinematic symbols, in the order of the identification
    /// (also listed as left out: no error compensation holds them).
    pub fn kinematic_changes(&self) -> &[KinematicChange] {
        &self.kinematic
    }

    /// The file the values were read from.
    pub fn file(&self) -> &str {
        &self.file
    }

    /// The name of the machine they were identified on.
    pub fn machine(&self) -> &str {
        &self.machine
    }

    /// The fingerprint of the machine description they were identified on.
    pub fn fingerprint(&self) -> &str {
        &self.fingerprint
    }

    /// The value of each of `errors()` at a pose: `commands` per machine axis (mm, rad);
    /// `out` has `errors().len()` slots (mm or rad).
    ///
    /// # Panics
    /// When `m` is not the machine the values were read for (another number of axes), or a
    /// slice has the wrong length.
    pub fn values_at(&self, m: &Machine, commands: &[f64], out: &mut [f64]) {
        assert_eq!(
            commands.len(),
            self.motion.len(),
            "one command per axis of machine {}",
            self.machine
        );
        assert_eq!(out.len(), self.errors.len(), "one slot per error");
        out.fill(0.0);
        let cx = BasisContext {
            commands,
            motion: &self.motion,
            tau: 0.0,
            elapsed_s: 0.0,
            since_start_s: 0.0,
            velocity: &[],
            reading: [0.0; 3],
        };
        for (t, &slot) in self.terms.iter().zip(&self.slots) {
            let b = t.term.basis.values(m, t.term.effect.carrier(m), &cx);
            out[slot] += t
                .coefficients
                .iter()
                .zip(b)
                .map(|(c, b)| c * b)
                .sum::<f64>();
        }
    }

    /// True when an error has a term that varies with its axis's position.
    pub fn varies(&self, error: ErrorId) -> bool {
        self.terms
            .iter()
            .any(|t| t.term.effect == Effect::Error(error) && t.term.basis != Basis::Const)
    }

    /// Checks that `m` is the machine description the values were identified on.
    ///
    /// # Errors
    /// [`CompensationError::OtherMachine`].
    pub fn check_machine(&self, m: &Machine) -> Result<(), CompensationError> {
        let own = m.fingerprint();
        if self.machine != m.name || self.fingerprint != own {
            return Err(CompensationError::OtherMachine {
                file: self.file.clone(),
                machine: self.machine.clone(),
                fingerprint: self.fingerprint.clone(),
                expected: m.name.clone(),
                expected_fingerprint: own,
            });
        }
        Ok(())
    }
}
