//! From the TOML text to a validated [`Machine`], with errors that name file, line and column.

use crate::basis::Basis;
use crate::catalogue::{
    ErrorId, ErrorKind, ErrorTerm, Motion, component_name, iso_rank, location_motions,
    location_name, six_motions, squareness_rotations,
};
use crate::error::SpecError;
use crate::geometry::{Dir, Direction};
use crate::locate::Locator;
use crate::machine::{
    Axis, AxisId, AxisKind, Chain, FULL_MODEL, Link, Machine, Offset, Side, SubModel, Symbol, Value,
};
use crate::raw::{Num, RawErrors, RawLink, RawMachine, RawValue};
use crate::terms::{Effect, Term};
use std::collections::BTreeMap;
use toml::Spanned;

/// Reads and validates a machine description. `file` names the source in error messages.
///
/// Every problem is reported as a [`SpecError`] whose line and column point at the offending
/// value or key (see `docs/model-spec.md` for the list of messages). No input panics.
pub fn parse_machine(file: &str, text: &str) -> Result<Machine, SpecError> {
    let loc = Locator { file, text };
    let raw: RawMachine = toml::from_str(text).map_err(|e| {
        let span = e.span().unwrap_or(0..0);
        loc.error(span, e.message().trim().to_string())
    })?;
    Validator { loc: &loc }.machine(raw)
}

/// The names a machine reserves for the commands of an axis in formulas: the linear command
/// `Xm`, or the sine and cosine `Sa`, `Ca` of a rotary command. A kinematic symbol may not take
/// one of these names.
pub fn reserved_names(axis: &str, kind: AxisKind) -> Vec<String> {
    match kind {
        AxisKind::Linear => vec![format!("{axis}m")],
        AxisKind::Rotary => {
            let l = axis.to_ascii_lowercase();
            vec![format!("S{l}"), format!("C{l}")]
        }
    }
}

struct Validator<'a> {
    loc: &'a Locator<'a>,
}

type Res<T> = Result<T, SpecError>;
type Span = std::ops::Range<usize>;

fn is_identifier(s: &str) -> bool {
    let mut c = s.chars();
    matches!(c.next(), Some(ch) if ch.is_ascii_alphabetic())
        && c.all(|ch| ch.is_ascii_alphanumeric() || ch == '_')
}

/// Rust's strict and reserved keywords (2024 edition): generated code uses symbol names as
/// field names and model names as module names, so neither may be one of these.
const RUST_KEYWORDS: &[&str] = &[
    "Self", "abstract", "as", "async", "await", "become", "box", "break", "const", "continue",
    "crate", "do", "dyn", "else", "enum", "extern", "false", "final", "fn", "for", "gen", "if",
    "impl", "in", "let", "loop", "macro", "match", "mod", "move", "mut", "override", "priv", "pub",
    "ref", "return", "self", "static", "struct", "super", "trait", "true", "try", "type", "typeof",
    "unsafe", "unsized", "use", "virtual", "where", "while", "yield",
];

fn is_rust_keyword(s: &str) -> bool {
    RUST_KEYWORDS.contains(&s)
}

fn join<'a>(names: impl IntoIterator<Item = &'a str>) -> String {
    names.into_iter().collect::<Vec<_>>().join(" ")
}

/// The unit people write a command limit in.
fn limit_unit(field: &str) -> &'static str {
    if field == "range" { "degrees" } else { "mm" }
}

impl Validator<'_> {
    fn err<T>(&self, span: Span, msg: impl Into<String>) -> Res<T> {
        Err(self.loc.error(span, msg))
    }

    fn line(&self, span: &Span) -> usize {
        self.loc.line_col(span.start).0
    }

    fn machine(&self, raw: RawMachine) -> Res<Machine> {
        let Some(raw_name) = &raw.name else {
            return self.err(
                0..0,
                "no `name = \"...\"` at the top of the file: every machine needs a short name",
            );
        };
        let name = raw_name.get_ref().trim().to_string();
        if name.is_empty()
            || !name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
        {
            return self.err(
                raw_name.span(),
                format!("machine name `{name}` must be letters, digits, `-` or `_`"),
            );
        }

        // Checked and kept in the order of the file, not the order of the map.
        let mut raw_symbols: Vec<(&Spanned<String>, &Spanned<Num>)> = raw.symbols.iter().collect();
        raw_symbols.sort_by_key(|(k, _)| k.span().start);
        let mut symbols = Vec::new();
        for &(k, v) in &raw_symbols {
            if !is_identifier(k.get_ref()) {
                return self.err(
                    k.span(),
                    format!(
                        "symbol name `{}` is not an identifier (a letter, then letters, digits or `_`)",
                        k.get_ref()
                    ),
                );
            }
            if is_rust_keyword(k.get_ref()) {
                return self.err(
                    k.span(),
                    format!(
                        "symbol name `{}` is a Rust keyword (generated code uses symbol names as field names): rename it",
                        k.get_ref()
                    ),
                );
            }
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
            symbols.push(Symbol {
                name: k.get_ref().clone(),
                default: x,
            });
        }

        let mut axes: Vec<Axis> = Vec::new();
        let mut axis_spans: Vec<Span> = Vec::new();
        let name_span = raw_name.span();
        let work = self.chain(
            &raw.work,
            Side::Work,
            (&name, &name_span),
            &symbols,
            &mut axes,
            &mut axis_spans,
        )?;
        let tool = self.chain(
            &raw.tool,
            Side::Tool,
            (&name, &name_span),
            &symbols,
            &mut axes,
            &mut axis_spans,
        )?;

        for &(k, _) in &raw_symbols {
            for a in &axes {
                if reserved_names(&a.name, a.kind).contains(k.get_ref()) {
                    let what = match a.kind {
                        AxisKind::Linear => "the command",
                        AxisKind::Rotary => "the sine and cosine of the command",
                    };
                    return self.err(
                        k.span(),
                        format!(
                            "symbol `{}` is reserved for {what} of axis {} in formulas: rename the symbol",
                            k.get_ref(),
                            a.name
                        ),
                    );
                }
            }
        }

        let squareness_order = self.squareness_order(&raw.errors, &axes)?;
        let catalogue = build_catalogue(&axes, &squareness_order);
        for &(k, _) in &raw_symbols {
            if catalogue.iter().any(|e| e.name == *k.get_ref()) {
                return self.err(
                    k.span(),
                    format!(
                        "symbol `{}` has the name of an error of this machine: rename the symbol",
                        k.get_ref()
                    ),
                );
            }
        }
        let mut machine = Machine {
            name,
            description: raw.description.trim().to_string(),
            symbols,
            axes,
            work,
            tool,
            catalogue,
            errors: Vec::new(),
            models: BTreeMap::new(),
            squareness_order,
        };
        machine.errors = self.model_errors(&raw.errors, &machine)?;
        let mut raw_models: Vec<_> = raw.models.iter().collect();
        raw_models.sort_by_key(|(name, _)| name.span().start);
        for (name, model) in raw_models {
            let n = name.get_ref();
            if n == FULL_MODEL {
                return self.err(
                    name.span(),
                    format!(
                        "model name `{FULL_MODEL}` is reserved for the machine's own error list ([errors]); choose another name"
                    ),
                );
            }
            if !is_identifier(n) {
                return self.err(
                    name.span(),
                    format!(
                        "model name `{n}` is not an identifier (a letter, then letters, digits or `_`)"
                    ),
                );
            }
            if is_rust_keyword(n) {
                return self.err(
                    name.span(),
                    format!(
                        "model name `{n}` is a Rust keyword (generated code uses model names as module names): choose another name"
                    ),
                );
            }
            let Some(list) = &model.get_ref().errors else {
                return self.err(
                    model.span(),
                    format!("model `{n}` has no `errors = [...]` list"),
                );
            };
            let (errors, terms) = self.term_list(list, &machine, n)?;
            machine.models.insert(
                n.clone(),
                SubModel {
                    description: model.get_ref().description.trim().to_string(),
                    errors,
                    terms,
                },
            );
        }
        Ok(machine)
    }

    fn chain(
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
                    links.push(Link::Fixed {
                        name: l.get_ref().clone(),
                        offset,
                    });
                } else if let Some(n) = &e.end {
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
        let n = name.get_ref().trim().to_string();
        let mut cs = n.chars();
        match (cs.next(), cs.next()) {
            (Some('E' | 'O'), None) => {
                return self.err(
                    name.span(),
                    format!(
                        "axis name `{n}` is not allowed: E and O are the letters of the error names (EXX, XOC)"
                    ),
                );
            }
            (Some(c), None) if c.is_ascii_uppercase() => {}
            (Some(c), None) if c.is_ascii_lowercase() && !matches!(c, 'e' | 'o') => {
                return self.err(
                    name.span(),
                    format!(
                        "axis name `{n}` must be upper case: write `{}`",
                        c.to_ascii_uppercase()
                    ),
                );
            }
            _ => {
                return self.err(
                    name.span(),
                    format!(
                        "axis name `{n}` must be one upper-case letter other than E and O (X, Y, Z, A, B, C, …)"
                    ),
                );
            }
        }
        if let Some(first) = axes.iter().position(|a| a.name == n) {
            return self.err(
                name.span(),
                format!(
                    "axis letter `{n}` is used twice (first on line {}): every axis of the machine needs its own letter",
                    self.line(&axis_spans[first])
                ),
            );
        }
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
        let Some(direction) = Direction::parse(dir_s.get_ref()) else {
            return self.err(
                dir_s.span(),
                format!(
                    "axis {n}: direction `{}` is not one of +x -x +y -y +z -z",
                    dir_s.get_ref()
                ),
            );
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

    fn limits(&self, s: &Spanned<Vec<Spanned<Num>>>, axis: &str, field: &str) -> Res<[f64; 2]> {
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
                RawValue::Number(x) if x.is_finite() => Value::Number(*x),
                RawValue::Number(x) => {
                    return self.err(
                        item.span(),
                        format!("`offset` has the non-finite number {x}"),
                    );
                }
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

    fn squareness_order(&self, raw: &RawErrors, axes: &[Axis]) -> Res<Vec<AxisId>> {
        let linear: Vec<AxisId> = (0..axes.len())
            .filter(|&i| axes[i].kind == AxisKind::Linear)
            .collect();
        if let Some(list) = &raw.squareness_order {
            let mut order = Vec::new();
            for item in list.get_ref() {
                let Some(i) = axes.iter().position(|a| &a.name == item.get_ref()) else {
                    return self.err(
                        item.span(),
                        format!(
                            "unknown axis `{}` in squareness_order (the linear axes are {})",
                            item.get_ref(),
                            join(linear.iter().map(|&i| axes[i].name.as_str()))
                        ),
                    );
                };
                if axes[i].kind != AxisKind::Linear {
                    return self.err(
                        item.span(),
                        format!(
                            "squareness_order lists rotary axis {}: only linear axes have squareness errors",
                            axes[i].name
                        ),
                    );
                }
                if order.contains(&i) {
                    return self.err(
                        item.span(),
                        format!("axis {} twice in squareness_order", axes[i].name),
                    );
                }
                order.push(i);
            }
            if let Some(&missing) = linear.iter().find(|i| !order.contains(i)) {
                return self.err(
                    list.span(),
                    format!(
                        "squareness_order misses linear axis {}: it must list every linear axis once",
                        axes[missing].name
                    ),
                );
            }
            return Ok(order);
        }
        Ok(default_squareness_order(axes))
    }

    /// The error ids of a list of names (the `[errors] include` list), in catalogue order.
    fn error_list(&self, list: &Spanned<Vec<Spanned<String>>>, m: &Machine) -> Res<Vec<ErrorId>> {
        let mut ids: Vec<(ErrorId, Span)> = Vec::new();
        for item in list.get_ref() {
            let id = self.error_id(item, m)?;
            if let Some((_, first)) = ids.iter().find(|(i, _)| *i == id) {
                return self.err(
                    item.span(),
                    format!(
                        "error {} is listed twice (first on line {})",
                        spelled(item.get_ref(), &m.catalogue[id].name),
                        self.line(first)
                    ),
                );
            }
            ids.push((id, item.span()));
        }
        let mut ids: Vec<ErrorId> = ids.into_iter().map(|(i, _)| i).collect();
        ids.sort_unstable();
        Ok(ids)
    }

    fn error_id(&self, item: &Spanned<String>, m: &Machine) -> Res<ErrorId> {
        self.error_id_at(item.get_ref(), item.span(), m)
    }

    /// The error called `written` (located at `span` for the message).
    fn error_id_at(&self, written: &str, span: Span, m: &Machine) -> Res<ErrorId> {
        if let Some(id) = m.error_by_name(written) {
            return Ok(id);
        }
        let canonical = crate::catalogue::canonical_name(written);
        let axis_names = join(m.axes.iter().map(|a| a.name.as_str()));
        let hint = match canonical.chars().count() {
            3 => {
                let last = canonical.chars().last().unwrap_or(' ').to_string();
                let mut own: Vec<&str> = m
                    .catalogue
                    .iter()
                    .filter(|e| e.axis().is_some_and(|a| m.axes[a].name == last))
                    .map(|e| e.name.as_str())
                    .collect();
                let what = if last == "W" {
                    own.extend(
                        m.catalogue
                            .iter()
                            .filter(|e| matches!(e.kind, ErrorKind::Setup { .. }))
                            .map(|e| e.name.as_str()),
                    );
                    if m.axis_by_name("W").is_some() {
                        "axis W and the workpiece"
                    } else {
                        "the workpiece"
                    }
                } else {
                    "axis"
                };
                if own.is_empty() {
                    format!("the machine has no axis {last} (axes {axis_names})")
                } else if what == "axis" {
                    format!("the errors of axis {last} are {}", join(own))
                } else {
                    format!("the errors of {what} are {}", join(own))
                }
            }
            _ => format!(
                "ISO 230 names have three letters: E<motion><axis>, <motion>O<axis> or XOW YOW ZOW (axes {axis_names})"
            ),
        };
        self.err(
            span,
            format!("error `{written}` does not exist for this machine: {hint}"),
        )
    }

    /// The terms of a sub-model's list: `NAME` (constant) or `NAME@BASIS`, `NAME` an error of
    /// the machine's full model or `dx0 dy0 dz0`. Returns the errors used (catalogue order, each
    /// once) and the terms in the order written.
    fn term_list(
        &self,
        list: &Spanned<Vec<Spanned<String>>>,
        m: &Machine,
        model: &str,
    ) -> Res<(Vec<ErrorId>, Vec<Term>)> {
        let mut terms: Vec<(Term, Span)> = Vec::new();
        for item in list.get_ref() {
            let written = item.get_ref().trim();
            let (name, basis) = match written.split_once('@') {
                Some((n, b)) => (n.trim(), Some(b.trim())),
                None => (written, None),
            };
            let effect = match Effect::parse_offset(name) {
                Some(e) => e,
                None => {
                    let id = self.error_id_at(name, item.span(), m)?;
                    if !m.errors.contains(&id) {
                        return self.err(
                            item.span(),
                            format!(
                                "model `{model}`: error {} is not in the machine's full model (it is left out by [errors] include/exclude)",
                                spelled(name, &m.catalogue[id].name),
                            ),
                        );
                    }
                    Effect::Error(id)
                }
            };
            let basis = match basis {
                None => Basis::Const,
                Some(b) => Basis::parse(b)
                    .or_else(|e| self.err(item.span(), format!("model `{model}`: {}", e.0)))?,
            };
            let term = Term::new(m, effect, basis).or_else(|e| {
                self.err(
                    item.span(),
                    format!("model `{model}`: {}: {}", effect.name(m), e.0),
                )
            })?;
            if let Some((_, first)) = terms.iter().find(|(t, _)| *t == term) {
                let what = match (effect, basis) {
                    (Effect::Error(id), Basis::Const) if !written.contains('@') => {
                        format!("error {}", spelled(name, &m.catalogue[id].name))
                    }
                    _ => format!("model `{model}`: term `{written}`"),
                };
                return self.err(
                    item.span(),
                    format!(
                        "{what} is listed twice (first on line {})",
                        self.line(first)
                    ),
                );
            }
            terms.push((term, item.span()));
        }
        let terms: Vec<Term> = terms.into_iter().map(|(t, _)| t).collect();
        let mut errors: Vec<ErrorId> = terms
            .iter()
            .filter_map(|t| match t.effect {
                Effect::Error(e) => Some(e),
                Effect::SensorOffset(_) => None,
            })
            .collect();
        errors.sort_unstable();
        errors.dedup();
        Ok((errors, terms))
    }

    fn model_errors(&self, raw: &RawErrors, m: &Machine) -> Res<Vec<ErrorId>> {
        let mut errors: Vec<ErrorId> = match &raw.include {
            Some(list) => self.error_list(list, m)?,
            None => (0..m.catalogue.len()).collect(),
        };
        if let Some(exclude) = &raw.exclude {
            let mut seen: Vec<(ErrorId, Span)> = Vec::new();
            for item in exclude.get_ref() {
                let id = self.error_id(item, m)?;
                if let Some((_, first)) = seen.iter().find(|(i, _)| *i == id) {
                    return self.err(
                        item.span(),
                        format!(
                            "error {} is excluded twice (first on line {})",
                            spelled(item.get_ref(), &m.catalogue[id].name),
                            self.line(first)
                        ),
                    );
                }
                seen.push((id, item.span()));
                errors.retain(|&e| e != id);
            }
        }
        Ok(errors)
    }
}

/// An error name as written, with its canonical spelling when it differs (`X0C` (XOC)).
fn spelled(written: &str, canonical: &str) -> String {
    if written == canonical {
        format!("`{written}`")
    } else {
        format!("`{written}` ({canonical})")
    }
}

/// The default squareness order of the linear axes: by depth among the linear axes of their
/// chain (the first linear axis from the bed has depth 0), the tool chain first on equal depth,
/// then by ISO letter order. For the seed machine (work X; tool Y, Z) this is Y, X, Z.
pub fn default_squareness_order(axes: &[Axis]) -> Vec<AxisId> {
    let depth = |id: AxisId| {
        (0..id)
            .filter(|&j| axes[j].kind == AxisKind::Linear && axes[j].side == axes[id].side)
            .count()
    };
    let mut order: Vec<AxisId> = (0..axes.len())
        .filter(|&i| axes[i].kind == AxisKind::Linear)
        .collect();
    order.sort_by_key(|&i| {
        let side_rank = match axes[i].side {
            Side::Tool => 0,
            Side::Work => 1,
        };
        (depth(i), side_rank, iso_rank(&axes[i].name))
    });
    order
}

/// Every ISO 230 error of the topology, in canonical order (see [`crate::catalogue`]).
pub fn build_catalogue(axes: &[Axis], squareness_order: &[AxisId]) -> Vec<ErrorTerm> {
    let mut by_iso: Vec<AxisId> = (0..axes.len()).collect();
    by_iso.sort_by_key(|&i| iso_rank(&axes[i].name));
    let mut out = Vec::new();
    let component = |i: AxisId, out: &mut Vec<ErrorTerm>| {
        for motion in six_motions() {
            out.push(ErrorTerm {
                name: component_name(motion, &axes[i].name),
                kind: ErrorKind::Component { axis: i, motion },
            });
        }
    };
    for &i in by_iso.iter().filter(|&&i| axes[i].kind == AxisKind::Linear) {
        component(i, &mut out);
    }
    if let Some(&first) = squareness_order.first() {
        let reference = axes[first].direction.dir;
        for (rank, &i) in squareness_order.iter().enumerate() {
            for about in squareness_rotations(rank, axes[i].direction.dir, reference) {
                out.push(ErrorTerm {
                    name: location_name(Motion::Rotation(about), &axes[i].name),
                    kind: ErrorKind::Squareness { axis: i, about },
                });
            }
        }
    }
    for along in Dir::ALL {
        out.push(ErrorTerm {
            name: format!("{}OW", along.translation_letter()),
            kind: ErrorKind::Setup { along },
        });
    }
    for &i in by_iso.iter().filter(|&&i| axes[i].kind == AxisKind::Rotary) {
        component(i, &mut out);
        for motion in location_motions(axes[i].direction.dir) {
            out.push(ErrorTerm {
                name: location_name(motion, &axes[i].name),
                kind: ErrorKind::Location { axis: i, motion },
            });
        }
    }
    debug_assert!({
        let mut names: Vec<_> = out.iter().map(|e| e.name.clone()).collect();
        names.sort();
        names.windows(2).all(|w| w[0] != w[1])
    });
    out
}
