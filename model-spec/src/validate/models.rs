//! The errors of the full model (`[errors]`), the squareness order and the sub-models.

use super::{Res, Span, Validator, join};
use crate::basis::Basis;
use crate::catalogue::{ErrorId, ErrorKind, default_squareness_order};
use crate::limits::MAX_TERMS;
use crate::machine::{Axis, AxisId, AxisKind, Machine, SubModel};
use crate::raw::{RawErrors, RawModel};
use crate::terms::{Effect, Term, errors_of};
use std::collections::BTreeMap;
use toml::Spanned;

impl Validator<'_> {
    /// The sub-models of `[models.NAME]`, in the order of the file, into `machine.models`.
    pub(super) fn sub_models(
        &self,
        raw: &BTreeMap<Spanned<String>, Spanned<RawModel>>,
        machine: &mut Machine,
    ) -> Res<()> {
        let mut raw_models: Vec<_> = raw.iter().collect();
        raw_models.sort_by_key(|(name, _)| name.span().start);
        for (name, model) in raw_models {
            self.model_name(name)?;
            let n = name.get_ref();
            let Some(list) = &model.get_ref().errors else {
                return self.err(
                    model.span(),
                    format!("model `{n}` has no `errors = [...]` list"),
                );
            };
            let (errors, terms) = self.term_list(list, machine, n)?;
            machine.models.insert(
                n.clone(),
                SubModel {
                    description: self.description(model.get_ref().description.as_ref())?,
                    errors,
                    terms,
                },
            );
        }
        Ok(())
    }

    pub(super) fn squareness_order(
        &self,
        raw: &RawErrors,
        axes: &[Axis],
        axis_spans: &[Span],
    ) -> Res<Vec<AxisId>> {
        let order = self.squareness_order_as_given(raw, axes)?;
        // The squareness of the second axis is about the normal of the first two, a coordinate
        // direction only when both are along coordinate directions.
        for &i in order.iter().take(2) {
            if axes[i].direction.inclined.is_some() {
                return self.err(
                    axis_spans[i].clone(),
                    format!(
                        "linear axis {} is inclined: an inclined linear axis cannot be first or second in the squareness order (put two axes along x, y or z first with `[errors] squareness_order`)",
                        axes[i].name
                    ),
                );
            }
        }
        Ok(order)
    }

    fn squareness_order_as_given(&self, raw: &RawErrors, axes: &[Axis]) -> Res<Vec<AxisId>> {
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
    /// the machine's full model, an effect of the measurement (`dx0 dy0 dz0`, `SXX` … `SZY`)
    /// or a kinematic symbol of the machine (`Zt`, written as in `[symbols]`; constants only). Returns the errors used (catalogue order, each
    /// once) and the terms in the order written.
    pub(super) fn term_list(
        &self,
        list: &Spanned<Vec<Spanned<String>>>,
        m: &Machine,
        model: &str,
    ) -> Res<(Vec<ErrorId>, Vec<Term>)> {
        if let Some(first_past) = list.get_ref().get(MAX_TERMS) {
            return self.err(
                first_past.span(),
                format!(
                    "model `{model}` has {} terms, more than {MAX_TERMS}, the most a sub-model may have",
                    list.get_ref().len()
                ),
            );
        }
        let mut terms: Vec<(Term, Span)> = Vec::new();
        for item in list.get_ref() {
            let written = item.get_ref().trim();
            let (name, basis) = match written.split_once('@') {
                Some((n, b)) => (n.trim(), Some(b.trim())),
                None => (written, None),
            };
            let effect = match Effect::parse_measurement(name)
                .or_else(|| Effect::parse_kinematic(m, name))
            {
                Some(e) => e,
                None => {
                    if m.error_by_name(name).is_none()
                        && let Some(sym) =
                            m.symbols.iter().find(|s| s.name.eq_ignore_ascii_case(name))
                    {
                        return self.err(
                            item.span(),
                            format!(
                                "model `{model}`: `{name}` is no error of this machine; the kinematic symbol is written `{}` (symbols are named exactly as [symbols] writes them)",
                                sym.name
                            ),
                        );
                    }
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
        Ok((errors_of(&terms), terms))
    }

    pub(super) fn model_errors(&self, raw: &RawErrors, m: &Machine) -> Res<Vec<ErrorId>> {
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
