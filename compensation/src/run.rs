//! Compensation of a list of commanded poses (a path file or an NC program): every pose
//! corrected on the host ([`super::correct`]), the corrected poses checked against the strokes
//! and ranges, and the summary a person reads.
//!
//! The poses are read from a [`PoseSource`] and corrected in batches of [`BATCH`] (shared among
//! the cores), each corrected pose handed to a sink as soon as its batch is done
//! ([`compensate_each`]): a program of millions of poses is corrected without holding its
//! corrected poses, and the summary is gathered as they pass.

use super::correct::{Compensator, Corrected, POSITION_TOLERANCE};
use model_spec::{AxisKind, ErrorId, Machine};
use std::convert::Infallible;

/// A tilt remainder above this (rad) marks a pose whose orientation the rotary axes could not
/// fully correct (near a singular pose, where the correction is damped): 1 µrad.
pub const TILT_REPORTED: f64 = 1e-6;

/// How far past a stroke or range limit a corrected command may fall and be put back on the
/// limit (mm for a linear axis, degrees for a rotary one): a correction of a few thousandths of
/// a degree at B = 0° on an axis whose range starts at 0° is clamped and listed, not refused
/// with the whole program. Further out, the pose is refused ([`RunError::OutOfLimits`]).
pub const CLAMP_MARGIN: f64 = 0.01;

/// Poses corrected at a time, shared among the cores: what is held of the corrected poses
/// while a list is compensated.
pub const BATCH: usize = 16_384;

/// Poses, each shown in the messages by its line: the poses the compensation reads, one at a
/// time.
pub trait PoseSource: Sync {
    /// The number of poses.
    fn count(&self) -> usize;

    /// The 1-based line of the file that holds pose `i`.
    fn line(&self, i: usize) -> usize;

    /// The command of every axis at pose `i` (mm, rad, machine order) into `out`.
    fn commands_into(&self, i: usize, out: &mut [f64]);
}

impl PoseSource for &[CommandedPose] {
    fn count(&self) -> usize {
        self.len()
    }

    fn line(&self, i: usize) -> usize {
        self[i].line
    }

    fn commands_into(&self, i: usize, out: &mut [f64]) {
        out.copy_from_slice(&self[i].commands);
    }
}

/// One commanded pose and where it came from.
#[derive(Clone, Debug, PartialEq)]
pub struct CommandedPose {
    /// The 1-based line of the input file.
    pub line: usize,
    /// The command of every axis (mm, rad), machine order.
    pub commands: Vec<f64>,
}

/// What one axis's corrections came to over the file.
#[derive(Clone, Debug, PartialEq)]
pub struct AxisCorrections {
    /// The axis.
    pub axis: String,
    /// `true` for a rotary axis (values in rad), `false` for a linear one (mm).
    pub rotary: bool,
    /// The largest correction, by magnitude, with its sign (mm or rad).
    pub largest: f64,
    /// The line of the pose with the largest correction.
    pub largest_line: usize,
    /// The RMS of the corrections (mm or rad).
    pub rms: f64,
}

/// A corrected command put back on the limit it passed by at most [`CLAMP_MARGIN`].
#[derive(Clone, Debug, PartialEq)]
pub struct Clamped {
    /// The 1-based line of the pose.
    pub line: usize,
    /// The axis.
    pub axis: String,
    /// `true` for a rotary axis (degrees), `false` for a linear one (mm).
    pub rotary: bool,
    /// The corrected command before it was clamped (mm or degrees).
    pub corrected: f64,
    /// The limit it was put on (mm or degrees).
    pub limit: f64,
}

/// Puts every axis of `commands` (mm, rad) that is outside its stroke or range by at most
/// [`CLAMP_MARGIN`] on that limit, and lists them; changes nothing and gives `None` when an
/// axis is further outside (the pose is then refused).
fn clamp(m: &Machine, line: usize, commands: &mut [f64]) -> Option<Vec<Clamped>> {
    let outside = m.outside_limits(commands);
    let beyond = |o: &model_spec::pose::OutsideLimits| {
        let [lo, hi] = o.limits;
        o.value < lo - CLAMP_MARGIN || o.value > hi + CLAMP_MARGIN
    };
    if outside.iter().any(beyond) {
        return None;
    }
    Some(
        outside
            .into_iter()
            .map(|o| {
                let [lo, hi] = o.limits;
                let limit = if o.value < lo { lo } else { hi };
                let rotary = o.kind == AxisKind::Rotary;
                commands[o.axis] = if rotary { limit.to_radians() } else { limit };
                Clamped {
                    line,
                    axis: o.name,
                    rotary,
                    corrected: o.value,
                    limit,
                }
            })
            .collect(),
    )
}

/// The summary of a compensated file.
#[derive(Clone, Debug, PartialEq)]
pub struct Summary {
    /// The number of poses.
    pub poses: usize,
    /// Per axis, machine order.
    pub axes: Vec<AxisCorrections>,
    /// The largest predicted position remainder after correction (mm): below 1 nm.
    pub position_remainder: f64,
    /// The largest predicted tilt of the tool axis that remains (rad).
    pub tilt_remainder: f64,
    /// The lines whose tilt remainder exceeds [`TILT_REPORTED`] (near a singular pose).
    pub tilt_uncorrected: Vec<usize>,
    /// The largest predicted rotation about the tool axis (rad): no axis removes it.
    pub roll_largest: f64,
    /// Its RMS over the poses (rad).
    pub roll_rms: f64,
    /// `true` when the machine has rotary axes that correct the orientation.
    pub orientation_corrected: bool,
    /// The poses that needed refinement steps after the fixed ones.
    pub refined: usize,
    /// The corrected commands put back on a limit they passed by at most [`CLAMP_MARGIN`].
    pub clamped: Vec<Clamped>,
}

/// Why a file cannot be compensated.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum RunError {
    /// Corrected poses leave a stroke or a range.
    #[error("{file}: {count} corrected pose(s) leave a stroke or range: {}", list(.lines, *.count))]
    OutOfLimits {
        /// The input file.
        file: String,
        /// `(line, what)` of the first [`LISTED`] poses outside.
        lines: Vec<(usize, String)>,
        /// The number of poses outside.
        count: usize,
    },
    /// The corrected pose did not converge.
    #[error(
        "{file}:{line}: the corrected pose does not reach the model's prediction (remainder {remainder_um:.3e} µm after the refinement steps)"
    )]
    NotConverged {
        /// The input file.
        file: String,
        /// The line.
        line: usize,
        /// The remainder, µm.
        remainder_um: f64,
    },
    /// Commanded poses already outside a stroke or range (or not finite).
    #[error("{file}: {count} commanded pose(s) are outside a stroke or range: {}", list(.lines, *.count))]
    CommandedOutside {
        /// The input file.
        file: String,
        /// `(line, what)` of the first [`LISTED`] poses outside.
        lines: Vec<(usize, String)>,
        /// The number of poses outside.
        count: usize,
    },
    /// The machine's topology is outside what the corrected-pose solver handles.
    #[error(transparent)]
    Topology(#[from] codegen::compensation::CompensationError),
    /// The input holds no pose.
    #[error("{file}: no commanded pose to compensate")]
    Empty {
        /// The input file.
        file: String,
    },
}

/// The poses outside a stroke or range a [`RunError`] lists (the others are counted).
pub const LISTED: usize = 10;

/// The listed poses, and how many more there are.
fn list(lines: &[(usize, String)], count: usize) -> String {
    let shown: Vec<String> = lines
        .iter()
        .take(LISTED)
        .map(|(l, w)| format!("line {l}: {w}"))
        .collect();
    let more = count.saturating_sub(shown.len());
    if more > 0 {
        format!("{}; and {more} more", shown.join("; "))
    } else {
        shown.join("; ")
    }
}

/// The poses outside a stroke or range: the first [`LISTED`], and their number.
#[derive(Default)]
struct Outside {
    lines: Vec<(usize, String)>,
    count: usize,
}

impl Outside {
    /// Notes pose `q` of line `line` if it is outside.
    fn check(&mut self, m: &Machine, line: usize, q: &[f64]) {
        if let Err(e) = m.check_pose(q) {
            if self.lines.len() < LISTED {
                self.lines.push((line, e.to_string()));
            }
            self.count += 1;
        }
    }
}

/// The corrected poses of a file, and its summary.
#[derive(Clone, Debug, PartialEq)]
pub struct Compensated {
    /// The corrected commands, one per input pose (mm, rad).
    pub poses: Vec<Vec<f64>>,
    /// The summary.
    pub summary: Summary,
}

/// Why [`compensate_each`] stopped: the compensation, or the sink.
#[derive(Debug)]
pub enum Stopped<E> {
    /// The compensation failed.
    Run(RunError),
    /// The sink refused a corrected pose.
    Sink(E),
}

/// Compensates every pose of `poses` (from the file `file`) with the model errors `errors`
/// (catalogue ids of `m`), kinematic parameters `params` (mm) and their values at any pose
/// (`values_at(commands, out)`, mm and rad, one per error), and collects the corrected poses:
/// [`compensate_each`] with a sink that keeps them.
///
/// # Errors
/// As [`compensate_each`].
pub fn compensate_poses(
    m: &Machine,
    errors: &[ErrorId],
    params: Vec<f64>,
    file: &str,
    poses: &[CommandedPose],
    values_at: &(dyn Fn(&[f64], &mut [f64]) + Sync),
) -> Result<Compensated, RunError> {
    let mut corrected = Vec::with_capacity(poses.len());
    let keep = |_: usize, q: &[f64]| -> Result<(), Infallible> {
        corrected.push(q.to_vec());
        Ok(())
    };
    let summary =
        compensate_each(m, errors, params, file, &poses, values_at, keep).map_err(|e| match e {
            Stopped::Run(e) => e,
            Stopped::Sink(never) => match never {},
        })?;
    Ok(Compensated {
        poses: corrected,
        summary,
    })
}

/// Compensates every pose of `poses` (from the file `file`) with the model errors `errors`
/// (catalogue ids of `m`), kinematic parameters `params` (mm) and their values at any pose
/// (`values_at(commands, out)`, mm and rad, one per error), handing each corrected pose to
/// `sink(i, commands)` (mm, rad), in the order of the poses, and gives the summary.
///
/// The commanded poses are checked against the strokes and ranges first; then they are
/// corrected [`BATCH`] at a time, each batch shared among the available cores (the result does
/// not depend on the split), and checked: a corrected command past a limit by at most
/// [`CLAMP_MARGIN`] is put on the limit and listed in the summary ([`Summary::clamped`]). Once a corrected pose is outside, the sink gets no
/// more poses (the others are still corrected, to list every pose outside).
///
/// # Errors
/// [`Stopped::Run`] with [`RunError::Empty`] without poses, [`RunError::CommandedOutside`]
/// listing the commanded poses outside a stroke or range, [`RunError::NotConverged`] for the
/// first pose that does not converge, [`RunError::OutOfLimits`] listing the corrected poses
/// outside; [`Stopped::Sink`] with the sink's first error.
pub fn compensate_each<E>(
    m: &Machine,
    errors: &[ErrorId],
    params: Vec<f64>,
    file: &str,
    poses: &dyn PoseSource,
    values_at: &(dyn Fn(&[f64], &mut [f64]) + Sync),
    mut sink: impl FnMut(usize, &[f64]) -> Result<(), E>,
) -> Result<Summary, Stopped<E>> {
    let run = |e: RunError| Stopped::Run(e);
    let n = poses.count();
    if n == 0 {
        return Err(run(RunError::Empty {
            file: file.to_string(),
        }));
    }
    let mut q = vec![0.0; m.axes.len()];
    let mut commanded_outside = Outside::default();
    for i in 0..n {
        poses.commands_into(i, &mut q);
        commanded_outside.check(m, poses.line(i), &q);
    }
    if commanded_outside.count > 0 {
        return Err(run(RunError::CommandedOutside {
            file: file.to_string(),
            lines: commanded_outside.lines,
            count: commanded_outside.count,
        }));
    }
    let comp = Compensator::new(m, errors, params).map_err(|e| run(e.into()))?;
    // Poses are independent: each batch is split over the cores, each with its own buffers.
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .clamp(1, 16)
        .min(n.div_ceil(256));
    let mut comps = vec![comp; threads];
    let mut summary = Gathered::new(m, poses.line(0));
    let mut corrected_outside = Outside::default();
    for start in (0..n).step_by(BATCH) {
        let batch = start..(start + BATCH).min(n);
        for (i, c) in (batch.start..).zip(correct_batch(
            &mut comps,
            m.axes.len(),
            poses,
            batch,
            file,
            values_at,
        )) {
            let mut c = c.map_err(run)?;
            let line = poses.line(i);
            if let Some(clamped) = clamp(m, line, &mut c.commands) {
                summary.clamped.extend(clamped);
            }
            corrected_outside.check(m, line, &c.commands);
            poses.commands_into(i, &mut q);
            summary.add(line, &q, &c);
            if corrected_outside.count == 0 {
                sink(i, &c.commands).map_err(Stopped::Sink)?;
            }
        }
    }
    if corrected_outside.count > 0 {
        return Err(run(RunError::OutOfLimits {
            file: file.to_string(),
            lines: corrected_outside.lines,
            count: corrected_outside.count,
        }));
    }
    Ok(summary.finish(m))
}

/// The corrected poses of `batch`, in order, the batch split into one part per compensator
/// (each run on a core of its own); a part stops at its first pose that does not converge.
fn correct_batch(
    comps: &mut [Compensator],
    axes: usize,
    poses: &dyn PoseSource,
    batch: std::ops::Range<usize>,
    file: &str,
    values_at: &(dyn Fn(&[f64], &mut [f64]) + Sync),
) -> Vec<Result<Corrected, RunError>> {
    let part = batch.len().div_ceil(comps.len());
    let correct = |comp: &mut Compensator, range: std::ops::Range<usize>| {
        let mut q = vec![0.0; axes];
        let mut values_at = |q: &[f64], out: &mut [f64]| values_at(q, out);
        let mut done = Vec::with_capacity(range.len());
        for i in range {
            poses.commands_into(i, &mut q);
            let c = comp
                .correct(&q, &mut values_at)
                .map_err(|r| RunError::NotConverged {
                    file: file.to_string(),
                    line: poses.line(i),
                    remainder_um: r * 1e3,
                });
            let failed = c.is_err();
            done.push(c);
            if failed {
                break;
            }
        }
        done
    };
    let ranges = (0..comps.len()).map(|k| {
        (batch.start + k * part).min(batch.end)..(batch.start + (k + 1) * part).min(batch.end)
    });
    if comps.len() == 1 {
        return correct(&mut comps[0], batch);
    }
    let parts: Vec<Vec<Result<Corrected, RunError>>> = std::thread::scope(|scope| {
        let handles: Vec<_> = comps
            .iter_mut()
            .zip(ranges)
            .map(|(comp, range)| scope.spawn(move || correct(comp, range)))
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().expect("a correction thread does not panic"))
            .collect()
    });
    parts.into_iter().flatten().collect()
}
/// The length of `v`.
fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// The summary, gathered pose after pose.
struct Gathered {
    poses: usize,
    /// Per axis: the largest correction (with its sign), its line, the sum of the squares.
    axes: Vec<(f64, usize, f64)>,
    position: f64,
    tilt: f64,
    tilt_uncorrected: Vec<usize>,
    roll_largest: f64,
    roll_squares: f64,
    refined: usize,
    orientation_corrected: bool,
    clamped: Vec<Clamped>,
}

impl Gathered {
    /// Nothing gathered yet; `first_line` is the line of the first pose.
    fn new(m: &Machine, first_line: usize) -> Gathered {
        Gathered {
            poses: 0,
            axes: vec![(0.0, first_line, 0.0); m.axes.len()],
            position: 0.0,
            tilt: 0.0,
            tilt_uncorrected: Vec::new(),
            roll_largest: 0.0,
            roll_squares: 0.0,
            refined: 0,
            orientation_corrected: m.rotary_axes().count() > 0,
            clamped: Vec::new(),
        }
    }

    /// Adds the pose of `line`, commanded `commanded` and corrected `c`.
    fn add(&mut self, line: usize, commanded: &[f64], c: &Corrected) {
        self.poses += 1;
        for ((largest, largest_line, sum2), (q, p)) in
            self.axes.iter_mut().zip(c.commands.iter().zip(commanded))
        {
            let d = q - p;
            *sum2 += d * d;
            if d.abs() > largest.abs() {
                (*largest, *largest_line) = (d, line);
            }
        }
        self.position = self.position.max(norm(&c.position));
        let tilt = norm(&c.tilt);
        self.tilt = self.tilt.max(tilt);
        if self.orientation_corrected && tilt > TILT_REPORTED {
            self.tilt_uncorrected.push(line);
        }
        self.roll_largest = self.roll_largest.max(c.roll.abs());
        self.roll_squares += c.roll * c.roll;
        self.refined += usize::from(c.refinements > 0);
    }

    fn finish(self, m: &Machine) -> Summary {
        let n = self.poses as f64;
        Summary {
            poses: self.poses,
            axes: m
                .axes
                .iter()
                .zip(self.axes)
                .map(|(axis, (largest, largest_line, sum2))| AxisCorrections {
                    axis: axis.name.clone(),
                    rotary: axis.kind == AxisKind::Rotary,
                    largest,
                    largest_line,
                    rms: (sum2 / n).sqrt(),
                })
                .collect(),
            position_remainder: self.position,
            tilt_remainder: self.tilt,
            tilt_uncorrected: self.tilt_uncorrected,
            roll_largest: self.roll_largest,
            roll_rms: (self.roll_squares / n).sqrt(),
            orientation_corrected: self.orientation_corrected,
            refined: self.refined,
            clamped: self.clamped,
        }
    }
}

/// `true` when every remainder is within the tolerance (for tests and reports).
pub fn converged(s: &Summary) -> bool {
    s.position_remainder < POSITION_TOLERANCE
}
