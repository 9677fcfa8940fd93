//! The rows of H, sample by sample: a sample's three rows depend on that sample alone (its
//! commands, its gains, its bases), so a long record is filled on several threads, each with its
//! own copy of the gain source, and the matrix is the same, bit for bit, however it is cut.

use super::{Gain, GainSource, HMatrixError, check_sample, parameter_name};
use crate::offsets::OffsetGains;
use model_spec::{Machine, parallel};
use simulation::model::{Basis, BasisContext, Carrier, Model};
use simulation::record::{PreTravelResponse, Record};

/// Samples per thread at least: a shorter record is filled on the calling thread alone (a
/// thread costs more than the rows it would fill).
pub(super) const SAMPLES_PER_THREAD: usize = 50_000;

/// The threads to fill `samples` on: one per core, each with [`SAMPLES_PER_THREAD`] at least.
pub(super) fn threads_for(samples: usize) -> usize {
    parallel::threads_for(samples, SAMPLES_PER_THREAD)
}

/// What every sample's rows are made from: the machine, the model and its columns, the record
/// and what was computed over the whole of it.
pub(super) struct Rows<'a> {
    /// The machine.
    pub(super) m: &'a Machine,
    /// The model (for the names of its columns in errors).
    pub(super) model: &'a Model,
    /// Per column: where its gain comes from, its carrier, basis and component.
    pub(super) cols: &'a [(Gain, Carrier, Basis, usize)],
    /// The record.
    pub(super) record: &'a Record,
    /// The axis velocities (sample-major), when a term needs them.
    pub(super) velocities: &'a [f64],
    /// The gains of the kinematic offsets, when the model has some.
    pub(super) offsets: Option<&'a OffsetGains<'a>>,
    /// The whole record's time span (s), for a block of it.
    pub(super) time_span: Option<(f64, f64)>,
}

impl Rows<'_> {
    /// Fills `data` (H column-major, `3·N` rows, one column per entry of `cols`) with every
    /// sample's rows on `threads` threads (at least one, at most one per sample), each a
    /// contiguous run of samples with its own copy of `source`.
    ///
    /// # Errors
    /// The first sample (in record order) that does not fit the machine, or whose gains or
    /// entries are not finite.
    pub(super) fn fill(
        &self,
        data: &mut [f64],
        source: &mut GainSource,
        threads: usize,
    ) -> Result<(), HMatrixError> {
        let n = self.record.samples.len();
        let rows = 3 * n;
        if rows == 0 || self.cols.is_empty() {
            return Ok(());
        }
        let threads = threads.clamp(1, n);
        // Each thread's samples, and its share of every column.
        let bounds: Vec<usize> = (0..=threads).map(|p| p * n / threads).collect();
        let mut parts: Vec<Vec<&mut [f64]>> = (0..threads).map(|_| Vec::new()).collect();
        for column in data.chunks_mut(rows) {
            let mut rest = column;
            for (p, part) in parts.iter_mut().enumerate() {
                let (mine, others) = rest.split_at_mut(3 * (bounds[p + 1] - bounds[p]));
                part.push(mine);
                rest = others;
            }
        }
        if threads == 1 {
            return self.fill_samples(0..n, &mut parts[0], source);
        }
        // Each part with its own copy of the source (its buffers are written per sample).
        let parts: Vec<_> = parts
            .into_iter()
            .enumerate()
            .map(|(p, columns)| (bounds[p]..bounds[p + 1], columns, source.clone()))
            .collect();
        parallel::map_parts(parts, |(samples, mut columns, mut own)| {
            self.fill_samples(samples, &mut columns, &mut own)
        })
        .into_iter()
        .collect()
    }

    /// Fills the rows of `samples` into `columns` (each column's rows of those samples, from
    /// the first sample's first row).
    fn fill_samples(
        &self,
        samples: std::ops::Range<usize>,
        columns: &mut [&mut [f64]],
        source: &mut GainSource,
    ) -> Result<(), HMatrixError> {
        let (m, record) = (self.m, self.record);
        let n_axes = m.axes.len();
        let first = samples.start;
        let mut g = vec![[0.0; 3]; source.errors().len()];
        let mut symbol_gains: Vec<[f64; 3]> = Vec::new();
        for i in samples {
            check_sample(m, record, i)?;
            let s = &record.samples[i];
            source
                .position_gains(&s.commands, &mut g)
                .map_err(|e| match e {
                    HMatrixError::Sample { message, .. } => {
                        HMatrixError::Sample { sample: i, message }
                    }
                    other => other,
                })?;
            if let Some(o) = self.offsets {
                symbol_gains = o.gains(&s.commands);
            }
            let (tau, elapsed_s) = match self.time_span {
                Some((t0, t1)) if t1 > t0 => (2.0 * (s.t - t0) / (t1 - t0) - 1.0, s.t - t0),
                Some((t0, _)) => (0.0, s.t - t0),
                None => (record.tau(i), record.elapsed_s(i)),
            };
            let cx = BasisContext {
                commands: &s.commands,
                motion: &s.motion,
                tau,
                elapsed_s,
                since_start_s: s.t,
                velocity: self
                    .velocities
                    .get(i * n_axes..(i + 1) * n_axes)
                    .unwrap_or(&[]),
                reading: record.measured.get(i).copied().unwrap_or([0.0; 3]),
            };
            for (c, &(gain, carrier, basis, k)) in self.cols.iter().enumerate() {
                let mut v = [0.0; 3];
                let b = match gain {
                    Gain::PreTravel(order) => {
                        v = PreTravelResponse::harmonic(&record.probe[i], order, k);
                        1.0
                    }
                    _ => basis.values(m, carrier, &cx)[k],
                };
                match gain {
                    Gain::Slot(slot) => v = g[slot],
                    Gain::Unit(d) => v[d] = 1.0,
                    Gain::Reading(d, j) => v[d] = cx.reading[j],
                    Gain::Symbol(s) => v = symbol_gains[s],
                    Gain::PreTravel(_) => {}
                }
                for d in 0..3 {
                    let x = v[d] * b;
                    if !x.is_finite() {
                        let (t, k) = self.model.columns()[c];
                        return Err(HMatrixError::NotFinite {
                            row: 3 * i + d,
                            column: c,
                            sample: i,
                            name: parameter_name(m, &self.model.terms[t], k),
                            value: x,
                        });
                    }
                    columns[c][3 * (i - first) + d] = x;
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::super::{GainSource, HMatrixError, h_matrix_on};
    use simulation::generator::{GeneratorOptions, generate};
    use simulation::model::{Model, Term};

    /// H filled on one, two, three and seven threads is the same matrix, bit for bit, with
    /// columns of every kind (errors, sensor offsets, kinematic offsets, time bases); a sample
    /// that does not fit is the error of the first such sample, whatever thread fills it.
    #[test]
    fn rows_filled_on_several_threads_are_the_rows_filled_on_one() {
        let m = model_spec::builtin("seed-ac").unwrap().unwrap();
        let params = m.default_parameters();
        let record = generate(&m, "K1", &params, &GeneratorOptions::default()).unwrap();
        let spelled = "XOC YOC AOC BOC ECC@harmonic:2 XOC@time:1 YOA@rate dx0 dy0 dz0 Zw";
        let model = Model {
            terms: spelled
                .split_whitespace()
                .map(|t| Term::parse(&m, t).unwrap())
                .collect(),
        };
        let mut source = GainSource::new(&m, &model.errors(), &params).unwrap();
        let one = h_matrix_on(&m, &model, &record, &mut source, None, 1).unwrap();
        assert_eq!(one.ncols(), model.width());
        for threads in [2, 3, 7] {
            let h = h_matrix_on(&m, &model, &record, &mut source, None, threads).unwrap();
            assert_eq!(h.as_slice(), one.as_slice(), "{threads} threads");
        }
        let mut bad = record.clone();
        let n = bad.samples.len();
        for i in [n / 2, n - 3] {
            bad.samples[i].commands[0] = f64::NAN;
        }
        for threads in [1, 2, 3] {
            let e = h_matrix_on(&m, &model, &bad, &mut source, None, threads).unwrap_err();
            assert!(
                matches!(e, HMatrixError::Sample { sample, .. } if sample == n / 2),
                "{threads} threads: {e}"
            );
        }
    }
}
