//! `--at` and `--param`: a pose of the machine and its kinematic parameters, read from
//! `NAME=VALUE` comma lists (axis positions in mm and degrees, offsets in mm). Every error names
//! its flag and is a usage error (exit code 2).

use super::args::items;
use super::{Error, VerbResult};
use model_spec::text::quoted_start;
use model_spec::units::compact;
use model_spec::{AxisId, Machine};

/// Parses a `NAME=VALUE,NAME=VALUE` list of finite numbers for `flag`; names as written,
/// duplicates (by `same`) rejected.
fn assignments(
    flag: &str,
    text: &str,
    same: impl Fn(&str, &str) -> bool,
) -> VerbResult<Vec<(String, f64)>> {
    let mut out: Vec<(String, f64)> = Vec::new();
    for item in items(flag, text, "expected NAME=VALUE,NAME=VALUE,...")? {
        let Some((name, value)) = item.split_once('=') else {
            return Err(Error::usage(format!(
                "{flag}: `{}` is not NAME=VALUE",
                quoted_start(item)
            )));
        };
        let (name, value) = (name.trim(), value.trim());
        if name.is_empty() {
            return Err(Error::usage(format!(
                "{flag}: `{}` has no name",
                quoted_start(item)
            )));
        }
        let x: f64 = value.parse().map_err(|_| {
            Error::usage(format!(
                "{flag}: `{}`: `{}` is not a number",
                quoted_start(item),
                quoted_start(value)
            ))
        })?;
        if !x.is_finite() {
            return Err(Error::usage(format!(
                "{flag}: `{}`: the value must be a finite number",
                quoted_start(item)
            )));
        }
        if out.iter().any(|(n, _)| same(n, name)) {
            return Err(Error::usage(format!(
                "{flag}: `{}` is given twice",
                quoted_start(name)
            )));
        }
        out.push((name.to_string(), x));
    }
    Ok(out)
}

/// Kinematic parameters: the machine's defaults (mm), overridden by `--param` (exact symbol
/// names).
pub fn params(m: &Machine, text: Option<&str>) -> VerbResult<Vec<f64>> {
    let mut params = m.default_parameters();
    if let Some(text) = text {
        override_params(m, "--param", text, &mut params)?;
    }
    Ok(params)
}

/// Overrides `params` (mm, symbol order) with the `SYMBOL=VALUE,...` list `text` of `flag`
/// (exact symbol names, each at most the largest length a machine may have).
pub fn override_params(m: &Machine, flag: &str, text: &str, params: &mut [f64]) -> VerbResult {
    for (name, x) in assignments(flag, text, |a, b| a == b)? {
        let Some(s) = m.symbol_by_name(&name) else {
            let names: Vec<&str> = m.symbols.iter().map(|s| s.name.as_str()).collect();
            return Err(Error::usage(format!(
                "{flag}: machine {} has no kinematic symbol `{}` (symbols: {})",
                m.name,
                quoted_start(&name),
                if names.is_empty() {
                    "none".to_string()
                } else {
                    names.join(", ")
                }
            )));
        };
        if x.abs() > model_spec::limits::MAX_LENGTH_MM {
            return Err(Error::usage(format!(
                "{flag}: `{name}` = {} mm is beyond the largest length a machine may have, {} mm",
                compact(x),
                model_spec::limits::MAX_LENGTH_MM
            )));
        }
        params[s] = x;
    }
    Ok(())
}

/// The axis positions of `--at` (axis names case-insensitive; linear mm, rotary degrees).
pub fn at(m: &Machine, text: &str) -> VerbResult<Vec<(AxisId, f64)>> {
    let mut given = Vec::new();
    for (name, x) in assignments("--at", text, |a, b| a.eq_ignore_ascii_case(b))? {
        let Some(i) = m
            .axes
            .iter()
            .position(|a| a.name.eq_ignore_ascii_case(&name))
        else {
            let names: Vec<&str> = m.axes.iter().map(|a| a.name.as_str()).collect();
            return Err(Error::usage(format!(
                "--at: machine {} has no axis `{}` (axes: {})",
                m.name,
                quoted_start(&name),
                names.join(", ")
            )));
        };
        given.push((i, x));
    }
    Ok(given)
}
