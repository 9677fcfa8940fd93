//! Numbers in a machine description: symbol defaults, offsets, strokes and ranges.

use super::{Res, Validator};
use crate::raw::Num;
use toml::Spanned;

/// The unit people write a command limit in.
fn limit_unit(field: &str) -> &'static str {
    if field == "range" { "degrees" } else { "mm" }
}

impl Validator<'_> {
    /// The default of symbol `k` (mm): a finite number.
    pub(super) fn symbol_default(&self, k: &Spanned<String>, v: &Spanned<Num>) -> Res<f64> {
        let x = v.get_ref().0;
        if !x.is_finite() {
            return self.err(
                v.span(),
                format!(
                    "symbol `{}` has the non-finite default {x}: give a number (mm)",
                    k.get_ref()
                ),
            );
        }
        Ok(x)
    }

    /// A number of an offset (mm): finite.
    pub(super) fn offset_number(&self, x: f64, span: std::ops::Range<usize>) -> Res<f64> {
        if !x.is_finite() {
            return self.err(span, format!("`offset` has the non-finite number {x}"));
        }
        Ok(x)
    }

    /// The `stroke` (mm) or `range` (degrees) of an axis: two finite numbers, min below max.
    pub(super) fn limits(
        &self,
        s: &Spanned<Vec<Spanned<Num>>>,
        axis: &str,
        field: &str,
    ) -> Res<[f64; 2]> {
        let v = s.get_ref();
        let unit = limit_unit(field);
        if v.len() != 2 {
            return self.err(
                s.span(),
                format!(
                    "axis {axis}: `{field}` needs two numbers [min, max] ({unit}), found {}",
                    v.len()
                ),
            );
        }
        for x in v {
            let value = x.get_ref().0;
            if !value.is_finite() {
                return self.err(
                    x.span(),
                    format!("axis {axis}: `{field}` has the non-finite number {value}"),
                );
            }
        }
        let (lo, hi) = (v[0].get_ref().0, v[1].get_ref().0);
        if lo >= hi {
            return self.err(
                s.span(),
                format!("axis {axis}: `{field}` minimum {lo} is not below maximum {hi} ({unit})"),
            );
        }
        Ok([lo, hi])
    }
}
