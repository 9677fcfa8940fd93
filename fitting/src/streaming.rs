//! Identification from long records without holding the H matrix.
//!
//! Blocks of rows of `[H | y]` are folded into the upper-triangular factor `R` ((p+1) × (p+1))
//! of a QR decomposition: `R ← triangular factor of [R; H_b y_b]` (Householder; the fold of
//! `crate::fold`, which every in-memory fit of a tall system uses as well). At every
//! step `RᵀR` equals the Gram matrix of all rows seen, so at the end
//! - `R₁₁` (p × p) and `z = R₁₂` (p) satisfy `R₁₁ᵀR₁₁ = HᵀH` and `R₁₁ᵀz = Hᵀy`;
//! - `R₂₂²` is the part of `‖y‖²` that no combination of the columns reaches,
//!
//! and [`crate::least_squares_reduced`] gives exactly the in-memory solver's estimate,
//! rank, uncertainties, covariance and identifiability. Memory: `(p+1)²` numbers plus one block,
//! whatever the number of samples. Time: `O(rows · p²)`, like one QR of the whole H.

use crate::fold::{BLOCK_ROWS, Blocks, Triangular};
use crate::hmatrix::{GainSource, HMatrixError, h_matrix_spanned, parameter_names};
use crate::{
    Constraint, EstimateError, Fit, Identification, IdentifyOptions, Tolerances, check_readings,
    gain_source, least_squares_reduced, measurement_vector,
};
use formats::csv::{CsvError, MeasurementBlocks, ReadOptions, time_span};
use model_spec::Machine;
use nalgebra::{DMatrix, DVector};
use simulation::model::Basis;
use simulation::model::Model;
use simulation::record::Record;

/// The running triangular factor of `[H | y]` (`crate::fold`: the fold of every in-memory
/// fit, here on blocks as they are read).
#[derive(Clone, Debug)]
pub struct StreamingQr {
    fold: Triangular,
    p: usize,
}

impl StreamingQr {
    /// For `p` parameters.
    pub fn new(p: usize) -> StreamingQr {
        StreamingQr {
            fold: Triangular::new(p + 1),
            p,
        }
    }

    /// Folds in a block of rows `h` (b × p, mm per unit of each parameter) with measurements
    /// `y` (b, mm).
    ///
    /// # Panics
    /// When `h` has another number of columns than the fit's parameters, or `y` another length
    /// than `h` rows (a caller's block, not the user's data).
    pub fn add(&mut self, h: &DMatrix<f64>, y: &DVector<f64>) {
        let (b, p) = (h.nrows(), self.p);
        assert_eq!(h.ncols(), p, "block has {} columns, the fit {p}", h.ncols());
        assert_eq!(
            y.len(),
            b,
            "block has {b} rows and {} measurements",
            y.len()
        );
        let blocks = Blocks {
            first: b,
            rest: BLOCK_ROWS,
        };
        self.fold.fold_blocks(b, blocks, |start, len, scratch| {
            scratch
                .view_mut((0, 0), (len, p))
                .copy_from(&h.view((start, 0), (len, p)));
            scratch
                .view_mut((0, p), (len, 1))
                .copy_from(&y.rows(start, len));
        });
    }

    /// Rows folded in so far.
    pub fn rows(&self) -> usize {
        self.fold.rows()
    }

    /// Bytes held between blocks (the factor).
    pub fn state_bytes(&self) -> usize {
        self.fold.r().len() * std::mem::size_of::<f64>()
    }

    /// The least-squares fit of all rows seen (see [`crate::least_squares()`]).
    pub fn solve(
        &self,
        names: &[String],
        constraint: &Constraint,
        tol: &Tolerances,
    ) -> Result<Fit, EstimateError> {
        let (p, r) = (self.p, self.fold.r());
        let r11 = r.view((0, 0), (p, p)).into_owned();
        let z = r.view((0, p), (p, 1)).column(0).into_owned();
        let outside = r[(p, p)] * r[(p, p)];
        least_squares_reduced(&r11, &z, names, constraint, tol, self.rows(), outside)
    }
}

/// Why a streaming identification failed.
#[derive(Debug, thiserror::Error)]
pub enum StreamingError<E: std::error::Error + 'static> {
    /// A block could not be read.
    #[error(transparent)]
    Read(E),
    /// A block's H matrix could not be built.
    #[error(transparent)]
    HMatrix(#[from] HMatrixError),
    /// A block's measurements, or the final solve, failed.
    #[error(transparent)]
    Estimate(#[from] EstimateError),
    /// The record must be read twice (a model with `time:K` or `exp:TAU` terms needs its time
    /// span first) but is not a regular file (a pipe or a device can be read once only).
    /// `rate` and `warmup:TAU` count from time 0 and need no span.
    #[error(
        "`{0}`: a model with time:K or exp:TAU terms reads the record twice (its time span first), so it must be a regular file, not a pipe or a device"
    )]
    ReadTwice(String),
}

/// A streaming identification.
#[derive(Clone, Debug)]
pub struct StreamingIdentification {
    /// The fit (its `residual` is the reduced system's, not per sample).
    pub fit: Fit,
    /// Samples used.
    pub samples: usize,
    /// Blocks folded in.
    pub blocks: usize,
    /// Largest block, samples.
    pub largest_block: usize,
    /// The first block, samples (a block reader may read ahead in it).
    pub first_block: usize,
}

/// Identifies `model` from `blocks` of one record (each a [`Record`] with measurements;
/// `time_span` `(t0, t1)` is the whole record's, s, for `time:K` and `exp:TAU` terms; `rate`
/// and `warmup:TAU` count from the record's time 0 and need none), with
/// gains from `source`. First-order least squares, as [`crate::identify()`] without
/// the refinement (which needs the whole record).
///
/// # Errors
/// Besides reading and fitting errors, [`HMatrixError::Times`] for a model with `velocity`
/// terms (the axis velocities are central differences across samples, which blocks cut) or
/// with `exp:TAU` terms and no `time_span`.
pub fn identify_streaming<E: std::error::Error + 'static>(
    m: &Machine,
    model: &Model,
    blocks: impl IntoIterator<Item = Result<Record, E>>,
    time_span: Option<(f64, f64)>,
    source: &mut GainSource,
    constraint: &Constraint,
    tol: &Tolerances,
) -> Result<StreamingIdentification, StreamingError<E>> {
    let refuse = |t: &simulation::model::Term, message: &str| {
        StreamingError::HMatrix(HMatrixError::Times {
            term: t.spelling(m),
            message: message.into(),
        })
    };
    if let Some(t) = model.terms.iter().find(|t| t.basis == Basis::Velocity) {
        return Err(refuse(
            t,
            "velocity terms need the whole record (central differences across samples): not available when the record is read in blocks",
        ));
    }
    if time_span.is_none()
        && let Some(t) = model
            .terms
            .iter()
            .find(|t| matches!(t.basis, Basis::Exp(_)))
    {
        return Err(refuse(
            t,
            "exp:TAU terms count time from the record's first sample: give the record's time span",
        ));
    }
    let mut qr = StreamingQr::new(model.width());
    let (mut samples, mut count, mut largest, mut first) = (0, 0, 0, None);
    for block in blocks {
        let block = block.map_err(StreamingError::Read)?;
        first.get_or_insert(block.samples.len());
        let h = h_matrix_spanned(m, model, &block, source, time_span)?;
        let y = measurement_vector(&block)?;
        qr.add(&h, &y);
        samples += block.samples.len();
        largest = largest.max(block.samples.len());
        count += 1;
    }
    check_readings(samples, model.width())?;
    let fit = qr.solve(&parameter_names(m, model), constraint, tol)?;
    Ok(StreamingIdentification {
        fit,
        samples,
        blocks: count,
        largest_block: largest,
        first_block: first.unwrap_or(0),
    })
}

/// Identifies `model` of `m` from the measurement CSV at `path`, read in blocks of `block`
/// samples with `read` (never the whole record, never the whole H): first-order least
/// squares, with the options of [`crate::identify()`] (zeroed readings add
/// `dx0 dy0 dz0`). A model with `time:K` or `exp:TAU` terms costs one more pass over the file
/// for the record's time span (`rate` and `warmup:TAU` do not: they count from time 0, and
/// are read from a pipe in one pass); `velocity` terms are refused ([`identify_streaming`]).
/// Fewer readings than parameters plus one is an error, as in memory. The [`Digest`] is that of
/// the bytes of the pass that was fitted, hashed as they were read.
///
/// [`Digest`]: model_spec::sha256::Digest
pub fn identify_file(
    m: &Machine,
    model: &Model,
    path: &std::path::Path,
    opts: &IdentifyOptions,
    block: usize,
    read: &ReadOptions,
) -> Result<
    (
        Identification,
        StreamingIdentification,
        model_spec::sha256::Digest,
    ),
    StreamingError<CsvError>,
> {
    let fitted = opts.fitted_model(model);
    let mut source = gain_source(m, model, opts)?;
    let has_time = fitted
        .terms
        .iter()
        .any(|t| matches!(t.basis, Basis::Time(_) | Basis::Exp(_)));
    let span = if has_time {
        if !std::fs::metadata(path).is_ok_and(|f| f.is_file()) {
            return Err(StreamingError::ReadTwice(path.display().to_string()));
        }
        Some(time_span(path, m, read).map_err(StreamingError::Read)?)
    } else {
        None
    };
    let file = path.display().to_string();
    let opened = std::fs::File::open(path).map_err(|source| {
        StreamingError::Read(CsvError::Io {
            file: file.clone(),
            source,
        })
    })?;
    let mut hashed = model_spec::sha256::HashingReader::new(opened);
    let blocks =
        MeasurementBlocks::new(file, &mut hashed, m, block, read).map_err(StreamingError::Read)?;
    let run = identify_streaming(
        m,
        &fitted,
        blocks,
        span,
        &mut source,
        &opts.constraint,
        &opts.tolerances,
    )?;
    let ident = Identification::new(
        m,
        fitted,
        run.fit.clone(),
        run.samples,
        opts.zeroed,
        &source,
    );
    Ok((ident, run, hashed.digest()))
}
