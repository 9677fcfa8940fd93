//! What well-formed samples must still satisfy to be an R-test record of the machine, checked
//! on a batch of samples (the whole file, or one block of a long one):
//!
//! 1. when the file gives the linear axes, every pose puts the nominal tool point on the nominal
//!    workpiece point (the sensor nest on the ball) within
//!    [`ReadOptions::on_ball_tolerance_mm`], at the machine's default kinematic parameters;
//! 2. unless [`ReadOptions::allow_off_stroke`], every pose (linear axes filled) lies within the
//!    machine's strokes (mm) and ranges (degrees), inclusive, with a rounding margin of
//!    [`model_spec::pose::LIMIT_TOLERANCE`] in the axis unit;
//! 3. every reading lies within [`ReadOptions::max_reading_mm`] in each direction.
//!
//! The first check that fails refuses the batch with [`CsvError::Refused`]: how many samples or
//! readings offend, and the first [`LISTED`] of them by line.

use crate::csv::{CsvError, MEASURED, ReadOptions};
use model_spec::units::{compact, plural, significant};
use model_spec::{Machine, parallel};
use simulation::exact::VirtualMachine;

/// How many offending samples a refusal lists.
pub const LISTED: usize = 5;

/// What an R-test record is, said when the nest is off the ball.
const R_TEST_RECORD: &str = "; in an R-test record the linear axes follow the ball (the sensor nest stays on the ball) and the readings are the small error vector in µm; leave the linear columns out to have them filled by the nominal inverse kinematics";

/// The checks of one reader: the machine, what the file gives.
pub(crate) struct SampleChecks<'m> {
    m: &'m Machine,
    /// Present when the file gives the linear axes (the nest must be on the ball): the nominal
    /// machine ([`nominal_machine`]) and the default kinematic parameters (mm).
    on_ball: Option<(Machine, Vec<f64>)>,
    /// The linear axes are filled by the inverse kinematics (said in the stroke message).
    filled: bool,
    opts: ReadOptions,
}

impl<'m> SampleChecks<'m> {
    /// The checks of a file of machine `m` whose linear axes are given (`linear_given`) or
    /// filled by the inverse kinematics.
    pub(crate) fn new(m: &'m Machine, linear_given: bool, opts: &ReadOptions) -> Self {
        let has_linear = m.linear_axes().next().is_some();
        SampleChecks {
            m,
            on_ball: (linear_given && has_linear)
                .then(|| (nominal_machine(m), m.default_parameters())),
            filled: has_linear && !linear_given,
            opts: opts.clone(),
        }
    }

    /// Checks the samples `commands` (mm, rad) read at `lines`, with their readings `measured`
    /// (mm; `None` in a path file without them). `file` names the file in messages.
    pub(crate) fn check(
        &self,
        file: &str,
        commands: &[Vec<f64>],
        measured: Option<&[[f64; 3]]>,
        lines: &[usize],
    ) -> Result<(), CsvError> {
        self.nest_on_ball(file, commands, lines)?;
        if !self.opts.allow_off_stroke {
            self.within_limits(file, commands, lines)?;
        }
        if let Some(measured) = measured {
            self.plausible(file, measured, lines)?;
        }
        Ok(())
    }

    fn nest_on_ball(
        &self,
        file: &str,
        commands: &[Vec<f64>],
        lines: &[usize],
    ) -> Result<(), CsvError> {
        let Some((nominal, params)) = &self.on_ball else {
            return Ok(());
        };
        let vm = VirtualMachine::new(nominal);
        let tol = self.opts.on_ball_tolerance_mm;
        let mut off = Offenders::default();
        let distances = off_ball_distances(&vm, commands, params);
        for (&d, &line) in distances.iter().zip(lines) {
            if !at_most(d, tol) {
                off.add(line, || {
                    if d.is_finite() {
                        format!("line {line}: {} mm", compact(d))
                    } else {
                        format!("line {line}: beyond any number (the commands overflow)")
                    }
                });
            }
        }
        let what = |n| {
            format!(
                "{n} pose{} put the nominal tool point off the nominal workpiece point by more than {} mm (machine {}, default kinematic parameters)",
                plural(n, "s"),
                compact(tol),
                self.m.name
            )
        };
        off.refuse(file, ", ", what, R_TEST_RECORD)
    }

    fn within_limits(
        &self,
        file: &str,
        commands: &[Vec<f64>],
        lines: &[usize],
    ) -> Result<(), CsvError> {
        let mut off = Offenders::default();
        for (c, &line) in commands.iter().zip(lines) {
            if let Err(why) = check_pose(self.m, c) {
                off.add(line, || format!("line {line}: {why}"));
            }
        }
        let filled = if self.filled {
            " (the linear axes filled by the nominal inverse kinematics)"
        } else {
            ""
        };
        off.refuse(
            file,
            "; ",
            |n| {
                format!(
                    "{n} pose{} outside the strokes and ranges of machine {}{filled}",
                    plural(n, "s"),
                    self.m.name
                )
            },
            "",
        )
    }

    fn plausible(
        &self,
        file: &str,
        measured: &[[f64; 3]],
        lines: &[usize],
    ) -> Result<(), CsvError> {
        let bound = self.opts.max_reading_mm;
        let mut off = Offenders::default();
        for (v, &line) in measured.iter().zip(lines) {
            for (k, &x) in v.iter().enumerate() {
                if !at_most(x.abs(), bound) {
                    off.add(line, || {
                        format!("line {line} {} = {}", MEASURED[k], significant(x * 1e3))
                    });
                }
            }
        }
        off.refuse(
            file,
            ", ",
            |n| {
                format!(
                    "{n} reading{} beyond the plausibility bound of {} µm",
                    plural(n, "s"),
                    significant(bound * 1e3)
                )
            },
            "",
        )
    }
}

/// `m` without its errors: its chains lowered without error steps (they are identities when
/// every error is zero), so that [`VirtualMachine::nominal_error_vector`] of it gives that of
/// `m` with a few matrix products per chain instead of dozens.
fn nominal_machine(m: &Machine) -> Machine {
    let mut nominal = m.clone();
    nominal.catalogue.clear();
    nominal.errors.clear();
    nominal.models.clear();
    nominal
}

/// Whether `commands` (mm, rad; one per axis) lies within the strokes (mm) and ranges
/// (degrees) of `m` ([`Machine::outside_limits`]); otherwise what lies outside, several axes
/// joined by `, `.
fn check_pose(m: &Machine, commands: &[f64]) -> Result<(), String> {
    let out: Vec<String> = m
        .outside_limits(commands)
        .iter()
        .map(ToString::to_string)
        .collect();
    if out.is_empty() {
        Ok(())
    } else {
        Err(out.join(", "))
    }
}

/// Offending samples (or readings): how many, the descriptions of the first [`LISTED`] and
/// their lines (each once).
#[derive(Default)]
struct Offenders {
    count: usize,
    lines: Vec<usize>,
    listed: Vec<String>,
}

impl Offenders {
    fn add(&mut self, line: usize, describe: impl FnOnce() -> String) {
        self.count += 1;
        if self.listed.len() < LISTED {
            self.listed.push(describe());
            if self.lines.last() != Some(&line) {
                self.lines.push(line);
            }
        }
    }

    /// `Ok` when nothing offends, else the refusal: `what(count)`, the listed offenders joined
    /// by `sep` (`…` when there are more), then `tail`.
    fn refuse(
        self,
        file: &str,
        sep: &str,
        what: impl FnOnce(usize) -> String,
        tail: &str,
    ) -> Result<(), CsvError> {
        if self.count == 0 {
            return Ok(());
        }
        let more = if self.count > self.listed.len() {
            format!("{sep}…")
        } else {
            String::new()
        };
        Err(CsvError::Refused {
            file: file.to_string(),
            count: self.count,
            message: format!(
                "{}: {}{more}{tail}",
                what(self.count),
                self.listed.join(sep)
            ),
            lines: self.lines,
        })
    }
}

/// `x <= bound`; `false` when either is NaN (a NaN offends).
fn at_most(x: f64, bound: f64) -> bool {
    x <= bound
}

/// Samples per thread at least when the distances of [`off_ball_distances`] are shared out.
const SAMPLES_PER_THREAD: usize = 50_000;

/// Per sample, the distance (mm) between the nominal tool point and the nominal workpiece point
/// at its commands, a long record's shared out over the cores ([`parallel::map_parts`]: each
/// sample's on its own, the same numbers however cut).
fn off_ball_distances(vm: &VirtualMachine, commands: &[Vec<f64>], params: &[f64]) -> Vec<f64> {
    let distance = |c: &Vec<f64>| vm.nominal_error_vector(c, params).position.norm();
    let threads = parallel::threads_for(commands.len(), SAMPLES_PER_THREAD);
    let part = commands.len().div_ceil(threads).max(1);
    parallel::map_parts(commands.chunks(part).collect(), |chunk| {
        chunk.iter().map(distance).collect::<Vec<f64>>()
    })
    .concat()
}

#[cfg(test)]
mod tests {
    use super::*;
    use model_spec::AxisKind;
    use simulation::rng::Rng;

    #[test]
    fn the_nominal_machine_has_the_nominal_error_vector_of_the_machine() {
        for name in ["seed-ac", "seed-3axis", "head-table-bc"] {
            let m = model_spec::builtin(name).unwrap().unwrap();
            let nominal = nominal_machine(&m);
            let (full, bare) = (VirtualMachine::new(&m), VirtualMachine::new(&nominal));
            assert!(
                bare.steps(model_spec::Side::Work).len() < full.steps(model_spec::Side::Work).len()
            );
            let mut rng = Rng::new(7);
            let mut params = m.default_parameters();
            for _ in 0..200 {
                params.iter_mut().for_each(|p| *p += 10.0 * rng.normal());
                let q: Vec<f64> = m
                    .axes
                    .iter()
                    .map(|a| match a.kind {
                        AxisKind::Linear => 300.0 * rng.normal(),
                        AxisKind::Rotary => 3.0 * rng.normal(),
                    })
                    .collect();
                assert_eq!(
                    bare.nominal_error_vector(&q, &params),
                    full.nominal_error_vector(&q, &params),
                    "{name} at {q:?}"
                );
            }
        }
    }

    /// The distances of a record long enough for several threads are those of one sample
    /// after another, in order.
    #[test]
    fn off_ball_distances_on_several_threads_are_those_of_one() {
        let m = model_spec::builtin("seed-ac").unwrap().unwrap();
        let vm = VirtualMachine::new(&m);
        let params = m.default_parameters();
        let mut rng = Rng::new(3);
        let commands: Vec<Vec<f64>> = (0..2 * SAMPLES_PER_THREAD + 17)
            .map(|_| {
                m.axes
                    .iter()
                    .map(|a| match a.kind {
                        AxisKind::Linear => 300.0 * rng.normal(),
                        AxisKind::Rotary => 3.0 * rng.normal(),
                    })
                    .collect()
            })
            .collect();
        let one: Vec<f64> = commands
            .iter()
            .map(|c| vm.nominal_error_vector(c, &params).position.norm())
            .collect();
        assert_eq!(off_ball_distances(&vm, &commands, &params), one);
    }
}
