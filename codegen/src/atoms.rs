//! The atoms of a machine's formulas: for every rotary axis the sine and cosine of its command,
//! for every linear axis its command (mm), and every kinematic symbol (mm). Their order is the
//! order of terms in tables and of inputs in generated code.

use crate::poly::Atom;
use model_spec::{AxisId, AxisKind, Machine, SymbolId};

/// What an atom stands for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum AtomKind {
    /// Sine of a rotary command.
    Sin(AxisId),
    /// Cosine of a rotary command.
    Cos(AxisId),
    /// A linear command, mm.
    Command(AxisId),
    /// A kinematic symbol, mm.
    Symbol(SymbolId),
}

/// The atoms of one machine, with their names for people and for code.
#[derive(Clone, Debug, PartialEq)]
pub struct AtomTable {
    /// The atoms, in order.
    pub kinds: Vec<AtomKind>,
    /// Names in formulas, the seed's style: `Sa`, `Ca`, `Xm`, `Xw`.
    pub names: Vec<String>,
    /// Names in LaTeX: `S_a`, `C_a`, `X_m`, `X_{w}`.
    pub latex: Vec<String>,
}

fn latex_symbol(name: &str) -> String {
    let mut chars = name.chars();
    match chars.next() {
        Some(first) if name.len() > 1 => format!("{first}_{{{}}}", chars.as_str()),
        _ => name.to_string(),
    }
}

impl AtomTable {
    /// The atoms of `m`: sin/cos of the rotary axes, linear commands, then kinematic symbols.
    pub fn new(m: &Machine) -> AtomTable {
        let mut kinds = Vec::new();
        for i in m.rotary_axes() {
            kinds.push(AtomKind::Sin(i));
            kinds.push(AtomKind::Cos(i));
        }
        for i in m.linear_axes() {
            kinds.push(AtomKind::Command(i));
        }
        for s in 0..m.symbols.len() {
            kinds.push(AtomKind::Symbol(s));
        }
        let names = kinds
            .iter()
            .map(|k| match *k {
                AtomKind::Sin(a) => format!("S{}", m.axes[a].name.to_ascii_lowercase()),
                AtomKind::Cos(a) => format!("C{}", m.axes[a].name.to_ascii_lowercase()),
                AtomKind::Command(a) => format!("{}m", m.axes[a].name),
                AtomKind::Symbol(s) => m.symbols[s].name.clone(),
            })
            .collect();
        let latex = kinds
            .iter()
            .map(|k| match *k {
                AtomKind::Sin(a) => format!("S_{}", m.axes[a].name.to_ascii_lowercase()),
                AtomKind::Cos(a) => format!("C_{}", m.axes[a].name.to_ascii_lowercase()),
                AtomKind::Command(a) => format!("{}_m", m.axes[a].name),
                AtomKind::Symbol(s) => latex_symbol(&m.symbols[s].name),
            })
            .collect();
        debug_assert!(
            m.axes
                .iter()
                .all(|a| a.kind == AxisKind::Linear || a.kind == AxisKind::Rotary)
        );
        AtomTable {
            kinds,
            names,
            latex,
        }
    }

    /// The atom of `kind`.
    pub fn find(&self, kind: AtomKind) -> Atom {
        self.kinds
            .iter()
            .position(|&k| k == kind)
            .expect("every axis and symbol has its atoms") as Atom
    }

    /// `(sin, cos)` atom pairs of the rotary axes, for the canonical reduction.
    pub fn trig_pairs(&self) -> Vec<(Atom, Atom)> {
        self.kinds
            .iter()
            .enumerate()
            .filter_map(|(i, k)| match k {
                AtomKind::Sin(a) => Some((i as Atom, self.find(AtomKind::Cos(*a)))),
                _ => None,
            })
            .collect()
    }

    /// The number of pose atoms: sines and cosines of the rotary commands and the linear
    /// commands, which come before the kinematic symbols.
    pub fn pose_count(&self) -> usize {
        self.kinds
            .iter()
            .take_while(|k| !matches!(k, AtomKind::Symbol(_)))
            .count()
    }

    /// Writes the values of the pose atoms at `commands` (per axis: linear mm, rotary rad)
    /// into the first [`AtomTable::pose_count`] entries of `out`, in atom order; the kinematic
    /// symbols after them are left as they are.
    pub fn fill_pose(&self, commands: &[f64], out: &mut [f64]) {
        for (v, k) in out.iter_mut().zip(&self.kinds) {
            *v = match *k {
                AtomKind::Sin(a) => commands[a].sin(),
                AtomKind::Cos(a) => commands[a].cos(),
                AtomKind::Command(a) => commands[a],
                AtomKind::Symbol(_) => break,
            };
        }
    }

    /// Numeric values of all atoms at a pose: `commands` per axis (linear mm, rotary rad),
    /// `params` per kinematic symbol (mm).
    pub fn values(&self, commands: &[f64], params: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; self.pose_count()];
        self.fill_pose(commands, &mut out);
        out.extend_from_slice(params);
        out
    }
}
