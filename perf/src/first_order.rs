//! Error gains by a runtime first-order product of the chain, without code generation: the
//! tool point, the workpiece point and the z direction of each end are carried through the
//! chain steps at one pose as `v0 + Σ εi·vi` with numbers, exactly as the symbolic engine does
//! with polynomials (`codegen::derive`). It is the baseline the generated code is measured
//! against (a generic "first-order HTM product" library), and a third independent check of the
//! gains.

use model_spec::kinematics::{Step, chain_steps};
use model_spec::{AxisKind, ErrorId, Machine, Side, Value};
use nalgebra::{Matrix3, Vector3};
use simulation::exact::{coordinate_rotation, frame_rotation};

/// A machine's chains lowered once, for repeated evaluation.
#[derive(Clone, Debug)]
pub struct FirstOrderChain<'m> {
    m: &'m Machine,
    tool: Vec<Step>,
    work: Vec<Step>,
    /// Catalogue id → slot of the requested errors (`usize::MAX`: not requested).
    slot: Vec<usize>,
    n: usize,
}

/// A first-order vector: nominal part and one part per requested error.
struct Carried {
    nominal: Vector3<f64>,
    parts: Vec<Vector3<f64>>,
    point: bool,
}

impl<'m> FirstOrderChain<'m> {
    /// For the gains of `errors` (catalogue ids) of `m`.
    pub fn new(m: &'m Machine, errors: &[ErrorId]) -> FirstOrderChain<'m> {
        let mut slot = vec![usize::MAX; m.catalogue.len()];
        for (i, &e) in errors.iter().enumerate() {
            slot[e] = i;
        }
        FirstOrderChain {
            m,
            tool: chain_steps(m, Side::Tool),
            work: chain_steps(m, Side::Work),
            slot,
            n: errors.len(),
        }
    }

    fn value(&self, v: Value, params: &[f64]) -> f64 {
        match v {
            Value::Number(x) => x,
            Value::Symbol(s) => params[s],
        }
    }

    fn carry(
        &self,
        steps: &[Step],
        point: bool,
        commands: &[f64],
        params: &[f64],
    ) -> (Carried, Matrix3<f64>) {
        let mut v = Carried {
            nominal: if point {
                Vector3::zeros()
            } else {
                Vector3::z()
            },
            parts: vec![Vector3::zeros(); self.n],
            point,
        };
        let mut rotation = Matrix3::identity();
        let slot = |id: &Option<ErrorId>| id.map(|e| self.slot[e]).filter(|&s| s != usize::MAX);
        for step in steps.iter().rev() {
            match step {
                Step::Offset(o) => {
                    if v.point {
                        v.nominal += Vector3::new(
                            self.value(o[0], params),
                            self.value(o[1], params),
                            self.value(o[2], params),
                        );
                    }
                }
                Step::ErrorTranslation(ids) => {
                    if v.point {
                        for (k, id) in ids.iter().enumerate() {
                            if let Some(s) = slot(id) {
                                v.parts[s][k] += 1.0;
                            }
                        }
                    }
                }
                Step::ErrorRotation(ids) => {
                    for (k, id) in ids.iter().enumerate() {
                        if let Some(s) = slot(id) {
                            v.parts[s] += Vector3::ith(k, 1.0).cross(&v.nominal);
                        }
                    }
                }
                Step::Frame { axis, turn } => {
                    let r = *frame_rotation(&self.m.axes[*axis].direction, *turn).matrix();
                    v.nominal = r * v.nominal;
                    for p in &mut v.parts {
                        *p = r * *p;
                    }
                    rotation = r * rotation;
                }
                Step::Motion {
                    axis,
                    positioning_error,
                } => {
                    let a = &self.m.axes[*axis];
                    match a.kind {
                        AxisKind::Linear => {
                            if v.point {
                                v.nominal[a.direction.own.dir.index()] +=
                                    a.direction.own.sign() * commands[*axis];
                            }
                        }
                        AxisKind::Rotary => {
                            if let Some(s) = slot(positioning_error) {
                                v.parts[s] += Vector3::ith(a.direction.own.dir.index(), 1.0)
                                    .cross(&v.nominal);
                            }
                            let r = *coordinate_rotation(
                                a.direction.own.dir,
                                a.direction.own.sign() * commands[*axis],
                            )
                            .matrix();
                            v.nominal = r * v.nominal;
                            for p in &mut v.parts {
                                *p = r * *p;
                            }
                            rotation = r * rotation;
                        }
                    }
                }
            }
        }
        (v, rotation)
    }

    /// The gains `[gx, gy, gz, gi, gj, gk]` of every requested error at a pose (commands mm and
    /// rad, parameters mm), as the symbolic engine defines them.
    pub fn gains(&self, commands: &[f64], params: &[f64], out: &mut [[f64; 6]]) {
        let (pt, r_tool) = self.carry(&self.tool, true, commands, params);
        let (pw, _) = self.carry(&self.work, true, commands, params);
        let (zt, _) = self.carry(&self.tool, false, commands, params);
        let (zw, _) = self.carry(&self.work, false, commands, params);
        let rt = r_tool.transpose();
        for (i, o) in out.iter_mut().enumerate().take(self.n) {
            let p = rt * (pt.parts[i] - pw.parts[i]);
            let z = rt * (zt.parts[i] - zw.parts[i]);
            *o = [p.x, p.y, p.z, z.x, z.y, z.z];
        }
    }
}
