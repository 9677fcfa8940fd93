//! A sequence of R-test samples along a path: the commanded pose of every axis, the time, the
//! direction of motion of every axis, and (for measured records) the error vector read.

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
}

/// A record: samples and, when measured, the error vector at each (tool minus workpiece, tool
/// frame, mm). Two records are equal when their samples and readings are: the lines they were
/// read from do not count.
#[derive(Clone, Debug, Default)]
pub struct Record {
    /// The samples, in the order they were taken.
    pub samples: Vec<Sample>,
    /// The measured error vector per sample (mm); empty for a bare path.
    pub measured: Vec<[f64; 3]>,
    /// The 1-based line of its file each sample was read from; empty when the record was not
    /// read from a file (simulated, or built in memory).
    pub lines: Vec<usize>,
}

impl PartialEq for Record {
    fn eq(&self, other: &Record) -> bool {
        self.samples == other.samples && self.measured == other.measured
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

    /// The record without the samples `drop` (indices, any order): samples, readings and lines
    /// of the others, in order.
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
            lines: (0..self.lines.len())
                .filter(keep)
                .map(|i| self.lines[i])
                .collect(),
        }
    }

    /// `true` when the first reading is exactly zero and there are others, as R-test software
    /// leaves readings zeroed at the first sample.
    pub fn looks_zeroed(&self) -> bool {
        self.measured.first() == Some(&[0.0; 3]) && self.measured.len() > 1
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

/// The samples of commands (per sample, one per axis: mm, rad), times (s) and directions of
/// motion, zipped (the shortest of the three sets the count).
pub fn samples_from(commands: Vec<Vec<f64>>, times: Vec<f64>, motion: Vec<Vec<i8>>) -> Vec<Sample> {
    commands
        .into_iter()
        .zip(times)
        .zip(motion)
        .map(|((commands, t), motion)| Sample {
            commands,
            t,
            motion,
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
