//! Names in a machine description: of the machine, its symbols, axes and models.

use super::{Res, Span, Validator};
use crate::catalogue::ErrorTerm;
use crate::limits::MAX_NAME_CHARS;
use crate::machine::{Axis, AxisKind, FULL_MODEL};
use crate::raw::Num;
use crate::terms::{Effect, MEASUREMENT_EFFECTS};
use toml::Spanned;

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

/// A letter, then letters, digits or `_`.
fn is_identifier(s: &str) -> bool {
    let mut c = s.chars();
    matches!(c.next(), Some(ch) if ch.is_ascii_alphabetic())
        && c.all(|ch| ch.is_ascii_alphanumeric() || ch == '_')
}

/// The items the generated code of a machine defines beside its model modules; a model may not
/// be named like one of them.
pub const GENERATED_ITEMS: &[&str] = &["Pose", "Params", "POSE_INPUTS", "PARAMETERS"];

/// Rust's strict and reserved keywords (2024 edition): generated code uses symbol names as
/// field names and model names as module names, so neither may be one of these (and the code
/// generator names no local one of these).
pub const RUST_KEYWORDS: &[&str] = &[
    "Self", "abstract", "as", "async", "await", "become", "box", "break", "const", "continue",
    "crate", "do", "dyn", "else", "enum", "extern", "false", "final", "fn", "for", "gen", "if",
    "impl", "in", "let", "loop", "macro", "match", "mod", "move", "mut", "override", "priv", "pub",
    "ref", "return", "self", "static", "struct", "super", "trait", "true", "try", "type", "typeof",
    "unsafe", "unsized", "use", "virtual", "where", "while", "yield",
];

fn is_rust_keyword(s: &str) -> bool {
    RUST_KEYWORDS.contains(&s)
}

impl Validator<'_> {
    /// A name (`what`: `machine name`, `symbol name`, …) of at most [`MAX_NAME_CHARS`]
    /// characters. Checked before anything else about the name, so that no message repeats
    /// a longer one.
    pub(super) fn name_length(&self, what: &str, name: &Spanned<String>) -> Res<()> {
        let n = name.get_ref().chars().count();
        if n <= MAX_NAME_CHARS {
            return Ok(());
        }
        self.err(
            name.span(),
            format!(
                "{what} `{}` has {n} characters, more than {MAX_NAME_CHARS}, the longest name",
                crate::text::quoted_start(name.get_ref())
            ),
        )
    }

    /// A `description` (of the machine or a sub-model), trimmed; empty when there is none
    /// ([`crate::text::description_text`]).
    pub(super) fn description(&self, raw: Option<&Spanned<String>>) -> Res<String> {
        crate::text::description_text(raw).or_else(|(span, why)| self.err(span, why))
    }

    /// The machine's name, trimmed: letters, digits, `-` or `_`, not too long.
    pub(super) fn machine_name(&self, raw_name: &Spanned<String>) -> Res<String> {
        self.name_length("machine name", raw_name)?;
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
        Ok(name)
    }

    /// A symbol's name: an identifier, not a Rust keyword, not too long.
    pub(super) fn symbol_name(&self, k: &Spanned<String>) -> Res<()> {
        self.name_length("symbol name", k)?;
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
        Ok(())
    }

    /// No symbol takes a name reserved for the commands of an axis in formulas.
    pub(super) fn symbols_not_reserved(
        &self,
        raw_symbols: &[(&Spanned<String>, &Spanned<Num>)],
        axes: &[Axis],
    ) -> Res<()> {
        for &(k, _) in raw_symbols {
            for a in axes {
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
        Ok(())
    }

    /// No symbol takes the name of an effect of the measurement (`dx0 dy0 dz0` in any case,
    /// `SXX` … `SZY`): those names are terms of models, truths and reports. (No error can have
    /// one: error names are built from axis letters, one upper-case letter other than E and O,
    /// as `E<direction><axis>`, `<direction>O<axis>` or `<direction>OW`.)
    pub(super) fn symbols_not_measurement_effects(
        &self,
        raw_symbols: &[(&Spanned<String>, &Spanned<Num>)],
    ) -> Res<()> {
        for &(k, _) in raw_symbols {
            if Effect::parse_measurement(k.get_ref()).is_some() {
                return self.err(
                    k.span(),
                    format!(
                        "symbol `{}` has a name reserved for an effect of the measurement (R-test or touch probe: {}): rename the symbol",
                        k.get_ref(),
                        MEASUREMENT_EFFECTS.join(" ")
                    ),
                );
            }
        }
        Ok(())
    }

    /// No symbol takes the name of an error of the machine, in any spelling that reads as that
    /// error (error names are read without regard to case and with the digit-zero alias:
    /// `xoc` and `X0C` are `XOC`). A model term, a `--terms` list or a report names an error
    /// or a kinematic offset by the same word, so the two may never share one.
    pub(super) fn symbols_not_errors(
        &self,
        raw_symbols: &[(&Spanned<String>, &Spanned<Num>)],
        catalogue: &[ErrorTerm],
    ) -> Res<()> {
        for &(k, _) in raw_symbols {
            let canonical = crate::catalogue::canonical_name(k.get_ref());
            if let Some(e) = catalogue.iter().find(|e| e.name == canonical) {
                let message = if e.name == *k.get_ref() {
                    format!(
                        "symbol `{}` has the name of an error of this machine: rename the symbol",
                        k.get_ref()
                    )
                } else {
                    format!(
                        "symbol `{}` reads as the error {} of this machine (error names are read without regard to case, with 0 for O): terms name errors and kinematic symbols alike, so rename the symbol",
                        k.get_ref(),
                        e.name
                    )
                };
                return self.err(k.span(), message);
            }
        }
        Ok(())
    }

    /// A sub-model's name: an identifier, not `full`, not a Rust keyword, not too long.
    pub(super) fn model_name(&self, name: &Spanned<String>) -> Res<()> {
        self.name_length("model name", name)?;
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
        if GENERATED_ITEMS.contains(&n.as_str()) {
            return self.err(
                name.span(),
                format!(
                    "model name `{n}` is the name of an item of the generated code ({}), which uses model names as module names: choose another name",
                    GENERATED_ITEMS.join(", ")
                ),
            );
        }
        Ok(())
    }

    /// An axis letter: one upper-case letter other than E and O, not used by an earlier axis
    /// (`axes`, whose names are at `axis_spans`).
    pub(super) fn axis_name(
        &self,
        name: &Spanned<String>,
        axes: &[Axis],
        axis_spans: &[Span],
    ) -> Res<String> {
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
        Ok(n)
    }
}
