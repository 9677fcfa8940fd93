//! Numbers and sizes in a machine description: symbol defaults, offsets, strokes and ranges
//! (finite, within the bounds of [`crate::limits`]), and the counts of symbols, axes, links,
//! sub-models and terms.

use super::{Res, Span, Validator};
use crate::limits::{
    MAX_AXES, MAX_LENGTH_MM, MAX_LINKS, MAX_MODELS, MAX_RANGE_DEG, MAX_SYMBOLS, MIN_STROKE_MM,
};
use crate::raw::{Num, RawMachine};
use toml::Spanned;

/// The unit people write a command limit in.
fn limit_unit(field: &str) -> &'static str {
    if field == "range" { "degrees" } else { "mm" }
}

/// A number for a message about its size: as written for ordinary values (`-217.504`), in
/// scientific notation when it is very large or very small (`1e308`, `1e-7`).
pub(super) fn written(x: f64) -> String {
    if x != 0.0 && x.is_finite() && !(1e-6..1e9).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// Why a length is refused: the bound and what it is.
fn length_bound() -> String {
    format!(
        "beyond ±{} mm (100 m), the largest length of a machine description",
        written(MAX_LENGTH_MM)
    )
}

impl Validator<'_> {
    /// The default of symbol `k` (mm): a finite number within ±[`MAX_LENGTH_MM`].
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
        if x.abs() > MAX_LENGTH_MM {
            return self.err(
                v.span(),
                format!(
                    "symbol `{}` has the default {} mm, {}",
                    k.get_ref(),
                    written(x),
                    length_bound()
                ),
            );
        }
        Ok(x)
    }

    /// A number of an offset (mm): finite, within ±[`MAX_LENGTH_MM`].
    pub(super) fn offset_number(&self, x: f64, span: Span) -> Res<f64> {
        if !x.is_finite() {
            return self.err(span, format!("`offset` has the non-finite number {x}"));
        }
        if x.abs() > MAX_LENGTH_MM {
            return self.err(
                span,
                format!(
                    "`offset` has the number {} mm, {}",
                    written(x),
                    length_bound()
                ),
            );
        }
        Ok(x)
    }

    /// The `stroke` (mm) or `range` (degrees) of an axis: two finite numbers, min below max,
    /// a stroke within ±[`MAX_LENGTH_MM`] and at least [`MIN_STROKE_MM`] long, a range
    /// within ±[`MAX_RANGE_DEG`].
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
            if field == "range" && value.abs() > MAX_RANGE_DEG {
                return self.err(
                    x.span(),
                    format!(
                        "axis {axis}: `range` has the number {} degrees, beyond ±{} degrees (ten turns), the largest range of a rotary axis; leave `range` out for an axis that turns without limit",
                        written(value),
                        written(MAX_RANGE_DEG)
                    ),
                );
            }
            if field == "stroke" && value.abs() > MAX_LENGTH_MM {
                return self.err(
                    x.span(),
                    format!(
                        "axis {axis}: `stroke` has the number {} mm, {}",
                        written(value),
                        length_bound()
                    ),
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
        if field == "stroke" && hi - lo < MIN_STROKE_MM {
            return self.err(
                s.span(),
                format!(
                    "axis {axis}: `stroke` is {} mm long, shorter than {} mm (1 µm), the shortest stroke of a linear axis",
                    written(hi - lo),
                    written(MIN_STROKE_MM)
                ),
            );
        }
        Ok([lo, hi])
    }

    /// The counts of symbols, axes, fixed links and sub-models are within [`MAX_SYMBOLS`],
    /// [`MAX_AXES`], [`MAX_LINKS`] and [`MAX_MODELS`]. Each message points at the first entry
    /// past the limit: symbols and sub-models in the order of the file, axes and links in the
    /// order of the machine (the work chain first).
    pub(super) fn counts(&self, raw: &RawMachine) -> Res<()> {
        let in_file_order = |mut spans: Vec<Span>| {
            spans.sort_by_key(|s| s.start);
            spans
        };
        let symbols = in_file_order(raw.symbols.keys().map(Spanned::span).collect());
        self.count(&symbols, MAX_SYMBOLS, "symbols", "a machine may declare")?;
        let entries: Vec<_> = [&raw.work, &raw.tool]
            .into_iter()
            .flatten()
            .flat_map(|chain| chain.get_ref())
            .map(Spanned::get_ref)
            .collect();
        let axes: Vec<Span> = entries
            .iter()
            .filter_map(|e| e.axis.as_ref().map(Spanned::span))
            .collect();
        self.count(&axes, MAX_AXES, "axes", "a machine may have")?;
        let links: Vec<Span> = entries
            .iter()
            .filter_map(|e| e.link.as_ref().map(Spanned::span))
            .collect();
        self.count(&links, MAX_LINKS, "fixed links", "a machine may have")?;
        let models = in_file_order(raw.models.keys().map(Spanned::span).collect());
        self.count(&models, MAX_MODELS, "sub-models", "a machine may have")
    }

    /// At most `limit` of the `what` at `spans`; the message points at the first one past the
    /// limit.
    fn count(&self, spans: &[Span], limit: usize, what: &str, who: &str) -> Res<()> {
        match spans.get(limit) {
            None => Ok(()),
            Some(first_past) => self.err(
                first_past.clone(),
                format!(
                    "the description has {} {what}, more than {limit}, the most {who}",
                    spans.len()
                ),
            ),
        }
    }
}
