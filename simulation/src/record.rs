//! A sequence of R-test samples along a path: the commanded pose of every axis, the time, the
//! direction of motion of every axis, and (for measured records) the error vector read.
//!
//! Times are real (a `t_s` column, or a simulated path) or only sample numbers (a CSV without
//! `t_s`): [`Sample::timed`] says which. Terms that need real times (`velocity`, `exp:TAU`,
//! `rate`, `warmup:TAU`) refuse a record whose samples are numbered ([`Record::check_times`]);
//! a warm-up, which starts at time 0, refuses a record with a sample before it
//! ([`Record::check_started`]).
//!
//! Axis velocities ([`Record::velocities`]) are central differences of the commands over the
//! times, `v_i = (q_{i+1} − q_{i−1}) / (t_{i+1} − t_{i−1})`, one-sided at the two ends
//! (`(q_1 − q_0)/(t_1 − t_0)`, `(q_{n−1} − q_{n−2})/(t_{n−1} − t_{n−2})`), in mm/ms or rad/ms.

/// One sample.
#[derive(Clone, Debug, PartialEq)]
pub struct Sample {
    /// Commanded position of every axis, `Machine::axes` order: mm for linear, rad for rotary.
    pub commands: Vec<f64>,
    /// Time since the start of the record, s.
    pub t: f64,
    /// Direction of motion of every axis when the sample was taken: +1 or −1 (an axis at rest
    /// keeps the direction of its last move; +1 before any move).
    pub motion: Vec<i8>,
    /// `true` when `t` is a real time (a `t_s` column, a simulated path); `false` when the CSV
    /// had no `t_s` column and `t` is the sample's number (0, 1, 2 … s).
    pub timed: bool,
}

/// Why a record's times cannot serve a term that needs them.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct TimesError(pub String);

/// A record: samples and, when measured, the error vector at each (tool minus workpiece, tool
/// frame, mm), with the covariance of each reading when the instrument declares one. Two
/// records are equal when their samples, readings and covariances are: the lines they were read
/// from do not count.
#[derive(Clone, Debug, Default)]
pub struct Record {
    /// The samples, in the order they were taken.
    pub samples: Vec<Sample>,
    /// The measured error vector per sample (mm); empty for a bare path.
    pub measured: Vec<[f64; 3]>,
    /// Per sample, the covariance of the error vector read (mm², tool frame): the sensors'
    /// noise propagated through the instrument's geometry ([`crate::instrument`]). Empty when
    /// none is declared (a record of error vectors); otherwise one per sample.
    pub covariance: Vec<[[f64; 3]; 3]>,
    /// The 1-based line of its file each sample was read from; empty when the record was not
    /// read from a file (simulated, or built in memory).
    pub lines: Vec<usize>,
    /// Per sample of a touch probe's record (one pose, read through its sphere fit), how the
    /// reading responds to each hit's pre-travel ([`PreTravelResponse`]); empty for every other
    /// record.
    pub probe: Vec<Vec<PreTravelResponse>>,
}

/// How a probe pose's reading responds to one hit's pre-travel: what the term `PRE@harmonic:K`
/// of a model is made of.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PreTravelResponse {
    /// The change of the pose's reading (tool frame, mm) per mm of this hit's pre-travel: the
    /// first-order response of its sphere fit.
    pub gain: [f64; 3],
    /// The part of the hit's approach direction across the stylus, `ρ = √(n_x² + n_y²)` of the
    /// approach in the probe's (tool) frame, 0 to 1.
    pub across: f64,
    /// The approach's azimuth about the stylus, `φ = atan2(n_y, n_x)` in the probe's frame, rad.
    pub azimuth_rad: f64,
}

impl PreTravelResponse {
    /// The reading's response (tool frame, mm per mm of amplitude) to the `component` (0:
    /// cos, 1: sin) of a pre-travel `ρ·(a·cos Kφ + b·sin Kφ)` of order `order` (K), summed over
    /// the hits `hits` of one pose.
    pub fn harmonic(hits: &[PreTravelResponse], order: u32, component: usize) -> [f64; 3] {
        let mut v = [0.0; 3];
        for h in hits {
            let angle = f64::from(order) * h.azimuth_rad;
            let w = h.across
                * if component == 0 {
                    angle.cos()
                } else {
                    angle.sin()
                };
            for (x, g) in v.iter_mut().zip(h.gain) {
                *x += w * g;
            }
        }
        v
    }
}

impl PartialEq for Record {
    fn eq(&self, other: &Record) -> bool {
        self.samples == other.samples
            && self.measured == other.measured
            && self.covariance == other.covariance
    }
}

impl Record {
    /// Where sample `i` came from, for messages: `line L` when the record was read from a
    /// file, else `sample i+1` (1-based).
    pub fn place(&self, i: usize) -> String {
        match self.lines.get(i) {
            Some(l) => format!("line {l}"),
            None => format!("sample {}", i + 1),
        }
    }

    /// The record without the samples `drop` (indices, any order): samples, readings,
    /// covariances and lines of the others, in order.
    pub fn without(&self, drop: &[usize]) -> Record {
        let keep = |i: &usize| !drop.contains(i);
        let pick =
            |v: &[[f64; 3]]| -> Vec<[f64; 3]> { (0..v.len()).filter(keep).map(|i| v[i]).collect() };
        Record {
            samples: (0..self.samples.len())
                .filter(keep)
                .map(|i| self.samples[i].clone())
                .collect(),
            measured: pick(&self.measured),
            covariance: (0..self.covariance.len())
                .filter(keep)
                .map(|i| self.covariance[i])
                .collect(),
            lines: (0..self.lines.len())
                .filter(keep)
                .map(|i| self.lines[i])
                .collect(),
            probe: (0..self.probe.len())
                .filter(keep)
                .map(|i| self.probe[i].clone())
                .collect(),
        }
    }

    /// `true` when the first reading is exactly zero and there are others, as R-test software
    /// leaves readings zeroed at the first sample.
    pub fn looks_zeroed(&self) -> bool {
        self.measured.first() == Some(&[0.0; 3]) && self.measured.len() > 1
    }

    /// `true` when every sample has a real time ([`Sample::timed`]).
    pub fn has_times(&self) -> bool {
        self.samples.iter().all(|s| s.timed)
    }

    /// Checks that `term` (its name, for the message) can be evaluated on this record: the
    /// samples have real times.
    ///
    /// # Errors
    /// [`TimesError`] naming the term when the samples are only numbered.
    pub fn check_times(&self, term: &str) -> Result<(), TimesError> {
        if self.has_times() {
            Ok(())
        } else {
            Err(TimesError(format!(
                "term `{term}` needs the real sample times (a `t_s` column, s), but the record has none: its samples are only numbered"
            )))
        }
    }

    /// Checks that `term` (its name, for the message), a warm-up that starts at time 0 of the
    /// record's clock, can be evaluated on this record: no sample before time 0.
    ///
    /// # Errors
    /// [`TimesError`] naming the term and the first sample before time 0 (its line when the
    /// record was read from a file).
    pub fn check_started(&self, term: &str) -> Result<(), TimesError> {
        match self.samples.iter().position(|s| s.t < 0.0) {
            None => Ok(()),
            Some(i) => Err(TimesError(format!(
                "term `{term}` is a warm-up from time 0 of the record's clock (`t_s` = 0, or T = 0 on a campaign clock), but {} is at {} s, before it: a warm-up before its start is not defined; give the times from the start",
                self.place(i),
                model_spec::units::short(self.samples[i].t)
            ))),
        }
    }

    /// The time since the first sample of sample `i`, s.
    pub fn elapsed_s(&self, i: usize) -> f64 {
        self.samples
            .first()
            .map_or(0.0, |a| self.samples[i].t - a.t)
    }

    /// The velocity of every axis at every sample (mm/ms for linear axes, rad/ms for rotary
    /// ones), sample-major (`n_axes` values per sample): central differences of the commands
    /// over the times, one-sided at the ends (see the module documentation).
    ///
    /// # Errors
    /// [`TimesError`] when the samples are numbered, not timed ([`Record::check_times`] with
    /// `term`), when there are fewer than two samples, or when a difference spans no time
    /// (equal times around a sample).
    pub fn velocities(&self, term: &str, n_axes: usize) -> Result<Vec<f64>, TimesError> {
        self.check_times(term)?;
        let s = &self.samples;
        let n = s.len();
        if n < 2 {
            return Err(TimesError(format!(
                "term `{term}` needs axis velocities, which take at least two samples; the record has {n}"
            )));
        }
        let mut v = Vec::with_capacity(n * n_axes);
        for i in 0..n {
            let (a, b) = (i.saturating_sub(1), (i + 1).min(n - 1));
            let dt_ms = (s[b].t - s[a].t) * 1000.0;
            if dt_ms <= 0.0 || !dt_ms.is_finite() {
                return Err(TimesError(format!(
                    "term `{term}` needs axis velocities, but samples {a} and {b} have the same time ({} s): the velocity at sample {i} is undefined",
                    s[a].t
                )));
            }
            for k in 0..n_axes {
                v.push((s[b].commands[k] - s[a].commands[k]) / dt_ms);
            }
        }
        Ok(v)
    }

    /// Normalised time τ ∈ [−1, 1] of sample `i` (0 when the record has no time span).
    pub fn tau(&self, i: usize) -> f64 {
        let (t0, t1) = match (self.samples.first(), self.samples.last()) {
            (Some(a), Some(b)) => (a.t, b.t),
            _ => return 0.0,
        };
        if t1 > t0 {
            2.0 * (self.samples[i].t - t0) / (t1 - t0) - 1.0
        } else {
            0.0
        }
    }
}

/// The samples of commands (per sample, one per axis: mm, rad), real times (s) and directions
/// of motion, zipped (the shortest of the three sets the count).
pub fn samples_from(commands: Vec<Vec<f64>>, times: Vec<f64>, motion: Vec<Vec<i8>>) -> Vec<Sample> {
    commands
        .into_iter()
        .zip(times)
        .zip(motion)
        .map(|((commands, t), motion)| Sample {
            commands,
            t,
            motion,
            timed: true,
        })
        .collect()
}

/// The direction of motion of every axis at every sample of a sequence of commanded poses:
/// the sign of the last non-zero move of the axis up to that sample; +1 before the first move.
pub fn motion_directions(commands: &[Vec<f64>]) -> Vec<Vec<i8>> {
    let n_axes = commands.first().map_or(0, Vec::len);
    let mut current = vec![1i8; n_axes];
    // The direction at sample 0 is that of the first move of each axis, so that a path that
    // starts by moving backwards is read as moving backwards from its first sample.
    for a in 0..n_axes {
        if let Some(w) = commands.windows(2).find(|w| w[1][a] != w[0][a]) {
            current[a] = if w[1][a] > w[0][a] { 1 } else { -1 };
        }
    }
    let mut out = Vec::with_capacity(commands.len());
    for (i, c) in commands.iter().enumerate() {
        if i > 0 {
            for a in 0..n_axes {
                let d = c[a] - commands[i - 1][a];
                if d > 0.0 {
                    current[a] = 1;
                } else if d < 0.0 {
                    current[a] = -1;
                }
            }
        }
        out.push(current.clone());
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn directions_follow_moves_and_hold_at_rest() {
        let c: Vec<Vec<f64>> = [0.0, -1.0, -1.0, 2.0, 2.0]
            .iter()
            .map(|&x| vec![x])
            .collect();
        let d: Vec<i8> = motion_directions(&c).into_iter().map(|v| v[0]).collect();
        assert_eq!(d, vec![-1, -1, -1, 1, 1]);
    }
}
