//! Models too large for one function, compiled in parts of bounded size.
//!
//! The whole model is compiled once. When it exceeds the bound, the instructions each error's
//! outputs depend on in the whole gains program (its closure; the closure of its three
//! position outputs for the position program) tell how large a part holding a set of errors
//! will be: about the size of the union of their closures. The errors are grouped
//! by axis (catalogue order keeps an axis together) and the groups packed into parts on that
//! estimate; each part is then compiled once, and a part that still exceeds the bound (its
//! own common-subexpression elimination came out larger than the estimate) is halved until it
//! fits or holds one error. The cost is a few compilations of the model, not one per trial.

use crate::derive::GainModel;
use crate::ir::{Op, Output, Program};
use crate::lower::{compile, compile_position};
use model_spec::Machine;

/// A part of a model compiled on its own: some of its errors, with their gains and position
/// gains programs.
#[derive(Clone, Debug, PartialEq)]
pub struct Part {
    /// Positions of its errors in the model's error list, ascending.
    pub rows: Vec<usize>,
    /// Six outputs per error of the part ([`compile`] of the part).
    pub gains: Program,
    /// Position gains, direction-major over the part's errors ([`compile_position`]).
    pub position: Program,
}

/// The default bound on the instructions of one generated function.
pub const MAX_INSTRUCTIONS: usize = 4000;

/// The instructions of `p` each group of outputs depends on: `group(o)` is the group of
/// output `o` (`None`: not counted), `groups` their number. Each closure is ascending.
fn closures(p: &Program, groups: usize, group: impl Fn(usize) -> Option<usize>) -> Vec<Vec<u32>> {
    let mut stamp = vec![usize::MAX; p.ops.len()];
    let mut roots: Vec<Vec<u32>> = vec![Vec::new(); groups];
    for (o, out) in p.outputs.iter().enumerate() {
        if let (Output::Var(v) | Output::Neg(v), Some(g)) = (out, group(o)) {
            roots[g].push(*v);
        }
    }
    roots
        .into_iter()
        .enumerate()
        .map(|(g, mut stack)| {
            let mut closure = Vec::new();
            while let Some(v) = stack.pop() {
                if stamp[v as usize] == g {
                    continue;
                }
                stamp[v as usize] = g;
                closure.push(v);
                match p.ops[v as usize] {
                    Op::Add(a, b) | Op::Sub(a, b) | Op::Mul(a, b) | Op::Div(a, b) => {
                        stack.push(a);
                        stack.push(b);
                    }
                    Op::Neg(a) => stack.push(a),
                    Op::Input(_) | Op::Const(_) => {}
                }
            }
            closure.sort_unstable();
            closure
        })
        .collect()
}

/// The estimated size of a part: the union of its errors' closures in the whole gains
/// program, of all six outputs for the part's gains program and of the three position outputs
/// for its position program (the larger of the two).
struct Estimate {
    gains: Vec<Vec<u32>>,
    position: Vec<Vec<u32>>,
    in_gains: Vec<bool>,
    in_position: Vec<bool>,
    size: [usize; 2],
}

impl Estimate {
    fn new(whole: &Program, n: usize) -> Estimate {
        Estimate {
            gains: closures(whole, n, |o| Some(o / 6)),
            position: closures(whole, n, |o| (o % 6 < 3).then_some(o / 6)),
            in_gains: vec![false; whole.ops.len()],
            in_position: vec![false; whole.ops.len()],
            size: [0, 0],
        }
    }

    /// The estimated size of the current part with `rows` added.
    fn with(&self, rows: &[usize]) -> usize {
        let count = |closures: &[Vec<u32>], inside: &[bool]| {
            let mut extra: Vec<u32> = rows
                .iter()
                .flat_map(|&i| closures[i].iter().copied())
                .filter(|&v| !inside[v as usize])
                .collect();
            extra.sort_unstable();
            extra.dedup();
            extra.len()
        };
        (self.size[0] + count(&self.gains, &self.in_gains))
            .max(self.size[1] + count(&self.position, &self.in_position))
    }

    fn add(&mut self, rows: &[usize]) {
        for &i in rows {
            for &v in &self.gains[i] {
                if !std::mem::replace(&mut self.in_gains[v as usize], true) {
                    self.size[0] += 1;
                }
            }
            for &v in &self.position[i] {
                if !std::mem::replace(&mut self.in_position[v as usize], true) {
                    self.size[1] += 1;
                }
            }
        }
    }

    fn clear(&mut self) {
        self.in_gains.fill(false);
        self.in_position.fill(false);
        self.size = [0, 0];
    }
}

/// Compiles a model into parts of at most `max_instructions` instructions each (one part when
/// the whole model fits): the errors are grouped by the axis they belong to (squareness,
/// set-up and sensor-offset errors by their kind), groups are added to a part while it stays
/// within the bound, and a group that alone exceeds it is split error by error (see the
/// module documentation for how sizes are estimated). Each part has its own
/// common-subexpression elimination, so sharing across parts is lost: the bound trades a
/// little arithmetic for a bounded function size and compile time. A part of one error may
/// exceed the bound.
pub fn compile_parts(m: &Machine, model: &GainModel, max_instructions: usize) -> Vec<Part> {
    let build = |rows: Vec<usize>| {
        let sub = model.select(&rows);
        Part {
            gains: compile(m, &sub),
            position: compile_position(m, &sub),
            rows,
        }
    };
    let n = model.errors.len();
    let size = |p: &Part| p.gains.ops.len().max(p.position.ops.len());
    let whole = compile(m, model);
    if whole.ops.len() <= max_instructions {
        let position = compile_position(m, model);
        if position.ops.len() <= max_instructions {
            return vec![Part {
                rows: (0..n).collect(),
                gains: whole,
                position,
            }];
        }
    }
    // Groups of consecutive errors with the same key (catalogue order keeps an axis together).
    let key = |i: usize| {
        let e = &m.catalogue[model.errors[i]];
        (e.axis(), std::mem::discriminant(&e.kind))
    };
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for i in 0..n {
        match groups.last_mut() {
            Some(g) if key(g[0]) == key(i) => g.push(i),
            _ => groups.push(vec![i]),
        }
    }
    let mut estimate = Estimate::new(&whole, n);
    let mut planned: Vec<Vec<usize>> = Vec::new();
    let mut current: Vec<usize> = Vec::new();
    let mut close = |current: &mut Vec<usize>, estimate: &mut Estimate| {
        if !current.is_empty() {
            planned.push(std::mem::take(current));
            estimate.clear();
        }
    };
    for g in groups {
        if !current.is_empty() && estimate.with(&g) > max_instructions {
            close(&mut current, &mut estimate);
        }
        // The whole group when it fits, else error by error.
        for &i in &g {
            if !current.is_empty() && estimate.with(&[i]) > max_instructions {
                close(&mut current, &mut estimate);
            }
            current.push(i);
            estimate.add(&[i]);
        }
    }
    close(&mut current, &mut estimate);
    // Compile each part; halve one that came out larger than estimated.
    let mut parts = Vec::new();
    let mut queue: Vec<Vec<usize>> = planned.into_iter().rev().collect();
    while let Some(rows) = queue.pop() {
        let part = build(rows);
        if size(&part) <= max_instructions || part.rows.len() == 1 {
            parts.push(part);
        } else {
            let half = part.rows.len() / 2;
            queue.push(part.rows[half..].to_vec());
            queue.push(part.rows[..half].to_vec());
        }
    }
    parts
}
