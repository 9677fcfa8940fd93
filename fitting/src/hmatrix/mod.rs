//! The H matrix (design matrix) of a [`Model`] on a [`Record`]: measured error vector ≈ H · p.
//!
//! - Rows: three per sample, `x, y, z` of the error vector (tool minus workpiece, tool frame),
//!   sample by sample: row `3·i + d` is direction `d` of sample `i`.
//! - Columns: one per model column ([`Model::columns`]): a term `effect × basis`, two columns
//!   for `harmonic:K` (cos, then sin).
//! - Entry: `g_d(pose_i) · b(sample_i)`, the position gain `g` of the term's effect (mm per mm
//!   for translational errors, mm per rad for angular ones) times the basis value `b`
//!   ([`simulation::model::Basis::values`] with the effect's carrier at the sample's
//!   [`simulation::model::BasisContext`]: commands, motion, [`Record::tau`], [`Record::elapsed_s`], the axis
//!   velocities of [`Record::velocities`] and the measured reading). The sensor offsets
//!   `dx0 dy0 dz0` have gain `+1` in their own direction and 0 in the others.
//! - Instrument terms `S<i><j>` (dimensionless) act on the reading, not on the machine: the row
//!   of direction `i` gets the displacement in direction `j`, for which the measured reading of
//!   direction `j` stands. That is first order: the reading differs from the displacement by
//!   the instrument terms themselves (S·d, S small) and by the sensor offsets (a constant,
//!   which `dx0 dy0 dz0` absorb) and the noise. The noise in H biases the fit by about
//!   (σ_noise / displacement)² relative, negligible when the noise is much smaller than the
//!   displacements; the refinement against the exact machine (which applies `(I + S)` to the
//!   displacement exactly) removes the first-order part.
//! - A touch probe's pre-travel `PRE@harmonic:K` (mm of amplitude): per pose, the sphere fit's
//!   response to the hits' pre-travel `ρ·cos Kφ` and `ρ·sin Kφ` (probe records only:
//!   [`Record::probe`]).
//! - Kinematic offsets (a symbol of the description, `Zt`): the exact derivative of the
//!   tool-minus-workpiece vector with respect to the symbol, mm/mm
//!   ([`crate::offsets`]); their coefficient is the symbol's change, mm.
//! - `velocity` terms need the whole record (central differences across samples) and real
//!   times; `exp:TAU`, `rate` and `warmup:TAU` need real times: a record whose samples are
//!   numbered is refused ([`HMatrixError::Times`]), and so is, for `warmup:TAU`, a record with
//!   a sample before time 0 of its clock (the warm-up's start).
//! - `rate` and `warmup:TAU` count from time 0 of the record's clock: the sample's time `t`
//!   (s) itself, on the record's own clock or, for a record moved onto a campaign clock, on
//!   that clock.
//!
//! With `p` in mm (translational), rad (angular), ms (`velocity`) and 1 (instrument terms),
//! `H · p` is in mm.
//!
//! Gains come from a [`GainSource`]: the compiled code of the `generated` crate for a built-in
//! machine (its `full` model, the needed errors picked out), or the in-process evaluator of the
//! straight-line IR ([`codegen::compile`] of a [`GainModel`] derived for the needed errors) for
//! any machine, in particular machines given as files. Both give the same numbers to rounding.

use codegen::atoms::AtomTable;
use codegen::{GainModel, Program};
use generated::CompiledModel;
use model_spec::{ErrorId, FULL_MODEL, Machine};
use nalgebra::DMatrix;
use simulation::model::{Basis, Effect, Model, Term};
use simulation::record::Record;

mod fill;

/// Why an H matrix (or its gain source) cannot be built.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum HMatrixError {
    /// The kinematic parameters do not fit the machine.
    #[error("machine `{machine}`: {message}")]
    Parameters {
        /// The machine's name.
        machine: String,
        /// What is wrong.
        message: String,
    },
    /// An error id outside the machine's catalogue.
    #[error("machine `{machine}`: error id {id} is not in its catalogue ({len} entries)")]
    UnknownError {
        /// The machine's name.
        machine: String,
        /// The id.
        id: ErrorId,
        /// Catalogue length.
        len: usize,
    },
    /// Compiled gains were asked for a machine that is not a built-in machine (or differs from
    /// the built-in description of that name).
    #[error(
        "machine `{machine}` has no compiled gains: it is not a built-in machine, or its description differs from the built-in one (use the evaluator)"
    )]
    NotCompiled {
        /// The machine's name.
        machine: String,
    },
    /// A term that does not fit the machine (a basis that does not fit its effect).
    #[error("term `{term}`: {message}")]
    Term {
        /// The term's name.
        term: String,
        /// What is wrong.
        message: String,
    },
    /// A term that needs real times (or velocities) on a record without them.
    #[error("term `{term}`: {message}")]
    Times {
        /// The term's name (`EXX@velocity`).
        term: String,
        /// What is missing.
        message: String,
    },
    /// A sample that does not fit the machine.
    #[error("sample {sample}: {message}")]
    Sample {
        /// The sample's index (0-based).
        sample: usize,
        /// What is wrong.
        message: String,
    },
    /// The gain source was prepared for other errors or another machine.
    #[error("the gain source was prepared for machine `{source_machine}` without error `{error}`")]
    MissingError {
        /// Machine of the source.
        source_machine: String,
        /// The error it lacks.
        error: String,
    },
    /// An entry came out NaN or infinite (e.g. `poly:K` of an axis without a finite stroke).
    #[error("H[{row}, {column}] (sample {sample}, column `{name}`) is not finite ({value})")]
    NotFinite {
        /// Row.
        row: usize,
        /// Column.
        column: usize,
        /// Sample.
        sample: usize,
        /// Column name.
        name: String,
        /// The value.
        value: f64,
    },
}

/// Which code computes the gains of a [`GainSource`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Backend {
    /// The compiled `full` model of the `generated` crate only.
    Compiled,
    /// The in-process IR evaluator only.
    Evaluator,
    /// Compiled code for the errors of the compiled `full` model, the evaluator for the rest.
    Mixed,
}

/// The compiled part of a source: the model and `(index in its output, slot)` pairs.
#[derive(Clone, Debug)]
struct CompiledPart {
    model: &'static CompiledModel,
    picks: Vec<(usize, usize)>,
    out: Vec<f64>,
}

/// The evaluator part of a source: the program and `(index in its output, slot)` pairs.
#[derive(Clone, Debug)]
struct EvaluatorPart {
    program: Program,
    picks: Vec<(usize, usize)>,
    scratch: Vec<f64>,
    out: Vec<f64>,
}

/// Position gains of a chosen set of errors of one machine at any pose, at fixed kinematic
/// parameters: compiled code or the IR evaluator (see [`Backend`]). Holds its own buffers, so
/// evaluation allocates nothing.
#[derive(Clone, Debug)]
pub struct GainSource {
    machine: String,
    axes: usize,
    atoms: AtomTable,
    /// Number of pose atoms (sin/cos of rotary commands, linear commands).
    n_pose: usize,
    /// Atom values: pose atoms, then the kinematic parameters (mm).
    values: Vec<f64>,
    errors: Vec<ErrorId>,
    /// Catalogue id → slot in `errors`.
    slot: Vec<Option<usize>>,
    compiled: Option<CompiledPart>,
    evaluator: Option<EvaluatorPart>,
}

fn check_setup(m: &Machine, errors: &[ErrorId], params: &[f64]) -> Result<(), HMatrixError> {
    if params.len() != m.symbols.len() {
        return Err(HMatrixError::Parameters {
            machine: m.name.clone(),
            message: format!(
                "expected one kinematic parameter per symbol ({}), got {}",
                m.symbols.len(),
                params.len()
            ),
        });
    }
    if let Some((s, v)) = params.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(HMatrixError::Parameters {
            machine: m.name.clone(),
            message: format!(
                "kinematic parameter `{}` is not finite ({v})",
                m.symbols[s].name
            ),
        });
    }
    if let Some(&id) = errors.iter().find(|&&e| e >= m.catalogue.len()) {
        return Err(HMatrixError::UnknownError {
            machine: m.name.clone(),
            id,
            len: m.catalogue.len(),
        });
    }
    Ok(())
}

/// `true` when `m` is exactly the built-in machine of its name (so that its compiled code
/// describes it).
fn is_builtin(m: &Machine) -> bool {
    matches!(model_spec::builtin(&m.name), Some(Ok(b)) if b == *m)
}

impl GainSource {
    fn base(m: &Machine, errors: &[ErrorId], params: &[f64]) -> Result<GainSource, HMatrixError> {
        check_setup(m, errors, params)?;
        let atoms = AtomTable::new(m);
        let n_pose = atoms.pose_count();
        let mut values = vec![0.0; n_pose];
        values.extend_from_slice(params);
        let mut errs: Vec<ErrorId> = Vec::with_capacity(errors.len());
        for &e in errors {
            if !errs.contains(&e) {
                errs.push(e);
            }
        }
        let mut slot = vec![None; m.catalogue.len()];
        for (i, &e) in errs.iter().enumerate() {
            slot[e] = Some(i);
        }
        Ok(GainSource {
            machine: m.name.clone(),
            axes: m.axes.len(),
            atoms,
            n_pose,
            values,
            errors: errs,
            slot,
            compiled: None,
            evaluator: None,
        })
    }

    /// The compiled `full` model of `m`, if `m` is a built-in machine and the compiled inputs
    /// are the atoms of `m` in the same order.
    fn compiled_full(&self, m: &Machine) -> Option<&'static CompiledModel> {
        let c = generated::lookup(&m.name, FULL_MODEL)?;
        let pose_ok = c.pose_inputs.len() == self.n_pose
            && c.pose_inputs
                .iter()
                .zip(&self.atoms.names)
                .all(|(a, b)| *a == b.as_str());
        let params_ok = c.parameters.len() == m.symbols.len()
            && c.parameters
                .iter()
                .zip(&m.symbols)
                .all(|(a, s)| *a == s.name);
        (is_builtin(m) && pose_ok && params_ok).then_some(c)
    }

    fn attach_evaluator(&mut self, m: &Machine, slots: &[usize]) {
        if slots.is_empty() {
            return;
        }
        let ids: Vec<ErrorId> = slots.iter().map(|&s| self.errors[s]).collect();
        let program = codegen::compile(m, &GainModel::derive(m, &ids));
        let out = vec![0.0; program.outputs.len()];
        self.evaluator = Some(EvaluatorPart {
            picks: slots.iter().enumerate().map(|(k, &s)| (k, s)).collect(),
            scratch: Vec::with_capacity(program.ops.len()),
            out,
            program,
        });
    }

    /// The best source for `errors` of `m` at kinematic parameters `params` (mm, symbol
    /// order): compiled code when `m` is a built-in machine, the evaluator for the errors its
    /// compiled `full` model lacks (or for everything when `m` is not built in).
    ///
    /// # Errors
    /// Parameters of the wrong length or not finite; an error id outside the catalogue.
    pub fn new(
        m: &Machine,
        errors: &[ErrorId],
        params: &[f64],
    ) -> Result<GainSource, HMatrixError> {
        let mut s = GainSource::base(m, errors, params)?;
        let mut rest: Vec<usize> = (0..s.errors.len()).collect();
        if let Some(c) = s.compiled_full(m) {
            let mut picks = Vec::new();
            rest.clear();
            for (slot, &e) in s.errors.iter().enumerate() {
                match c.errors.iter().position(|n| *n == m.catalogue[e].name) {
                    Some(k) => picks.push((k, slot)),
                    None => rest.push(slot),
                }
            }
            s.compiled = Some(CompiledPart {
                model: c,
                picks,
                out: vec![0.0; 3 * c.errors.len()],
            });
        }
        s.attach_evaluator(m, &rest);
        Ok(s)
    }

    /// Compiled code only (the `full` model of the built-in machine `m`, errors picked out).
    ///
    /// # Errors
    /// As [`GainSource::new`]; [`HMatrixError::NotCompiled`] when `m` is not a built-in
    /// machine or an error is not in its compiled `full` model.
    pub fn compiled(
        m: &Machine,
        errors: &[ErrorId],
        params: &[f64],
    ) -> Result<GainSource, HMatrixError> {
        let s = GainSource::new(m, errors, params)?;
        if s.evaluator.is_some() || s.compiled.is_none() {
            return Err(HMatrixError::NotCompiled {
                machine: m.name.clone(),
            });
        }
        Ok(s)
    }

    /// The in-process IR evaluator only, for any machine: [`codegen::compile`] of the
    /// [`GainModel`] of exactly `errors`.
    ///
    /// # Errors
    /// As [`GainSource::new`].
    pub fn evaluator(
        m: &Machine,
        errors: &[ErrorId],
        params: &[f64],
    ) -> Result<GainSource, HMatrixError> {
        let mut s = GainSource::base(m, errors, params)?;
        let all: Vec<usize> = (0..s.errors.len()).collect();
        s.attach_evaluator(m, &all);
        Ok(s)
    }

    /// Which code computes the gains.
    pub fn backend(&self) -> Backend {
        match (&self.compiled, &self.evaluator) {
            (Some(_), Some(_)) => Backend::Mixed,
            (Some(_), None) => Backend::Compiled,
            (None, _) => Backend::Evaluator,
        }
    }

    /// The machine's name.
    pub fn machine(&self) -> &str {
        &self.machine
    }

    /// The errors whose gains it gives, in output order (repeats removed).
    pub fn errors(&self) -> &[ErrorId] {
        &self.errors
    }

    /// The output slot of error `e`, if the source has it.
    pub fn slot(&self, e: ErrorId) -> Option<usize> {
        self.slot.get(e).copied().flatten()
    }

    /// The kinematic parameters (mm, symbol order).
    pub fn params(&self) -> &[f64] {
        &self.values[self.n_pose..]
    }

    /// Position gains `[gx, gy, gz]` (tool frame; mm/mm or mm/rad) of every error of
    /// [`GainSource::errors`], in that order, at `commands` (one per axis: mm, rad). Valid where
    /// the nominal tool point is on the nominal workpiece point (every R-test sample).
    ///
    /// # Errors
    /// [`HMatrixError::Sample`] (index 0) when `commands` or `out` has the wrong length.
    pub fn position_gains(
        &mut self,
        commands: &[f64],
        out: &mut [[f64; 3]],
    ) -> Result<(), HMatrixError> {
        if commands.len() != self.axes || out.len() != self.errors.len() {
            return Err(HMatrixError::Sample {
                sample: 0,
                message: format!(
                    "expected {} commands and {} gain slots, got {} and {}",
                    self.axes,
                    self.errors.len(),
                    commands.len(),
                    out.len()
                ),
            });
        }
        self.atoms.fill_pose(commands, &mut self.values);
        if let Some(c) = &mut self.compiled {
            let (pose, params) = self.values.split_at(self.n_pose);
            (c.model.position_gains)(pose, params, &mut c.out);
            let n = c.model.errors.len();
            for &(k, s) in &c.picks {
                out[s] = [c.out[k], c.out[n + k], c.out[2 * n + k]];
            }
        }
        if let Some(e) = &mut self.evaluator {
            e.program.eval(&self.values, &mut e.scratch, &mut e.out);
            for &(k, s) in &e.picks {
                out[s].copy_from_slice(&e.out[6 * k..6 * k + 3]);
            }
        }
        Ok(())
    }
}

/// The name of column `k` of `term` as people and the JSON see it: the effect's name for a
/// constant term (`XOC`, `dx0`), else `NAME@BASIS` with `:cos`/`:sin` for harmonics
/// (`ECC@harmonic:2:cos`, `EXX@reversal`).
pub fn parameter_name(m: &Machine, term: &Term, k: usize) -> String {
    let n = term.effect.name(m);
    match term.basis {
        simulation::model::Basis::Const => n,
        b => {
            let names = b.column_names();
            format!("{n}@{}", names.get(k).unwrap_or(&names[0]))
        }
    }
}

/// The parameter names of every column of `model` ([`parameter_name`]), in column order.
/// Every effect must be of `m` (see [`check_model`]).
pub fn parameter_names(m: &Machine, model: &Model) -> Vec<String> {
    model
        .columns()
        .into_iter()
        .map(|(t, k)| parameter_name(m, &model.terms[t], k))
        .collect()
}

/// Checks that every term of `model` belongs to `m`: error ids in its catalogue, bases that fit
/// their effects ([`Term::check`]).
///
/// # Errors
/// [`HMatrixError::UnknownError`] or [`HMatrixError::Term`].
pub fn check_model(m: &Machine, model: &Model) -> Result<(), HMatrixError> {
    for t in &model.terms {
        if let Effect::Error(e) = t.effect
            && e >= m.catalogue.len()
        {
            return Err(HMatrixError::UnknownError {
                machine: m.name.clone(),
                id: e,
                len: m.catalogue.len(),
            });
        }
        t.check(m).map_err(|e| HMatrixError::Term {
            term: t.spelling(m),
            message: e.0,
        })?;
    }
    Ok(())
}

/// Where a column's gain comes from.
#[derive(Clone, Copy)]
enum Gain {
    /// Slot of the gain source.
    Slot(usize),
    /// A sensor offset: `+1` along this direction.
    Unit(usize),
    /// An instrument term: the measured reading of direction `.1` in the row of direction `.0`.
    Reading(usize, usize),
    /// A kinematic offset: the gain of this symbol.
    Symbol(usize),
    /// A probe's pre-travel of this harmonic order: the sphere fits' response
    /// ([`simulation::record::PreTravelResponse::harmonic`]); its basis value is 1.
    PreTravel(u32),
}

/// The axis velocities of `record` (sample-major, mm/ms or rad/ms) when `model` has a
/// `velocity` term, else nothing; checks that the record has real times when a term needs them.
fn times_for(
    m: &Machine,
    model: &Model,
    record: &Record,
    block: bool,
) -> Result<Vec<f64>, HMatrixError> {
    let times_err = |t: &Term, message: String| HMatrixError::Times {
        term: t.spelling(m),
        message,
    };
    if let Some(t) = model.terms.iter().find(|t| t.basis.needs_times()) {
        record
            .check_times(&t.spelling(m))
            .map_err(|e| times_err(t, e.0))?;
    }
    if let Some(t) = model.terms.iter().find(|t| t.basis.starts_at_zero()) {
        record
            .check_started(&t.spelling(m))
            .map_err(|e| times_err(t, e.0))?;
    }
    match model.terms.iter().find(|t| t.basis == Basis::Velocity) {
        Some(t) if block => Err(times_err(
            t,
            "velocity terms need the whole record (central differences across samples), not a block of it".into(),
        )),
        Some(t) => record
            .velocities(&t.spelling(m), m.axes.len())
            .map_err(|e| times_err(t, e.0)),
        None => Ok(Vec::new()),
    }
}

/// Checks a sample's lengths and values against the machine.
fn check_sample(m: &Machine, record: &Record, i: usize) -> Result<(), HMatrixError> {
    let s = &record.samples[i];
    let err = |message: String| HMatrixError::Sample { sample: i, message };
    if s.commands.len() != m.axes.len() {
        return Err(err(format!(
            "{} commands for the {} axes of machine `{}`",
            s.commands.len(),
            m.axes.len(),
            m.name
        )));
    }
    if s.motion.len() != m.axes.len() {
        return Err(err(format!(
            "{} directions of motion for the {} axes of machine `{}`",
            s.motion.len(),
            m.axes.len(),
            m.name
        )));
    }
    if let Some(a) = (0..m.axes.len()).find(|&a| !s.commands[a].is_finite()) {
        return Err(err(format!(
            "the command of axis {} is not finite ({})",
            m.axes[a].name, s.commands[a]
        )));
    }
    if !s.t.is_finite() {
        return Err(err(format!("the time is not finite ({})", s.t)));
    }
    Ok(())
}

/// The H matrix of `model` on `record` (3 rows per sample, one column per model column; mm per
/// unit of each parameter: mm/mm, mm/rad), with gains from `source` (prepared for `m` and
/// covering every error of `model`). See the module documentation for the layout.
///
/// # Errors
/// A term that does not fit `m`, a sample that does not fit `m`, a source without one of the
/// model's errors, an entry that is not finite.
pub fn h_matrix(
    m: &Machine,
    model: &Model,
    record: &Record,
    source: &mut GainSource,
) -> Result<DMatrix<f64>, HMatrixError> {
    h_matrix_spanned(m, model, record, source, None)
}

/// [`h_matrix`] of a block of a longer record (or of a whole record with `None`; a record of
/// 100 000 samples or more is filled on every core, the same matrix bit for bit): `time_span` `(t0, t1)` (s) is the whole
/// record's, so that `time:K` terms are normalised over the record and `exp:TAU` counts from
/// its first sample, not the block's (`rate` and `warmup:TAU` count from time 0 and need no
/// span). With a `time_span`, `velocity` terms are refused (they need the whole record).
pub fn h_matrix_spanned(
    m: &Machine,
    model: &Model,
    record: &Record,
    source: &mut GainSource,
    time_span: Option<(f64, f64)>,
) -> Result<DMatrix<f64>, HMatrixError> {
    let threads = fill::threads_for(record.samples.len());
    h_matrix_on(m, model, record, source, time_span, threads)
}

/// [`h_matrix_spanned`] with the rows filled on `threads` threads (the same matrix, bit for
/// bit, on any number).
fn h_matrix_on(
    m: &Machine,
    model: &Model,
    record: &Record,
    source: &mut GainSource,
    time_span: Option<(f64, f64)>,
    threads: usize,
) -> Result<DMatrix<f64>, HMatrixError> {
    check_model(m, model)?;
    // Per column: where its gain comes from, carrier, basis, component.
    let mut cols = Vec::with_capacity(model.width());
    for (t, k) in model.columns() {
        let term = model.terms[t];
        if !record.probe.is_empty() {
            probe_term(m, &term)?;
        }
        let gain = match term.effect {
            Effect::Error(e) => match source.slot(e) {
                Some(s) if source.machine == m.name => Gain::Slot(s),
                _ => {
                    return Err(HMatrixError::MissingError {
                        source_machine: source.machine.clone(),
                        error: m.catalogue[e].name.clone(),
                    });
                }
            },
            Effect::SensorOffset(d) => Gain::Unit(d.index()),
            Effect::Instrument {
                reading,
                displacement,
            } => {
                if record.measured.len() != record.samples.len() {
                    return Err(HMatrixError::Term {
                        term: term.spelling(m),
                        message: "an instrument term needs the measured readings (its column is the reading of the displacement it takes)".into(),
                    });
                }
                Gain::Reading(reading.index(), displacement.index())
            }
            Effect::KinematicOffset(s) => Gain::Symbol(s),
            Effect::PreTravel => {
                let Basis::Harmonic(order) = term.basis else {
                    return Err(HMatrixError::Term {
                        term: term.spelling(m),
                        message: "a touch probe's pre-travel is a harmonic of the approach azimuth (PRE@harmonic:K)".into(),
                    });
                };
                if record.probe.len() != record.samples.len() {
                    return Err(HMatrixError::Term {
                        term: term.spelling(m),
                        message: "a touch probe's pre-travel needs records of probe hits (read through --probe): its columns are what each pose's sphere fit makes of the hits' pre-travel".into(),
                    });
                }
                Gain::PreTravel(order)
            }
        };
        cols.push((gain, term.effect.carrier(m), term.basis, k));
    }
    let velocities = times_for(m, model, record, time_span.is_some())?;
    let offsets =
        crate::offsets::has_kinematic_offsets(model).then(|| crate::offsets::OffsetGains::new(m));
    let n = record.samples.len();
    // Every entry is written below: zeroed pages from the allocator, not a pass of zeros.
    let mut h = DMatrix::from_vec(3 * n, cols.len(), vec![0.0; 3 * n * cols.len()]);
    let rows = fill::Rows {
        m,
        model,
        cols: &cols,
        record,
        velocities: &velocities,
        offsets: offsets.as_ref(),
        time_span,
    };
    rows.fill(h.as_mut_slice(), source, threads)?;
    Ok(h)
}

/// Refuses a term a touch probe's readings cannot carry: a linear axis's reversal (the hits of a
/// pose approach along both directions of every linear axis, so its backlash moves the hits and
/// the sphere's radius, not the centre) and the servo lag (the probe stands still at a hit).
pub fn probe_term(m: &Machine, term: &Term) -> Result<(), HMatrixError> {
    let why = match (term.basis, term.effect.carrier(m)) {
        (Basis::Reversal, model_spec::basis::Carrier::Axis(a))
            if m.axes[a].kind == model_spec::AxisKind::Linear =>
        {
            "a touch probe's pose approaches the sphere along both directions of every linear axis: a linear axis's backlash moves the hits (and the fitted radius), not the centre, so probe readings do not carry it; the reversal of rotary axes they do (poses approached from either side)"
        }
        (Basis::Velocity, _) => {
            "a touch probe stands still at every hit: its readings carry no servo lag"
        }
        _ => return Ok(()),
    };
    Err(HMatrixError::Term {
        term: term.spelling(m),
        message: why.into(),
    })
}

/// [`h_matrix`] with the best [`GainSource`] for the model's errors at kinematic parameters
/// `params` (mm, symbol order; e.g. [`Machine::default_parameters`]).
///
/// # Errors
/// As [`GainSource::new`] and [`h_matrix`].
pub fn h_matrix_auto(
    m: &Machine,
    model: &Model,
    record: &Record,
    params: &[f64],
) -> Result<DMatrix<f64>, HMatrixError> {
    check_model(m, model)?;
    let mut source = GainSource::new(m, &model.errors(), params)?;
    h_matrix(m, model, record, &mut source)
}
