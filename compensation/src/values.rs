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
//! **Campaigns.** The values are those of an identification of one record or several
//! ([`CampaignValues`]: a record is a campaign of one). Only the machine's shared values are
//! compensated; every parameter that belongs to a set-up or a record (`XOW[k4]`, `dx0[k1]`,
//! `XOC@time:1[k4]`, a ball position `Xw[high]`) is left out and listed under its name. The
//! records' ball positions (kinematic symbols of the workpiece side) do not matter to
//! compensation; the other kinematic symbols (the tool's length, the axes' positions) are the
//! machine's, and the records must agree on them: records modelled with different values of
//! one are refused, the symbol named ([`CompensationError::RecordsDiffer`]). The correction
//! itself takes those symbols from its caller (`--param`).
//!
//! **Undetermined values are refused.** A compensated term whose value the report has as
//! `null` (the data could not determine it: a rank-deficient fit) is an error naming the terms
//! and what to do. A constrained fit gives every parameter a value: `zero: NAME, …` fixes the
//! named parameters to 0 (`fixed: true`), `minimum-norm` gives the undetermined ones the
//! minimum-norm choice (`determined: false`). Those values are taken, and listed
//! ([`MachineErrors::set_by_constraint`]): they come from the constraint, not from the data.
//!
//! Units inside: mm and rad, as everywhere in the solver.

use fitting::campaign::{CampaignValues, Owner};
use model_spec::{ErrorId, ErrorKind, Machine};
use simulation::model::{Basis, BasisContext, Effect, Term};

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
    /// Records of the identification modelled with different values of a kinematic symbol of
    /// the machine's side (not the ball's position): which value the machine has is not known.
    #[error(
        "{file}: {records} were modelled with different values of the machine's kinematic symbol `{symbol}` ({values} mm): the identification does not say which the machine has; compensate with values identified on records of one `{symbol}`"
    )]
    RecordsDiffer {
        /// The file of the values.
        file: String,
        /// The symbol.
        symbol: String,
        /// Two records that differ: "records `a` and `b`".
        records: String,
        /// Their values: "200 and 210".
        values: String,
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
/// ([`crate::kinematics::corrected_description`]).
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
    /// terms; `None` where the data did not determine it. A length of the machine (a
    /// kinematic symbol identified as a term) is its change from the description's default.
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
    /// The kinematic parameters the records were modelled with (mm, symbol order; the first
    /// record's, every record's for the symbols of the machine's side).
    params: Vec<f64>,
}

/// The kinematic parameters of the records of `values` (the first record's), after checking
/// that every record has the same value of each symbol of the machine's side (every symbol but
/// the workpiece's: the ball's position does not matter to compensation).
fn machine_params(
    m: &Machine,
    values: &CampaignValues,
    file: &str,
) -> Result<Vec<f64>, CompensationError> {
    let records = &values.layout.records;
    let Some(first) = records.first() else {
        return Ok(m.default_parameters());
    };
    let workpiece = m.workpiece_symbols();
    for r in &records[1..] {
        for (s, sym) in m.symbols.iter().enumerate() {
            if workpiece.contains(&s) {
                continue;
            }
            let (a, b) = (first.params.get(s), r.params.get(s));
            if a != b {
                let mm = |x: Option<&f64>| x.map_or("?".into(), |x| model_spec::units::short(*x));
                return Err(CompensationError::RecordsDiffer {
                    file: file.to_string(),
                    symbol: sym.name.clone(),
                    records: format!("records `{}` and `{}`", first.label, r.label),
                    values: format!("{} and {}", mm(a), mm(b)),
                });
            }
        }
    }
    if first.params.len() == m.symbols.len() {
        Ok(first.params.clone())
    } else {
        Ok(m.default_parameters())
    }
}

/// Why a term is left out of compensation; `None` for a term that is compensated.
fn left_out_reason(m: &Machine, term: &Term) -> Option<String> {
    let reason = match (term.effect, term.basis) {
        (Effect::SensorOffset(_), _) => {
            "a zero offset of the R-test's reading, not an error of the machine"
        }
        (Effect::PreTravel, _) => {
            "the touch probe's pre-travel (its lobing in the approach azimuth), not an error of the machine"
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
        (_, b) if b.jump_at().is_some() => {
            "a jump during one record (the ball or the sensor moved), not an error of the machine"
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
    /// The machine errors of an identification (`values`, of one record or several, read from
    /// `file`: the file names it in messages); the left-out terms are listed, each parameter
    /// of a set-up or a record under its own name in a campaign (`XOW[k4]`).
    ///
    /// # Errors
    /// [`CompensationError::Undetermined`] when a compensated term has no value (see the
    /// module documentation); [`CompensationError::RecordsDiffer`] when records were modelled
    /// with different values of a kinematic symbol of the machine's side;
    /// [`CompensationError::Inconsistent`] when the values are not one per column of the
    /// layout.
    pub fn from_values(
        m: &Machine,
        values: &CampaignValues,
        file: &str,
    ) -> Result<(MachineErrors, Vec<LeftOut>), CompensationError> {
        let layout = &values.layout;
        let width = layout.columns.len();
        for (what, len) in [
            ("values", values.values.len()),
            ("determined flags", values.determined.len()),
            ("fixed flags", values.fixed.len()),
        ] {
            if len != width {
                return Err(CompensationError::Inconsistent {
                    file: file.to_string(),
                    why: format!("{len} {what} for the {width} parameters of the identification"),
                });
            }
        }
        let params = machine_params(m, values, file)?;
        let value_source = |cols: std::ops::Range<usize>| {
            if cols.clone().any(|j| values.fixed[j]) {
                ValueSource::FixedToZero
            } else if cols.clone().any(|j| !values.determined[j]) {
                ValueSource::MinimumNorm
            } else {
                ValueSource::Measured
            }
        };
        let one = layout.records.len() == 1;
        let nominal = layout.nominal_mm();
        let mut compensated: Vec<CompensatedTerm> = Vec::new();
        let mut kinematic = Vec::new();
        let mut left_out = Vec::new();
        let mut missing = (Vec::new(), Vec::new());
        // One record's columns in its model's order (as its report lists them), several
        // records' in layout order: shared, per set-up, per record.
        let order: Vec<usize> = match layout.records.as_slice() {
            [r] => r.columns.clone(),
            _ => (0..width).collect(),
        };
        let mut k = 0;
        while k < order.len() {
            let column = order[k];
            let c = &layout.columns[column];
            let term = c.term;
            let w = term.basis.width();
            let cols = column..column + w;
            k += w;
            let owned = c.owner != Owner::Shared;
            let spelling = if owned && !one {
                format!("{}[{}]", term.spelling(m), layout.owner_label(c.owner))
            } else {
                term.spelling(m)
            };
            let mut term_values = values.values[cols.clone()].to_vec();
            if let Effect::KinematicOffset(symbol) = term.effect {
                // A length of the machine, as a change from the description's default (the
                // records may have been modelled with another value of it: the controller's).
                if !owned && let Some(n) = nominal[column] {
                    let shift = n - m.symbols[symbol].default;
                    for v in term_values.iter_mut().flatten() {
                        *v += shift;
                    }
                }
                kinematic.push(KinematicChange {
                    term,
                    symbol,
                    spelling: spelling.clone(),
                    change_mm: term_values.iter().copied().flatten().next(),
                    source: value_source(cols.clone()),
                });
            }
            let reason = left_out_reason(m, &term).or_else(|| {
                owned.then(|| match c.owner {
                    Owner::Setup(_) => format!(
                        "belongs to the set-up {} (the workpiece's mounting), not to the machine",
                        layout.owner_label(c.owner)
                    ),
                    _ => format!(
                        "belongs to the record {} (one recording), not to the machine",
                        layout.owner_label(c.owner)
                    ),
                })
            });
            if let Some(reason) = reason {
                left_out.push(LeftOut {
                    term: spelling,
                    reason,
                    values: term_values,
                });
                continue;
            }
            if term_values.iter().any(Option::is_none) {
                missing.0.push(spelling);
                missing.1.extend(
                    cols.clone()
                        .filter(|&j| values.values[j].is_none())
                        .map(|j| fitting::hmatrix::parameter_name(m, &term, j - cols.start)),
                );
                continue;
            }
            compensated.push(CompensatedTerm {
                term,
                spelling,
                coefficients: term_values.into_iter().flatten().collect(),
                source: value_source(cols),
            });
        }
        if !missing.0.is_empty() {
            return Err(CompensationError::Undetermined {
                file: file.to_string(),
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
                file: file.to_string(),
                machine: m.name.clone(),
                fingerprint: m.fingerprint(),
                errors,
                terms: compensated,
                kinematic,
                slots,
                motion: vec![1; m.axes.len()],
                params,
            },
            left_out,
        ))
    }

    /// The kinematic parameters the identification's records were modelled with (mm, symbol
    /// order): every record's value of each symbol of the machine's side, the first record's
    /// ball position. What a correction should use for the machine's symbols unless told
    /// otherwise (`--param`).
    pub fn record_params(&self) -> &[f64] {
        &self.params
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
