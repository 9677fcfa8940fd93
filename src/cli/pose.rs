//! `--at` and `--param`: a pose of the machine and its kinematic parameters, read from
//! `NAME=VALUE` comma lists (axis positions in mm and degrees, offsets in mm).

use super::{CliError, CliResult};
use model_spec::{AxisId, AxisKind, Machine};

/// A pose ready for evaluation.
#[derive(Clone, Debug)]
pub struct Pose {
    /// Per axis, in axis order: linear mm, rotary rad.
    pub commands: Vec<f64>,
    /// Per axis, as people read it: linear mm, rotary degrees (as given, not converted back).
    pub shown: Vec<f64>,
    /// Per axis: `true` when the value came from the inverse kinematics, not from `--at`.
    pub from_ik: Vec<bool>,
    /// Per kinematic symbol, mm.
    pub params: Vec<f64>,
}

/// Parses a `NAME=VALUE,NAME=VALUE` list of finite numbers for the flag `flag`. Names are
/// returned as written; duplicates (by `same`) are rejected.
fn assignments(
    flag: &str,
    text: &str,
    same: impl Fn(&str, &str) -> bool,
) -> CliResult<Vec<(String, f64)>> {
    if text.trim().is_empty() {
        return Err(CliError::usage(format!(
            "{flag}: empty list (expected NAME=VALUE,NAME=VALUE,...)"
        )));
    }
    let mut out: Vec<(String, f64)> = Vec::new();
    for item in text.split(',') {
        let item = item.trim();
        if item.is_empty() {
            return Err(CliError::usage(format!(
                "{flag}: empty item in `{text}` (expected NAME=VALUE,NAME=VALUE,...)"
            )));
        }
        let Some((name, value)) = item.split_once('=') else {
            return Err(CliError::usage(format!(
                "{flag}: `{item}` is not NAME=VALUE"
            )));
        };
        let (name, value) = (name.trim(), value.trim());
        if name.is_empty() {
            return Err(CliError::usage(format!("{flag}: `{item}` has no name")));
        }
        let x: f64 = value
            .parse()
            .map_err(|_| CliError::usage(format!("{flag}: `{item}`: `{value}` is not a number")))?;
        if !x.is_finite() {
            return Err(CliError::usage(format!(
                "{flag}: `{item}`: the value must be a finite number"
            )));
        }
        if out.iter().any(|(n, _)| same(n, name)) {
            return Err(CliError::usage(format!("{flag}: `{name}` is given twice")));
        }
        out.push((name.to_string(), x));
    }
    Ok(out)
}

/// Kinematic parameters: the machine's defaults (mm), overridden by `--param` (exact symbol
/// names).
pub fn parse_params(m: &Machine, text: Option<&str>) -> CliResult<Vec<f64>> {
    let mut params = m.default_parameters();
    let Some(text) = text else {
        return Ok(params);
    };
    for (name, x) in assignments("--param", text, |a, b| a == b)? {
        let Some(s) = m.symbol_by_name(&name) else {
            let names: Vec<&str> = m.symbols.iter().map(|s| s.name.as_str()).collect();
            return Err(CliError::usage(format!(
                "--param: machine {} has no kinematic symbol `{name}` (symbols: {})",
                m.name,
                if names.is_empty() {
                    "none".to_string()
                } else {
                    names.join(", ")
                }
            )));
        };
        params[s] = x;
    }
    Ok(params)
}

/// The pose of `--at` (axis names case-insensitive; linear mm, rotary degrees) with the
/// parameters `params`. Every rotary axis must be given; linear axes left out are filled by the
/// nominal tool-centre-point inverse kinematics (`solver::simulation::tool_centre_point_ik`), which puts the
/// tool point on the workpiece point at the given rotary positions.
pub fn parse_at(m: &Machine, text: &str, params: Vec<f64>) -> CliResult<Pose> {
    let mut given = Vec::new();
    for (name, x) in assignments("--at", text, |a, b| a.eq_ignore_ascii_case(b))? {
        let Some(i) = m
            .axes
            .iter()
            .position(|a| a.name.eq_ignore_ascii_case(&name))
        else {
            let names: Vec<&str> = m.axes.iter().map(|a| a.name.as_str()).collect();
            return Err(CliError::usage(format!(
                "--at: machine {} has no axis `{name}` (axes: {})",
                m.name,
                names.join(", ")
            )));
        };
        given.push((i, x));
    }
    complete(m, &given, params)
}

/// The pose with the axis positions `given` (axis id, linear mm or rotary degrees): every
/// rotary axis must be there; missing linear axes are filled by the nominal tool-centre-point
/// inverse kinematics at `params`. Errors name `--at`.
pub fn complete(m: &Machine, given: &[(AxisId, f64)], params: Vec<f64>) -> CliResult<Pose> {
    let mut commands = vec![0.0; m.axes.len()];
    let mut shown = vec![0.0; m.axes.len()];
    let mut seen = vec![false; m.axes.len()];
    for &(i, x) in given {
        commands[i] = match m.axes[i].kind {
            AxisKind::Linear => x,
            AxisKind::Rotary => x.to_radians(),
        };
        shown[i] = x;
        seen[i] = true;
    }
    if let Some(i) = m.rotary_axes().find(|&i| !seen[i]) {
        return Err(CliError::usage(format!(
            "--at: rotary axis {} is missing (give every rotary axis in degrees; linear axes may be left to the inverse kinematics)",
            m.axes[i].name
        )));
    }
    let from_ik: Vec<bool> = seen.iter().map(|s| !s).collect();
    if from_ik.iter().any(|&f| f) {
        let mut ik = commands.clone();
        solver::simulation::tool_centre_point_ik(m, &mut ik, &params).map_err(|e| {
            CliError::failure(format!(
                "--at: cannot fill the missing linear axes by inverse kinematics: {e} (give every axis)"
            ))
        })?;
        for i in 0..commands.len() {
            if from_ik[i] {
                commands[i] = ik[i];
                shown[i] = ik[i];
            }
        }
    }
    Ok(Pose {
        commands,
        shown,
        from_ik,
        params,
    })
}

/// The pose for people: `X = 12.5 mm (IK), A = 30°, …`.
pub fn describe(m: &Machine, pose: &Pose) -> String {
    m.axes
        .iter()
        .enumerate()
        .map(|(i, a)| match a.kind {
            AxisKind::Linear => format!(
                "{} = {} mm{}",
                a.name,
                super::short(pose.shown[i]),
                if pose.from_ik[i] { " (IK)" } else { "" }
            ),
            AxisKind::Rotary => format!("{} = {}°", a.name, super::short(pose.shown[i])),
        })
        .collect::<Vec<_>>()
        .join(", ")
}
