//! The kinematic-parameter independent model of a three-axis machine whose three linear axes
//! carry the tool (`seed-3axis`: bed → Y → X → Z → holder → tool, the workpiece on the bed).
//!
//! With the axes numbered 1, 2, 3 from the bed outwards (Y, X, Z), `n_j` the signed unit
//! direction of axis `j`, `q_j` its command, and axis `k` measured at the tool end with the
//! other axes standing at `a_kj`, the tool-end error is, to first order in the errors
//! (docs/volumetric.md derives it):
//!
//! ```text
//! du(q) = Σ_k T_k(q_k)                                   measured translations (9 tables)
//!       + Σ_s ω_s × Σ_{j ≥ axis of s} n_j·q_j              squareness (3 errors)
//!       + Σ_{i<j} (R_i(q_i) − R_i(a_ji)) × n_j·(q_j − a_ij)  lower axis tilts, upper axis moved
//!       − (the same at the reference point)
//! ```
//!
//! - `T_k`: the translations measured while axis `k` moves, the positioning component as
//!   measured, the two straightness components with their least-squares straight line taken
//!   out (the reference straight line of ISO 230-1: the laser's alignment does not matter, and
//!   the squareness carries the angle between the axes' lines);
//! - `R_i`: the rotations measured while axis `i` moves. Only differences of them enter, so the
//!   angular zero of the laser does not matter either. The rotations of the top axis (Z) and
//!   the rotation of the middle axis about the top axis's direction (ECX) do not enter: 17 of
//!   the 21 errors;
//! - no kinematic parameter enters: the Abbe offsets of the reflector at the tool end are in
//!   the measured translations.
//!
//! `du` is the tool point's position error (actual minus nominal, mm) along +x, +y, +z of the
//! frame the measurements define (y along the reference axis's line, x in the plane of the
//! first two axes' lines), zero at the reference point.

use super::laser::AxisMeasurement;
use super::squareness::Squareness;
use super::table::Table;
use super::{MAX_TRANSLATION_MM, VolumetricError};
use model_spec::units::compact;
use model_spec::{AxisId, AxisKind, Dir, ErrorKind, Machine, Side};
use nalgebra::Vector3;

/// The three axes in chain order, bed outwards.
const N: usize = 3;

/// The kinematic-parameter independent model of a three-axis machine, built from three laser
/// measurements and the squareness errors.
#[derive(Clone, Debug)]
pub struct VolumetricModel {
    /// The machine's name.
    pub machine: String,
    /// The linear axes in the tool chain, bed outwards ([`Machine::axes`] indices).
    chain: [AxisId; N],
    /// Their letters.
    names: [String; N],
    /// The signed unit direction of each (chain order), bed frame.
    dirs: [Vector3<f64>; N],
    /// The coordinate direction and sign of each (chain order).
    coordinate: [(Dir, f64); N],
    /// The strokes (chain order), mm.
    strokes: [[f64; 2]; N],
    /// Translation tables (chain order; along +x, +y, +z), mm.
    translations: Vec<[Table; 3]>,
    /// Rotation tables (chain order; about +x, +y, +z), rad.
    rotations: Vec<[Table; 3]>,
    /// `stood[k][j]`: the command of axis `j` while axis `k` was measured (chain order), mm.
    stood: [[f64; N]; N],
    /// The squareness errors: chain index of their axis and rotation vector, rad.
    squareness: Vec<(usize, Vector3<f64>)>,
    /// The reference point (chain order), mm.
    reference: [f64; N],
    /// The uncorrected model at the reference point, mm.
    at_reference: Vector3<f64>,
    /// The number of axes of the machine (the length of a pose).
    axes: usize,
    /// The files the measurements came from (chain order).
    sources: [String; N],
}

fn unit(d: Dir) -> Vector3<f64> {
    let mut v = Vector3::zeros();
    v[d.index()] = 1.0;
    v
}

impl VolumetricModel {
    /// Builds the model of `m` from one laser measurement per linear axis (any order) and the
    /// squareness file.
    ///
    /// # Errors
    /// [`VolumetricError::Setup`] when `m` is not a machine whose three linear axes all carry
    /// the tool along three different coordinate directions, an axis is measured twice or not
    /// at all, or a measurement was taken with a lower axis outside the range that axis's own
    /// measurement covers; [`VolumetricError::OutOfRange`] when the reference point is outside
    /// a measured range.
    pub fn new(
        m: &Machine,
        measurements: &[AxisMeasurement],
        squareness: &Squareness,
    ) -> Result<VolumetricModel, VolumetricError> {
        let chain: Vec<AxisId> = m.tool.axes().collect();
        let described: Vec<String> = m
            .axes
            .iter()
            .map(|a| {
                let side = match a.side {
                    Side::Work => "work",
                    Side::Tool => "tool",
                };
                let kind = match a.kind {
                    AxisKind::Linear => "linear",
                    AxisKind::Rotary => "rotary",
                };
                format!("{} ({kind}, {side} chain)", a.name)
            })
            .collect();
        let mut dirs_seen = [false; 3];
        let fits = m.axes.len() == N
            && chain.len() == N
            && chain.iter().all(|&a| {
                let Some(d) = m.axes[a].direction.as_coordinate().map(|d| d.dir.index()) else {
                    return false;
                };
                let fresh = !dirs_seen[d];
                dirs_seen[d] = true;
                m.axes[a].kind == AxisKind::Linear && fresh
            });
        if !fits {
            return Err(VolumetricError::Setup(format!(
                "machine `{}`: the volumetric model covers machines whose three linear axes all carry the tool along three different coordinate directions, the workpiece fixed on the bed (like seed-3axis); this machine has the axes {}",
                m.name,
                described.join(", ")
            )));
        }
        let chain: [AxisId; N] = [chain[0], chain[1], chain[2]];
        let index_of = |a: AxisId| chain.iter().position(|&c| c == a);
        let mut by_axis: [Option<&AxisMeasurement>; N] = [None; N];
        for meas in measurements {
            let Some(k) = index_of(meas.axis) else {
                return Err(VolumetricError::Setup(format!(
                    "{}: axis {} is not a linear axis of the tool chain of {}",
                    meas.source, m.axes[meas.axis].name, m.name
                )));
            };
            if let Some(first) = by_axis[k] {
                return Err(VolumetricError::Setup(format!(
                    "axis {} is measured twice ({} and {})",
                    m.axes[meas.axis].name, first.source, meas.source
                )));
            }
            by_axis[k] = Some(meas);
        }
        let mut meas: Vec<&AxisMeasurement> = Vec::with_capacity(N);
        for (k, found) in by_axis.iter().enumerate() {
            match found {
                Some(x) => meas.push(x),
                None => {
                    return Err(VolumetricError::Setup(format!(
                        "axis {} has no laser measurement: the model needs one per linear axis ({})",
                        m.axes[chain[k]].name,
                        chain
                            .iter()
                            .map(|&a| m.axes[a].name.as_str())
                            .collect::<Vec<_>>()
                            .join(", ")
                    )));
                }
            }
        }
        let names = chain.map(|a| m.axes[a].name.clone());
        // Every axis of the chain is along a coordinate direction (checked above).
        let coordinate =
            chain.map(|a| (m.axes[a].direction.own.dir, m.axes[a].direction.own.sign()));
        let dirs = coordinate.map(|(d, s)| unit(d) * s);
        let strokes = chain.map(|a| m.axes[a].limits);
        let mut translations = Vec::with_capacity(N);
        let mut rotations = Vec::with_capacity(N);
        for (k, x) in meas.iter().enumerate() {
            let along = coordinate[k].0.index();
            let t = |d: usize| {
                let raw = Table::new(
                    x.positions.clone(),
                    x.translations.iter().map(|v| v[d]).collect(),
                );
                if d == along { raw } else { raw.without_line() }
            };
            let r = |d: usize| {
                Table::new(
                    x.positions.clone(),
                    x.rotations.iter().map(|v| v[d]).collect(),
                )
            };
            translations.push([t(0), t(1), t(2)]);
            rotations.push([r(0), r(1), r(2)]);
        }
        let mut stood = [[0.0; N]; N];
        for k in 0..N {
            for j in 0..N {
                stood[k][j] = meas[k].pose[chain[j]];
            }
        }
        let mut sq = Vec::new();
        for &(e, v) in &squareness.values {
            if let ErrorKind::Squareness { axis, about } = m.catalogue[e].kind
                && let Some(c) = index_of(axis)
            {
                sq.push((c, unit(about) * v));
            }
        }
        let mut model = VolumetricModel {
            machine: m.name.clone(),
            chain,
            names,
            dirs,
            coordinate,
            strokes,
            translations,
            rotations,
            stood,
            squareness: sq,
            reference: chain.map(|a| squareness.reference[a]),
            at_reference: Vector3::zeros(),
            axes: m.axes.len(),
            sources: [0, 1, 2].map(|k| meas[k].source.clone()),
        };
        // A lower axis's rotations are read where it stood while an upper axis was measured.
        for j in 0..N {
            for i in 0..j {
                let q = model.stood[j][i];
                let [lo, hi] = model.range_of(i);
                if !(lo..=hi).contains(&q) {
                    return Err(VolumetricError::Setup(format!(
                        "{}: axis {} stood at {} mm while axis {} was measured, outside the range {} .. {} mm that the laser measurement of {} covers ({}): the model needs {}'s angular errors there",
                        model.sources[j],
                        model.names[i],
                        compact(q),
                        model.names[j],
                        compact(lo),
                        compact(hi),
                        model.names[i],
                        model.sources[i],
                        model.names[i]
                    )));
                }
            }
        }
        for k in 0..N {
            model.check_position(k, model.reference[k]).map_err(|e| {
                VolumetricError::Setup(format!("{}: the reference point: {e}", squareness.source))
            })?;
        }
        model.at_reference = model.raw(&model.reference);
        Ok(model)
    }

    /// The measured range `[first, last]` of chain axis `k`, mm.
    fn range_of(&self, k: usize) -> [f64; 2] {
        self.translations[k][0].range()
    }

    fn check_position(&self, k: usize, q: f64) -> Result<(), VolumetricError> {
        let range = self.range_of(k);
        if q >= range[0] && q <= range[1] {
            Ok(())
        } else {
            Err(VolumetricError::OutOfRange {
                axis: self.names[k].clone(),
                position: q,
                range,
            })
        }
    }

    /// The measured range `[first, last]` of `axis` (a [`Machine::axes`] index), mm; `None` for
    /// an axis the model does not have.
    pub fn measured_range(&self, axis: AxisId) -> Option<[f64; 2]> {
        let k = self.chain.iter().position(|&c| c == axis)?;
        Some(self.range_of(k))
    }

    /// The stroke of `axis` (a [`Machine::axes`] index), mm.
    pub fn stroke(&self, axis: AxisId) -> Option<[f64; 2]> {
        let k = self.chain.iter().position(|&c| c == axis)?;
        Some(self.strokes[k])
    }

    /// The linear axes in the tool chain, bed outwards ([`Machine::axes`] indices).
    pub fn chain(&self) -> [AxisId; N] {
        self.chain
    }

    /// The signed unit direction (bed frame) of `axis` (a [`Machine::axes`] index).
    pub fn direction(&self, axis: AxisId) -> Option<Vector3<f64>> {
        let k = self.chain.iter().position(|&c| c == axis)?;
        Some(self.dirs[k])
    }

    /// The reference point ([`Machine::axes`] order), mm: `du` is zero there.
    pub fn reference(&self) -> Vec<f64> {
        let mut r = vec![0.0; self.axes];
        for (k, &a) in self.chain.iter().enumerate() {
            r[a] = self.reference[k];
        }
        r
    }

    /// The chain-order commands of a pose ([`Machine::axes`] order).
    fn in_chain(&self, commands: &[f64]) -> [f64; N] {
        assert_eq!(
            commands.len(),
            self.axes,
            "machine `{}`: one command per axis",
            self.machine
        );
        self.chain.map(|a| commands[a])
    }

    /// Checks that every command of `commands` ([`Machine::axes`] order, mm) is finite and
    /// within the range its axis was measured over.
    ///
    /// # Errors
    /// [`VolumetricError::OutOfRange`] for the first axis outside (chain order).
    ///
    /// # Panics
    /// When `commands` does not have one command per axis of the machine.
    pub fn check_range(&self, commands: &[f64]) -> Result<(), VolumetricError> {
        let q = self.in_chain(commands);
        (0..N).try_for_each(|k| self.check_position(k, q[k]))
    }

    /// The predicted tool-end error at `commands` ([`Machine::axes`] order, mm): actual minus
    /// nominal tool point, mm, along +x, +y, +z, zero at the reference point.
    ///
    /// # Errors
    /// [`VolumetricError::OutOfRange`] for a command outside its measured range;
    /// [`VolumetricError::Computation`] for a predicted error beyond ±1000 µm.
    ///
    /// # Panics
    /// When `commands` does not have one command per axis of the machine.
    pub fn du(&self, commands: &[f64]) -> Result<Vector3<f64>, VolumetricError> {
        self.check_range(commands)?;
        self.du_held(commands)
    }

    /// [`VolumetricModel::du`] with every command held to its measured range (the tables at
    /// their end values beyond it): for corrected commands a few µm past the end of a range.
    ///
    /// # Errors
    /// [`VolumetricError::Computation`] for a predicted error beyond ±1000 µm.
    pub(crate) fn du_held(&self, commands: &[f64]) -> Result<Vector3<f64>, VolumetricError> {
        let mut q = self.in_chain(commands);
        for (k, x) in q.iter_mut().enumerate() {
            let [lo, hi] = self.range_of(k);
            *x = x.clamp(lo, hi);
        }
        let du = self.raw(&q) - self.at_reference;
        if !du
            .iter()
            .all(|v| v.is_finite() && v.abs() <= MAX_TRANSLATION_MM)
        {
            let pose: Vec<String> = (0..N)
                .map(|k| format!("{} = {} mm", self.names[k], compact(q[k])))
                .collect();
            return Err(VolumetricError::Computation(format!(
                "the predicted error at {} is ({}, {}, {}) µm, beyond ±1000 µm: the measurements do not describe a machine tool",
                pose.join(", "),
                compact(du.x * 1e3),
                compact(du.y * 1e3),
                compact(du.z * 1e3)
            )));
        }
        Ok(du)
    }

    /// The model before the reference point is taken off (chain-order commands, mm).
    fn raw(&self, q: &[f64; N]) -> Vector3<f64> {
        let mut du = Vector3::zeros();
        for (t, &qk) in self.translations.iter().zip(q) {
            du += Vector3::new(t[0].at(qk), t[1].at(qk), t[2].at(qk));
        }
        for &(c, omega) in &self.squareness {
            let moved: Vector3<f64> = (c..N).map(|j| self.dirs[j] * q[j]).sum();
            du += omega.cross(&moved);
        }
        for j in 1..N {
            for i in 0..j {
                let tilt = self.rotation(i, q[i]) - self.rotation(i, self.stood[j][i]);
                du += tilt.cross(&(self.dirs[j] * (q[j] - self.stood[i][j])));
            }
        }
        du
    }

    fn rotation(&self, k: usize, q: f64) -> Vector3<f64> {
        let r = &self.rotations[k];
        Vector3::new(r[0].at(q), r[1].at(q), r[2].at(q))
    }

    /// The command change of every axis ([`Machine::axes`] order, mm) that moves the nominal
    /// tool point by `d` (mm, bed frame): `n_a · d` for each axis `a`.
    pub fn commands_for(&self, d: &Vector3<f64>) -> Vec<f64> {
        let mut c = vec![0.0; self.axes];
        for (k, &a) in self.chain.iter().enumerate() {
            let (dir, sign) = self.coordinate[k];
            c[a] = sign * d[dir.index()];
        }
        c
    }

    /// The axis letters, [`Machine::axes`] order.
    pub fn axis_name(&self, axis: AxisId) -> Option<&str> {
        let k = self.chain.iter().position(|&c| c == axis)?;
        Some(&self.names[k])
    }
}
