//! The flat straight-line IR: one instruction list that both the in-process evaluator
//! ([`Program::eval`]) and the Rust emitter ([`crate::emit`]) walk.
//!
//! Every instruction defines one value (static single assignment); operands refer to earlier
//! instructions, so the list is already in evaluation order. Bodies are `+`, `−` and `×` only:
//! sines and cosines of rotary commands are inputs.

use std::fmt;

/// Index of a value (the instruction that defines it).
pub type Var = u32;

/// One instruction.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Op {
    /// The input at this index of [`Program::inputs`].
    Input(u32),
    /// A constant (stored as its bit pattern so that the op is hashable; read with
    /// [`f64::from_bits`]).
    Const(u64),
    /// `a + b`.
    Add(Var, Var),
    /// `a − b`.
    Sub(Var, Var),
    /// `a × b`.
    Mul(Var, Var),
    /// `−a`.
    Neg(Var),
    /// `a / b` (only in compensation programs; gain programs are `+ − ×` only).
    Div(Var, Var),
}

/// An output slot: a value or a constant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Output {
    /// A computed value.
    Var(Var),
    /// The negation of a computed value (counted as a negation).
    Neg(Var),
    /// A constant, often `0.0`.
    Const(f64),
}

/// What an input is.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Input {
    /// Its name in formulas (`Sa`, `Xm`, `Xw`).
    pub name: String,
    /// Its field name in generated code (`sin_a`, `x`, `Xw`).
    pub field: String,
    /// `true` for kinematic parameters, `false` for pose inputs.
    pub parameter: bool,
}

/// A straight-line program: inputs, instructions, outputs.
#[derive(Clone, Debug, PartialEq)]
pub struct Program {
    /// Inputs, in order.
    pub inputs: Vec<Input>,
    /// Instructions, in evaluation order.
    pub ops: Vec<Op>,
    /// Outputs, row-major: six per error (`gx gy gz gi gj gk`).
    pub outputs: Vec<Output>,
}

/// Operation counts of a program (inputs and constants are free).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OpCounts {
    /// Additions and subtractions.
    pub add: usize,
    /// Multiplications.
    pub mul: usize,
    /// Negations.
    pub neg: usize,
    /// Divisions (compensation programs only).
    pub div: usize,
}

impl OpCounts {
    /// All arithmetic operations.
    pub fn total(&self) -> usize {
        self.add + self.mul + self.neg + self.div
    }
}

impl fmt::Display for OpCounts {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} operations: {} add/sub, {} mul, {} neg",
            self.total(),
            self.add,
            self.mul,
            self.neg
        )?;
        if self.div > 0 {
            write!(f, ", {} div", self.div)?;
        }
        Ok(())
    }
}

impl Program {
    /// Counts the arithmetic operations.
    pub fn op_counts(&self) -> OpCounts {
        let mut c = OpCounts::default();
        for op in &self.ops {
            match op {
                Op::Add(..) | Op::Sub(..) => c.add += 1,
                Op::Mul(..) => c.mul += 1,
                Op::Neg(..) => c.neg += 1,
                Op::Div(..) => c.div += 1,
                Op::Input(_) | Op::Const(_) => {}
            }
        }
        c.neg += self
            .outputs
            .iter()
            .filter(|o| matches!(o, Output::Neg(_)))
            .count();
        c
    }

    /// Evaluates the program: `inputs` in [`Program::inputs`] order, `out` of length
    /// `outputs.len()`. `scratch` is reused between calls (resized as needed).
    pub fn eval(&self, inputs: &[f64], scratch: &mut Vec<f64>, out: &mut [f64]) {
        assert_eq!(
            inputs.len(),
            self.inputs.len(),
            "one value per program input"
        );
        assert_eq!(out.len(), self.outputs.len(), "one slot per program output");
        scratch.clear();
        scratch.reserve(self.ops.len());
        for op in &self.ops {
            let v = match *op {
                Op::Input(i) => inputs[i as usize],
                Op::Const(bits) => f64::from_bits(bits),
                Op::Add(a, b) => scratch[a as usize] + scratch[b as usize],
                Op::Sub(a, b) => scratch[a as usize] - scratch[b as usize],
                Op::Mul(a, b) => scratch[a as usize] * scratch[b as usize],
                Op::Neg(a) => -scratch[a as usize],
                Op::Div(a, b) => scratch[a as usize] / scratch[b as usize],
            };
            scratch.push(v);
        }
        for (o, slot) in out.iter_mut().zip(&self.outputs) {
            *o = match *slot {
                Output::Var(v) => scratch[v as usize],
                Output::Neg(v) => -scratch[v as usize],
                Output::Const(c) => c,
            };
        }
    }
}
