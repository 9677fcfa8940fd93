//! The corrected pose of one commanded pose, on the host: the generated compensation programs
//! evaluated in process ([`codegen::Program::eval`]), step for step what the generated
//! `compensate` function does, then checked and, where needed, refined.

use codegen::atoms::AtomTable;
use codegen::compensation::{
    CompensationError, CompensationPrograms, RESIDUALS, STEPS, compile_compensation,
};
use model_spec::{ErrorId, Machine};

/// The predicted remainder a corrected pose must reach (mm): 1 nm.
pub const POSITION_TOLERANCE: f64 = 1e-6;

/// The most refinement steps after the [`STEPS`] fixed ones.
pub const MAX_REFINEMENT_STEPS: usize = 20;

/// A corrected pose.
#[derive(Clone, Debug, PartialEq)]
pub struct Corrected {
    /// The corrected command of every axis (mm, rad), machine order.
    pub commands: Vec<f64>,
    /// The predicted remainder at the corrected pose, tool frame: position (mm).
    pub position: [f64; 3],
    /// The predicted tilt of the tool axis that remains (rad, about x and y of the tool frame).
    pub tilt: [f64; 2],
    /// The predicted rotation about the tool axis (rad): no axis removes it.
    pub roll: f64,
    /// Refinement steps the host took after the fixed ones (0 where the fixed steps were
    /// enough).
    pub refinements: usize,
}

/// The host side of the generated compensation of one model.
#[derive(Clone, Debug)]
pub struct Compensator {
    programs: CompensationPrograms,
    atoms: AtomTable,
    /// The programs' inputs, in their order: pose atoms, kinematic parameters (filled once),
    /// error values, target. Each program reads the prefix it takes.
    inputs: Vec<f64>,
    scratch: Vec<f64>,
    out: Vec<f64>,
}

impl Compensator {
    /// Compiles the compensation of the errors `errors` (catalogue order of `m` as the model
    /// lists them) with the kinematic parameters `params` (mm, one per symbol of `m`).
    ///
    /// # Errors
    /// When the topology is outside what the solver handles.
    pub fn new(
        m: &Machine,
        errors: &[ErrorId],
        params: Vec<f64>,
    ) -> Result<Compensator, CompensationError> {
        let programs = compile_compensation(m, errors)?;
        let mut inputs = vec![0.0; programs.pose_inputs];
        inputs.extend_from_slice(&params);
        inputs.resize(inputs.len() + errors.len() + 6, 0.0);
        Ok(Compensator {
            atoms: AtomTable::new(m),
            inputs,
            programs,
            scratch: Vec::new(),
            out: Vec::new(),
        })
    }

    /// Loads a pose into the input buffer (the sines and cosines of the rotary commands by
    /// `f64::sin` and `f64::cos`, as `f64::sin_cos`, the generated code's caller on the host,
    /// computes them), and the error values and target where given; returns the length of the
    /// prefix that holds them.
    fn load(
        &mut self,
        commands: &[f64],
        values: Option<&[f64]>,
        target: Option<&[f64; 6]>,
    ) -> usize {
        self.atoms.fill_pose(commands, &mut self.inputs);
        let mut end = self.programs.pose_inputs + self.programs.params;
        if let Some(v) = values {
            self.inputs[end..end + v.len()].copy_from_slice(v);
            end += v.len();
        }
        if let Some(t) = target {
            self.inputs[end..end + 6].copy_from_slice(t);
            end += 6;
        }
        end
    }

    /// The target of a commanded pose: the tool point and the tool axis in the work frame.
    pub fn target(&mut self, commanded: &[f64]) -> [f64; 6] {
        let end = self.load(commanded, None, None);
        let mut t = [0.0; 6];
        self.programs
            .target
            .eval(&self.inputs[..end], &mut self.scratch, &mut t);
        t
    }

    /// One step from `at` towards `target` with the error values `values` (mm, rad, model
    /// order): returns the change of every axis (mm, rad) and fills `residual` with the
    /// residual at `at`.
    fn step(
        &mut self,
        at: &[f64],
        values: &[f64],
        target: &[f64; 6],
        residual: &mut [f64; RESIDUALS],
        rotary_held: bool,
    ) -> &[f64] {
        let end = self.load(at, Some(values), Some(target));
        let n = self.programs.axis_count();
        self.out.resize(n + RESIDUALS, 0.0);
        let program = if rotary_held {
            &self.programs.position_step
        } else {
            &self.programs.step
        };
        program.eval(&self.inputs[..end], &mut self.scratch, &mut self.out);
        residual.copy_from_slice(&self.out[n..]);
        &self.out[..n]
    }

    /// The [`STEPS`] fixed steps of the generated `compensate` function, from the commanded
    /// pose with the values at the commanded pose: bit for bit what the generated function
    /// returns when its caller's sine and cosine are `f64::sin_cos`.
    pub fn fixed_steps(&mut self, commanded: &[f64], values: &[f64]) -> Vec<f64> {
        let target = self.target(commanded);
        self.steps_towards(commanded, values, &target)
    }

    /// The fixed steps from `commanded` towards `target` (the commanded pose's own).
    fn steps_towards(&mut self, commanded: &[f64], values: &[f64], target: &[f64; 6]) -> Vec<f64> {
        let mut q = commanded.to_vec();
        let mut residual = [0.0; RESIDUALS];
        for _ in 0..STEPS {
            let change = self.step(&q, values, target, &mut residual, false);
            for (qi, d) in q.iter_mut().zip(change) {
                *qi += d;
            }
        }
        q
    }

    /// The corrected pose of `commanded` (mm, rad): the fixed steps with the values at the
    /// commanded pose, then steps of the linear axes alone (the rotary axes held where the fixed
    /// steps put them) with the values at the corrected pose (`values_at(commands, out)` fills
    /// one value per model error) until the predicted position remainder is below
    /// [`POSITION_TOLERANCE`].
    ///
    /// # Errors
    /// The remainder after [`MAX_REFINEMENT_STEPS`] more steps, when it is still above the
    /// tolerance.
    pub fn correct(
        &mut self,
        commanded: &[f64],
        values_at: &mut dyn FnMut(&[f64], &mut [f64]),
    ) -> Result<Corrected, f64> {
        let mut values = vec![0.0; self.programs.errors.len()];
        values_at(commanded, &mut values);
        let target = self.target(commanded);
        let mut q = self.steps_towards(commanded, &values, &target);
        let mut residual = [0.0; RESIDUALS];
        let mut refinements = 0;
        loop {
            values_at(&q, &mut values);
            let change = self.step(&q, &values, &target, &mut residual, true);
            let remainder = residual[..3].iter().map(|r| r * r).sum::<f64>().sqrt();
            if remainder < POSITION_TOLERANCE {
                break;
            }
            if refinements == MAX_REFINEMENT_STEPS {
                return Err(remainder);
            }
            for (qi, d) in q.iter_mut().zip(change) {
                *qi += d;
            }
            refinements += 1;
        }
        Ok(Corrected {
            commands: q,
            position: [residual[0], residual[1], residual[2]],
            tilt: [residual[3], residual[4]],
            roll: residual[5],
            refinements,
        })
    }

    /// The first-order correction of `commanded` alone (the generated `f32` function's
    /// computation, in `f64`): the change of every axis (mm, rad).
    pub fn first_order(&mut self, commanded: &[f64], values: &[f64]) -> Vec<f64> {
        let end = self.load(commanded, Some(values), None);
        let n = self.programs.axis_count();
        let mut out = vec![0.0; n + RESIDUALS];
        self.programs
            .first_step
            .eval(&self.inputs[..end], &mut self.scratch, &mut out);
        out.truncate(n);
        out
    }
}
