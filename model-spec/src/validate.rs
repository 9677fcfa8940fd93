//! From the TOML text to a validated [`Machine`], with errors that name file, line and column.

use crate::catalogue::{
    ErrorKind, ErrorTerm, Motion, component_name, iso_rank, location_motions, location_name,
    six_motions, squareness_rotations,
};
use crate::error::{Locator, SpecError};
use crate::geometry::{Dir, Direction};
use crate::machine::{
    Axis, AxisId, AxisKind, Chain, FULL_MODEL, Link, Machine, Offset, Side, SubModel, Symbol, Value,
};
use crate::raw::{RawErrors, RawLink, RawMachine, RawValue};
use std::collections::{BTreeMap, HashMap};
use toml::Spanned;

/// Reads and validates a machine description. `file` names the source in error messages.
pub fn parse_machine(file: &str, text: &str) -> Result<Machine, SpecError> {
    let loc = Locator { file, text };
    let raw: RawMachine = toml::from_str(text).map_err(|e| {
        let span = e.span().unwrap_or(0..0);
        loc.error(span, e.message().trim().to_string())
    })?;
    Validator { loc: &loc }.machine(raw)
}

/// The names a machine reserves for the commands of an axis in formulas: the linear command
/// `Xm`, or the sine and cosine `Sa`, `Ca` of a rotary command.
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

fn is_identifier(s: &str) -> bool {
    let mut c = s.chars();
    matches!(c.next(), Some(ch) if ch.is_ascii_alphabetic())
        && c.all(|ch| ch.is_ascii_alphanumeric() || ch == '_')
}

impl Validator<'_> {
    fn err<T>(&self, span: std::ops::Range<usize>, msg: impl Into<String>) -> Res<T> {
        Err(self.loc.error(span, msg))
    }

    fn machine(&self, raw: RawMachine) -> Res<Machine> {
        let name = raw.name.get_ref().trim().to_string();
        if name.is_empty()
            || !name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
        {
            return self.err(
                raw.name.span(),
                format!("machine name `{name}` must be letters, digits, `-` or `_`"),
            );
        }

        let mut symbols = Vec::new();
        for (k, v) in &raw.symbols {
            if !is_identifier(k.get_ref()) {
                return self.err(
                    k.span(),
                    format!("symbol name `{}` is not an identifier", k.get_ref()),
                );
            }
            if !v.get_ref().is_finite() {
                return self.err(
                    v.span(),
                    format!("symbol `{}` has a non-finite default", k.get_ref()),
                );
            }
            symbols.push(Symbol {
                name: k.get_ref().clone(),
                default: *v.get_ref(),
            });
        }
        // Keep the order of the file, not the order of the map.
        symbols.sort_by_key(|s| {
            raw.symbols
                .keys()
                .find(|k| k.get_ref() == &s.name)
                .map(|k| k.span().start)
        });

        let mut axes: Vec<Axis> = Vec::new();
        let mut axis_spans: Vec<std::ops::Range<usize>> = Vec::new();
        let work = self.chain(&raw.work, Side::Work, &symbols, &mut axes, &mut axis_spans)?;
        let tool = self.chain(&raw.tool, Side::Tool, &symbols, &mut axes, &mut axis_spans)?;

        for a in &axes {
            for reserved in reserved_names(&a.name, a.kind) {
                if let Some(k) = raw.symbols.keys().find(|k| *k.get_ref() == reserved) {
                    return self.err(
                        k.span(),
                        format!(
                            "symbol `{reserved}` is reserved for the command of axis {}",
                            a.name
                        ),
                    );
                }
            }
        }

        let squareness_order = self.squareness_order(&raw.errors, &axes, &work, &tool)?;
        let catalogue = build_catalogue(&axes, &squareness_order);
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
        for (name, model) in &raw.models {
            let n = name.get_ref();
            if n == FULL_MODEL || !is_identifier(n) {
                return self.err(
                    name.span(),
                    format!("model name `{n}` is reserved or not an identifier"),
                );
            }
            let errors = self.error_list(&model.errors, &machine, Some(&machine.errors))?;
            machine.models.insert(
                n.clone(),
                SubModel {
                    description: model.description.trim().to_string(),
                    errors,
                },
            );
        }
        Ok(machine)
    }

    fn chain(
        &self,
        raw: &Option<Spanned<Vec<Spanned<RawLink>>>>,
        side: Side,
        symbols: &[Symbol],
        axes: &mut Vec<Axis>,
        axis_spans: &mut Vec<std::ops::Range<usize>>,
    ) -> Res<Chain> {
        let (table, end_word) = match side {
            Side::Work => ("work", "workpiece"),
            Side::Tool => ("tool", "tool"),
        };
        let Some(entries) = raw else {
            return self.err(
                0..0,
                format!("no [[{table}]] chain: describe the {table} chain from the bed to its {end_word} end"),
            );
        };
        let mut links = Vec::new();
        let mut end = None;
        for entry in entries.get_ref() {
            let e = entry.get_ref();
            if end.is_some() {
                return self.err(
                    entry.span(),
                    format!("[[{table}]] entry after the {end_word} end: the `end` entry must be the last of the chain"),
                );
            }
            let roles = [e.axis.is_some(), e.link.is_some(), e.end.is_some()];
            if roles.iter().filter(|&&r| r).count() != 1 {
                return self.err(
                    entry.span(),
                    format!("each [[{table}]] entry needs exactly one of `axis`, `link` or `end`"),
                );
            }
            let offset = self.offset(&e.offset, symbols)?;
            if let Some(name) = &e.axis {
                let axis = self.axis(e, name, offset, side, axes)?;
                axes.push(axis);
                axis_spans.push(name.span());
                links.push(Link::Axis(axes.len() - 1));
            } else {
                for (field, present) in [
                    ("type", e.kind.as_ref().map(Spanned::span)),
                    ("direction", e.direction.as_ref().map(Spanned::span)),
                    ("stroke", e.stroke.as_ref().map(Spanned::span)),
                    ("range", e.range.as_ref().map(Spanned::span)),
                ] {
                    if let Some(span) = present {
                        return self.err(
                            span,
                            format!("`{field}` belongs to an axis, not to a `link` or `end` entry"),
                        );
                    }
                }
                if let Some(l) = &e.link {
                    links.push(Link::Fixed {
                        name: l.get_ref().clone(),
                        offset,
                    });
                } else if let Some(n) = &e.end {
                    end = Some((n.get_ref().clone(), offset));
                }
            }
        }
        let Some((end_name, end_offset)) = end else {
            return self.err(
                entries.span(),
                format!("the [[{table}]] chain has no {end_word} end: add a last entry with `end = \"...\"` and its offset"),
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
    ) -> Res<Axis> {
        let n = name.get_ref().trim().to_string();
        let mut cs = n.chars();
        let valid = match (cs.next(), cs.next()) {
            (Some(c), None) => c.is_ascii_uppercase() && c != 'E' && c != 'O',
            _ => false,
        };
        if !valid {
            return self.err(
                name.span(),
                format!("axis name `{n}` must be one upper-case letter other than E and O"),
            );
        }
        if axes.iter().any(|a| a.name == n) {
            return self.err(
                name.span(),
                format!("duplicate axis `{n}`: every axis of the machine needs its own letter"),
            );
        }
        let Some(kind_s) = &e.kind else {
            return self.err(
                name.span(),
                format!("axis {n} has no `type` (\"linear\" or \"rotary\")"),
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
                format!("axis {n} has no `direction` (\"+x\", \"-y\", \"z\", …)"),
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
                        format!("linear axis {n} takes `stroke` (mm), not `range`"),
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
                        format!("rotary axis {n} takes `range` (degrees), not `stroke`"),
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

    fn limits(&self, s: &Spanned<Vec<Spanned<f64>>>, axis: &str, field: &str) -> Res<[f64; 2]> {
        let v = s.get_ref();
        if v.len() != 2 {
            return self.err(
                s.span(),
                format!("axis {axis}: `{field}` needs two numbers [min, max]"),
            );
        }
        for x in v {
            if !x.get_ref().is_finite() {
                return self.err(
                    x.span(),
                    format!("axis {axis}: `{field}` has a non-finite number"),
                );
            }
        }
        let (lo, hi) = (*v[0].get_ref(), *v[1].get_ref());
        if lo >= hi {
            return self.err(
                s.span(),
                format!("axis {axis}: `{field}` minimum {lo} is not below maximum {hi}"),
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
                "`offset` needs three entries [x, y, z] (numbers in mm or symbol names)",
            );
        }
        let mut out = [Value::Number(0.0); 3];
        for (slot, item) in out.iter_mut().zip(v) {
            *slot = match item.get_ref() {
                RawValue::Number(x) if x.is_finite() => Value::Number(*x),
                RawValue::Number(_) => {
                    return self.err(item.span(), "non-finite number in `offset`");
                }
                RawValue::Name(s) => match symbols.iter().position(|sym| &sym.name == s) {
                    Some(i) => Value::Symbol(i),
                    None => {
                        return self.err(
                            item.span(),
                            format!("unknown symbol `{s}`: declare it under [symbols] with its default (mm)"),
                        );
                    }
                },
            };
        }
        Ok(out)
    }

    fn squareness_order(
        &self,
        raw: &RawErrors,
        axes: &[Axis],
        work: &Chain,
        tool: &Chain,
    ) -> Res<Vec<AxisId>> {
        let linear: Vec<AxisId> = (0..axes.len())
            .filter(|&i| axes[i].kind == AxisKind::Linear)
            .collect();
        if let Some(list) = &raw.squareness_order {
            let mut order = Vec::new();
            for item in list.get_ref() {
                let Some(i) = axes.iter().position(|a| &a.name == item.get_ref()) else {
                    return self.err(
                        item.span(),
                        format!("unknown axis `{}` in squareness_order", item.get_ref()),
                    );
                };
                if axes[i].kind != AxisKind::Linear {
                    return self.err(item.span(), format!("squareness_order lists rotary axis {}: only linear axes have squareness errors", axes[i].name));
                }
                if order.contains(&i) {
                    return self.err(
                        item.span(),
                        format!("axis {} twice in squareness_order", axes[i].name),
                    );
                }
                order.push(i);
            }
            if order.len() != linear.len() {
                return self.err(
                    list.span(),
                    "squareness_order must list every linear axis once",
                );
            }
            return Ok(order);
        }
        // Default: by depth among the linear axes of its chain, the tool chain first on a tie.
        let depth = |chain: &Chain, id: AxisId| {
            chain
                .links
                .iter()
                .filter_map(|l| match l {
                    Link::Axis(a) if axes[*a].kind == AxisKind::Linear => Some(*a),
                    _ => None,
                })
                .position(|a| a == id)
        };
        let mut order = linear;
        order.sort_by_key(|&i| {
            let (d, side_rank) = match depth(tool, i) {
                Some(d) => (d, 0),
                None => (depth(work, i).unwrap_or(usize::MAX), 1),
            };
            (d, side_rank, iso_rank(&axes[i].name))
        });
        Ok(order)
    }

    fn error_list(
        &self,
        list: &Spanned<Vec<Spanned<String>>>,
        m: &Machine,
        within: Option<&[usize]>,
    ) -> Res<Vec<usize>> {
        let mut ids = Vec::new();
        for item in list.get_ref() {
            let id = self.error_id(item, m)?;
            if ids.contains(&id) {
                return self.err(
                    item.span(),
                    format!("error `{}` listed twice", item.get_ref()),
                );
            }
            if let Some(allowed) = within
                && !allowed.contains(&id)
            {
                return self.err(
                    item.span(),
                    format!(
                        "error `{}` is excluded from the machine's error list",
                        item.get_ref()
                    ),
                );
            }
            ids.push(id);
        }
        ids.sort_unstable();
        Ok(ids)
    }

    fn error_id(&self, item: &Spanned<String>, m: &Machine) -> Res<usize> {
        m.error_by_name(item.get_ref()).ok_or_else(|| {
            self.loc.error(
                item.span(),
                format!(
                    "error `{}` does not exist for this topology (axes {}); see `rtest machines` for the catalogue",
                    item.get_ref(),
                    m.axes.iter().map(|a| a.name.as_str()).collect::<Vec<_>>().join(" ")
                ),
            )
        })
    }

    fn model_errors(&self, raw: &RawErrors, m: &Machine) -> Res<Vec<usize>> {
        let mut errors: Vec<usize> = match &raw.include {
            Some(list) => self.error_list(list, m, None)?,
            None => (0..m.catalogue.len()).collect(),
        };
        let mut seen = HashMap::new();
        for item in &raw.exclude {
            let id = self.error_id(item, m)?;
            if seen.insert(id, ()).is_some() {
                return self.err(
                    item.span(),
                    format!("error `{}` excluded twice", item.get_ref()),
                );
            }
            errors.retain(|&e| e != id);
        }
        Ok(errors)
    }
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
