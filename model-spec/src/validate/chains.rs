//! The two kinematic chains and their axes.

use super::{Res, Span, Validator};
use crate::geometry::{AxisDirection, Direction};
use crate::machine::{Axis, AxisKind, Chain, Link, Offset, Side, Symbol, Value};
use crate::raw::{Num, RawDirection};
use crate::raw::{RawLink, RawValue};
use toml::Spanned;

impl Validator<'_> {
    /// The chain on `side`; its axes are appended to `axes` (their names' spans to
    /// `axis_spans`).
    pub(super) fn chain(
        &self,
        raw: &Option<Spanned<Vec<Spanned<RawLink>>>>,
        side: Side,
        (machine_name, name_span): (&str, &Span),
        symbols: &[Symbol],
        axes: &mut Vec<Axis>,
        axis_spans: &mut Vec<Span>,
    ) -> Res<Chain> {
        let (table, end_word) = match side {
            Side::Work => ("work", "workpiece point (the R-test ball)"),
            Side::Tool => ("tool", "tool point (the R-test sensor nest)"),
        };
        let Some(entries) = raw else {
            return self.err(
                name_span.clone(),
                format!(
                    "machine `{machine_name}` has no [[{table}]] chain: describe the chain from the bed to the {end_word} with [[{table}]] entries, the last one with `end = \"...\"`"
                ),
            );
        };
        let mut links = Vec::new();
        let mut end: Option<(String, Offset, Span)> = None;
        for entry in entries.get_ref() {
            let e = entry.get_ref();
            if let Some((_, _, end_span)) = &end {
                return self.err(
                    entry.span(),
                    format!(
                        "[[{table}]] entry after the `end` entry of line {}: the `end` entry must be the last of the chain",
                        self.line(end_span)
                    ),
                );
            }
            let mut roles: Vec<(&str, Span)> =
                [("axis", &e.axis), ("link", &e.link), ("end", &e.end)]
                    .into_iter()
                    .filter_map(|(k, v)| v.as_ref().map(|v| (k, v.span())))
                    .collect();
            // In the order they are written: the message points at the second one.
            roles.sort_by_key(|(_, span)| span.start);
            match roles.as_slice() {
                [] => {
                    return self.err(
                        entry.span(),
                        format!(
                            "this [[{table}]] entry has none of `axis`, `link` or `end`: each entry is an axis, a fixed link or the end of the chain"
                        ),
                    );
                }
                [_] => {}
                [(first, _), (second, span), ..] => {
                    return self.err(
                        span.clone(),
                        format!(
                            "this [[{table}]] entry has both `{first}` and `{second}`: each entry is one axis, one fixed link or the end of the chain; split it"
                        ),
                    );
                }
            }
            let offset = self.offset(&e.offset, symbols)?;
            if let Some(name) = &e.axis {
                let axis = self.axis(e, name, offset, side, axes, axis_spans)?;
                axes.push(axis);
                axis_spans.push(name.span());
                links.push(Link::Axis(axes.len() - 1));
            } else {
                let role = roles[0].0;
                for (field, present) in [
                    ("type", e.kind.as_ref().map(Spanned::span)),
                    ("direction", e.direction.as_ref().map(Spanned::span)),
                    ("stroke", e.stroke.as_ref().map(Spanned::span)),
                    ("range", e.range.as_ref().map(Spanned::span)),
                ] {
                    if let Some(span) = present {
                        return self.err(
                            span,
                            format!("`{field}` belongs to an axis, not to a `{role}` entry"),
                        );
                    }
                }
                if let Some(l) = &e.link {
                    self.name_length("link name", l)?;
                    links.push(Link::Fixed {
                        name: l.get_ref().clone(),
                        offset,
                    });
                } else if let Some(n) = &e.end {
                    self.name_length("end name", n)?;
                    end = Some((n.get_ref().clone(), offset, entry.span()));
                }
            }
        }
        let Some((end_name, end_offset, _)) = end else {
            let at = entries
                .get_ref()
                .last()
                .map_or_else(|| entries.span(), Spanned::span);
            return self.err(
                at,
                format!(
                    "the [[{table}]] chain has no `end` entry: add a last [[{table}]] entry with `end = \"...\"` and the offset of the {end_word}"
                ),
            );
        };
        Ok(Chain {
            links,
            end_name,
            end_offset,
        })
    }

    fn axis(
        &self,
        e: &RawLink,
        name: &Spanned<String>,
        offset: Offset,
        side: Side,
        axes: &[Axis],
        axis_spans: &[Span],
    ) -> Res<Axis> {
        let n = self.axis_name(name, axes, axis_spans)?;
        let Some(kind_s) = &e.kind else {
            return self.err(
                name.span(),
                format!("axis {n} has no `type`: add `type = \"linear\"` or `type = \"rotary\"`"),
            );
        };
        let kind = match kind_s.get_ref().as_str() {
            "linear" => AxisKind::Linear,
            "rotary" => AxisKind::Rotary,
            other => {
                return self.err(
                    kind_s.span(),
                    format!("axis {n}: unknown type `{other}` (\"linear\" or \"rotary\")"),
                );
            }
        };
        let Some(dir_s) = &e.direction else {
            return self.err(
                name.span(),
                format!(
                    "axis {n} has no `direction`: add `direction = \"+x\"` (or -x, +y, -y, +z, -z)"
                ),
            );
        };
        let direction = match dir_s.get_ref() {
            RawDirection::Text(t) => match Direction::parse(t) {
                Some(d) => AxisDirection::coordinate(d),
                None => {
                    return self.err(
                        dir_s.span(),
                        format!(
                            "axis {n}: direction `{t}` is not one of +x -x +y -y +z -z (or a vector such as [0, 1, 1])"
                        ),
                    );
                }
            },
            RawDirection::Vector(v) => {
                let parsed = <[Num; 3]>::try_from(v.as_slice())
                    .ok()
                    .and_then(|v| AxisDirection::from_vector(v.map(|x| x.0)));
                match parsed {
                    Some(d) => d,
                    None => {
                        return self.err(
                            dir_s.span(),
                            format!(
                                "axis {n}: a direction vector needs three finite numbers, not all zero (e.g. [0, 1, 1])"
                            ),
                        );
                    }
                }
            }
        };
        if kind == AxisKind::Rotary && n == "W" {
            return self.err(
                name.span(),
                "a rotary axis cannot be called W: XOW YOW ZOW are the workpiece set-up errors",
            );
        }
        let limits = match kind {
            AxisKind::Linear => {
                if let Some(r) = &e.range {
                    return self.err(
                        r.span(),
                        format!("linear axis {n} takes `stroke = [min, max]` (mm), not `range`"),
                    );
                }
                let Some(s) = &e.stroke else {
                    return self.err(
                        name.span(),
                        format!("linear axis {n} has no `stroke = [min, max]` (mm)"),
                    );
                };
                self.limits(s, &n, "stroke")?
            }
            AxisKind::Rotary => {
                if let Some(s) = &e.stroke {
                    return self.err(
                        s.span(),
                        format!(
                            "rotary axis {n} takes `range = [min, max]` (degrees), not `stroke`"
                        ),
                    );
                }
                match &e.range {
                    Some(r) => self.limits(r, &n, "range")?,
                    None => [f64::NEG_INFINITY, f64::INFINITY],
                }
            }
        };
        Ok(Axis {
            name: n,
            kind,
            direction,
            offset,
            limits,
            side,
        })
    }

    fn offset(
        &self,
        raw: &Option<Spanned<Vec<Spanned<RawValue>>>>,
        symbols: &[Symbol],
    ) -> Res<Offset> {
        let Some(raw) = raw else {
            return Ok([Value::Number(0.0); 3]);
        };
        let v = raw.get_ref();
        if v.len() != 3 {
            return self.err(
                raw.span(),
                format!(
                    "`offset` needs three entries [x, y, z] (numbers in mm or symbol names), found {}",
                    v.len()
                ),
            );
        }
        let mut out = [Value::Number(0.0); 3];
        for (slot, item) in out.iter_mut().zip(v) {
            *slot = match item.get_ref() {
                RawValue::Number(x) => Value::Number(self.offset_number(*x, item.span())?),
                RawValue::Name(s) => match symbols.iter().position(|sym| &sym.name == s) {
                    Some(i) => Value::Symbol(i),
                    None => {
                        return self.err(
                            item.span(),
                            format!(
                                "unknown symbol `{s}`: declare it under [symbols] with its default (mm)"
                            ),
                        );
                    }
                },
            };
        }
        Ok(out)
    }
}
