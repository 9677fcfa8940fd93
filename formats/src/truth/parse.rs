//! The validation of a truth file: every entry checked against the machine, every problem
//! located by line and column.

use super::TruthError;
use crate::located::{Key, TomlText, Val, in_order};
use model_spec::Machine;
use model_spec::units::parse_scaled;
use simulation::model::{Basis, Carrier, Effect, Term};
use simulation::truth::{MAX_NOISE_PHI, MAX_NOISE_UM, MAX_SEED, MAX_VALUE, Truth, places};
use std::ops::Range;
use toml::de::{DeTable, DeValue};

/// The validator: the source, for locating errors, and the machine.
pub(super) struct Parser<'a> {
    pub(super) t: TomlText<'a>,
    pub(super) m: &'a Machine,
}

type Res<T> = Result<T, TruthError>;

const TOP_KEYS: &str =
    "machine, description, noise_um, noise_phi, seed, zeroed, [parameters], [errors]";

impl Parser<'_> {
    /// The truth of the text, validated.
    pub(super) fn parse(&self) -> Res<Truth> {
        let root = self.t.root()?;
        self.truth(root.get_ref())
    }

    fn err(&self, span: Range<usize>, message: impl Into<String>) -> TruthError {
        self.t.at(span, message).into()
    }

    fn line(&self, span: &Range<usize>) -> usize {
        self.t.line(span)
    }

    fn truth(&self, root: &DeTable<'_>) -> Res<Truth> {
        let m = self.m;
        let mut t = Truth::nominal(m);
        t.source = self.t.file().to_string();
        t.description = String::new();
        let mut terms: Vec<(Term, Vec<f64>, Range<usize>)> = Vec::new();
        for (k, v) in in_order(root) {
            match k.get_ref().as_ref() {
                "machine" => {
                    let name = self.string(k, v)?;
                    if name != m.name {
                        return Err(self.err(
                            v.span(),
                            format!(
                                "this truth is written for machine `{name}`, not `{}`",
                                m.name
                            ),
                        ));
                    }
                }
                "description" => t.description = self.string(k, v)?.trim().to_string(),
                "noise_um" => {
                    let what = "`noise_um` (standard deviation of the reading noise, µm)";
                    let (x, text) = self.number(v, what)?;
                    if !(0.0..=MAX_NOISE_UM).contains(&x) {
                        return Err(self.err(
                            v.span(),
                            format!("{what} must be from 0 to {MAX_NOISE_UM} µm, not {text}"),
                        ));
                    }
                    t.noise_mm = self.scaled(&text, 3, v, what)?;
                }
                "noise_phi" => {
                    let what = "`noise_phi` (lag-1 autocorrelation of the reading noise)";
                    let (x, text) = self.number(v, what)?;
                    if !(0.0..MAX_NOISE_PHI).contains(&x) {
                        return Err(self.err(
                            v.span(),
                            format!(
                                "{what} must be at least 0 and below {MAX_NOISE_PHI}, not {text}"
                            ),
                        ));
                    }
                    t.noise_phi = x;
                }
                "seed" => t.seed = self.seed(v)?,
                "zeroed" => match v.get_ref() {
                    DeValue::Boolean(b) => t.zeroed = *b,
                    other => {
                        return Err(self.err(
                            v.span(),
                            format!("`zeroed` must be true or false, not {}", other.type_str()),
                        ));
                    }
                },
                "parameters" => self.parameters(v, &mut t.params)?,
                "errors" => self.errors(v, &mut terms)?,
                other => {
                    return Err(self.err(
                        k.span(),
                        format!("unknown key `{other}` (expected {TOP_KEYS})"),
                    ));
                }
            }
        }
        terms.sort_by_key(|(term, _, _)| *term);
        for (term, c, _) in terms {
            t.model.terms.push(term);
            t.coefficients.extend(c);
        }
        Ok(t)
    }

    fn table<'v, 'i>(&self, v: &'v Val<'i>, what: &str) -> Res<&'v DeTable<'i>> {
        match v.get_ref() {
            DeValue::Table(t) => Ok(t),
            other => Err(self.err(
                v.span(),
                format!("{what} must be a table, not {}", other.type_str()),
            )),
        }
    }

    fn string(&self, k: &Key<'_>, v: &Val<'_>) -> Res<String> {
        Ok(self.t.string(v, &format!("`{}`", k.get_ref()))?)
    }

    /// A finite number and the decimal text it was written as.
    fn number(&self, v: &Val<'_>, what: &str) -> Res<(f64, String)> {
        Ok(self.t.number(v, what)?)
    }

    /// `x` (read at `v`, written `text`) if its magnitude is at most `max` (in `unit`).
    fn bounded(
        &self,
        v: &Val<'_>,
        what: &str,
        (x, text): (f64, &str),
        max: f64,
        unit: &str,
    ) -> Res<f64> {
        if x.abs() <= max {
            Ok(x)
        } else {
            Err(self.err(
                v.span(),
                format!(
                    "{what}: {text} is beyond the largest magnitude a truth may have, {max} {unit}"
                ),
            ))
        }
    }

    /// The number `text` (already checked) with the decimal point moved `places` to the left.
    fn scaled(&self, text: &str, places: i32, v: &Val<'_>, what: &str) -> Res<f64> {
        match parse_scaled(text, -places) {
            Some(x) if x.is_finite() => Ok(x),
            _ => Err(self.err(v.span(), format!("{what}: `{text}` is out of range"))),
        }
    }

    fn seed(&self, v: &Val<'_>) -> Res<u64> {
        let msg = format!("`seed` must be a whole number from 0 to {MAX_SEED}");
        match v.get_ref() {
            DeValue::Integer(i) => u64::from_str_radix(i.as_str(), i.radix())
                .ok()
                .filter(|&s| s <= MAX_SEED)
                .ok_or_else(|| self.err(v.span(), format!("{msg}, not `{i}`"))),
            other => Err(self.err(v.span(), format!("{msg}, not {}", other.type_str()))),
        }
    }

    fn parameters(&self, v: &Val<'_>, params: &mut [f64]) -> Res<()> {
        let m = self.m;
        for (k, v) in in_order(self.table(v, "`[parameters]`")?) {
            let name = k.get_ref().as_ref();
            let Some(i) = m.symbol_by_name(name) else {
                let known: Vec<&str> = m.symbols.iter().map(|s| s.name.as_str()).collect();
                return Err(self.err(
                    k.span(),
                    format!(
                        "machine {} has no kinematic parameter `{name}` (it has: {})",
                        m.name,
                        if known.is_empty() {
                            "none".to_string()
                        } else {
                            known.join(", ")
                        }
                    ),
                ));
            };
            let what = format!("parameter `{name}` (mm)");
            let (x, text) = self.number(v, &what)?;
            params[i] = self.bounded(
                v,
                &what,
                (x, &text),
                model_spec::limits::MAX_LENGTH_MM,
                "mm",
            )?;
        }
        Ok(())
    }

    fn errors(&self, v: &Val<'_>, terms: &mut Vec<(Term, Vec<f64>, Range<usize>)>) -> Res<()> {
        let m = self.m;
        for (k, v) in in_order(self.table(v, "`[errors]`")?) {
            let name = k.get_ref().as_ref();
            let Some(effect) = Effect::parse(m, name) else {
                return Err(self.err(
                    k.span(),
                    format!(
                        "`{name}` is neither an error of machine {} nor a sensor offset dx0 dy0 dz0 nor an instrument term SXX … SZY (errors: {})",
                        m.name,
                        m.catalogue.iter().map(|e| e.name.as_str()).collect::<Vec<_>>().join(" ")
                    ),
                ));
            };
            if effect == Effect::PreTravel {
                return Err(self.err(
                    k.span(),
                    "`PRE` is a touch probe's pre-travel, not an error of the machine: a simulated probe's pre-travel is its probe file's pre_travel_um and lobing_um (rtest simulate --probe)".to_string(),
                ));
            }
            let unit = effect.unit(m).replace('u', "µ");
            match v.get_ref() {
                DeValue::Table(table) => {
                    if table.is_empty() {
                        return Err(self.err(
                            v.span(),
                            format!("`{name}` has no terms: give e.g. {{ const = 1.0 }} ({unit})"),
                        ));
                    }
                    for (bk, bv) in in_order(table) {
                        let basis = Basis::parse(bk.get_ref())
                            .map_err(|e| self.err(bk.span(), format!("{name}: {}", e.0)))?;
                        self.term(effect, basis, &bk.span(), bv, terms)?;
                    }
                }
                DeValue::Integer(_) | DeValue::Float(_) => {
                    self.term(effect, Basis::Const, &k.span(), v, terms)?;
                }
                other => {
                    return Err(self.err(
                        v.span(),
                        format!(
                            "`{name}` must be a number (a constant, {unit}) or a table of basis = value, e.g. {{ const = 1.0, \"harmonic:2\" = [0.5, 0.0] }}, not {}",
                            other.type_str()
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// One term `effect × basis` whose value `v` is written at `v`; `at` locates the basis key
    /// (or the error name for a constant given as a plain number).
    fn term(
        &self,
        effect: Effect,
        basis: Basis,
        at: &Range<usize>,
        v: &Val<'_>,
        terms: &mut Vec<(Term, Vec<f64>, Range<usize>)>,
    ) -> Res<()> {
        let m = self.m;
        let name = effect.name(m);
        let term = Term::new(m, effect, basis).map_err(|e| {
            let what = match effect.carrier(m) {
                Carrier::Axis(a) => format!("{name} is an error of axis {}", m.axes[a].name),
                Carrier::None => format!("{name} belongs to no axis"),
            };
            self.err(
                at.clone(),
                format!("{name}: basis does not fit: {} ({what})", e.0),
            )
        })?;
        if let Some((_, _, first)) = terms.iter().find(|(t, _, _)| *t == term) {
            return Err(self.err(
                at.clone(),
                format!(
                    "{name} with basis `{basis}` is given twice (first at line {})",
                    self.line(first)
                ),
            ));
        }
        let unit = term.unit(m).replace('u', "µ");
        let what = format!("{name} `{basis}` ({unit})");
        let p = places(m, &term);
        let values = if basis.width() == 2 {
            let arr = match v.get_ref() {
                DeValue::Array(a) if a.len() == 2 => a,
                DeValue::Array(a) => {
                    return Err(self.err(
                        v.span(),
                        format!(
                            "{what} needs two numbers [cos, sin], got an array of {}",
                            a.len()
                        ),
                    ));
                }
                other => {
                    return Err(self.err(
                        v.span(),
                        format!(
                            "{what} needs two numbers [cos, sin], not {}",
                            other.type_str()
                        ),
                    ));
                }
            };
            let mut out = Vec::with_capacity(2);
            for x in arr.iter() {
                let (value, text) = self.number(x, &what)?;
                self.bounded(x, &what, (value, &text), MAX_VALUE, &unit)?;
                out.push(self.scaled(&text, p, x, &what)?);
            }
            out
        } else {
            if let DeValue::Array(_) = v.get_ref() {
                return Err(self.err(
                    v.span(),
                    format!(
                        "{what} takes one number; only `harmonic:K` and `period:P` take a pair [cos, sin]"
                    ),
                ));
            }
            let (value, text) = self.number(v, &what)?;
            self.bounded(v, &what, (value, &text), MAX_VALUE, &unit)?;
            vec![self.scaled(&text, p, v, &what)?]
        };
        terms.push((term, values, at.clone()));
        Ok(())
    }
}
