//! `--at` and `--param`: a pose of the machine and its kinematic parameters, read from
//! `NAME=VALUE` comma lists (axis positions in mm and degrees, offsets in mm). Every error names
//! its flag and is a usage error (exit code 2).

use super::args::items;
use super::{CliError, CliResult};
use model_spec::units::compact;
use model_spec::{AxisId, Machine};

/// Parses a `NAME=VALUE,NAME=VALUE` list of finite numbers for `flag`; names as written,
/// duplicates (by `same`) rejected.
fn assignments(
    flag: &str,
    text: &str,
    same: impl Fn(&str, &str) -> bool,
) -> CliResult<Vec<(String, f64)>> {
    let mut out: Vec<(String, f64)> = Vec::new();
    for item in items(flag, text, "expected NAME=VALUE,NAME=VALUE,...")? {
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
pub fn params(m: &Machine, text: Option<&str>) -> CliResult<Vec<f64>> {
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
        if x.abs() > model_spec::limits::MAX_LENGTH_MM {
            return Err(CliError::usage(format!(
                "--param: `{name}` = {} mm is beyond the largest length a machine may have, {} mm",
                compact(x),
                model_spec::limits::MAX_LENGTH_MM
            )));
        }
        params[s] = x;
    }
    Ok(params)
}

/// The axis positions of `--at` (axis names case-insensitive; linear mm, rotary degrees).
pub fn at(m: &Machine, text: &str) -> CliResult<Vec<(AxisId, f64)>> {
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
    Ok(given)
}
