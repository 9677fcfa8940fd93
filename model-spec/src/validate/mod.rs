//! From the TOML text to a validated [`Machine`], with errors that name file, line and column.
//!
//! One module per job: [`names`] checks the names of the machine, its symbols, axes and models;
//! [`numbers`] the numbers; [`chains`] reads the two chains and their axes; [`models`] the
//! full model, the squareness order and the sub-models.

mod chains;
mod models;
mod names;
mod numbers;

pub use names::{RUST_KEYWORDS, reserved_names};

use crate::catalogue::build_catalogue;
use crate::error::SpecError;
use crate::limits::MAX_FILE_BYTES;
use crate::locate::Locator;
use crate::machine::{Axis, Machine, Side, Symbol};
use crate::raw::{Num, RawMachine};
use std::collections::BTreeMap;
use toml::Spanned;

/// Reads and validates a machine description. `file` names the source in error messages.
///
/// Every problem is reported as a [`SpecError`] whose line and column point at the offending
/// value or key (see `docs/model-spec.md` for the list of messages). No input panics.
pub fn parse_machine(file: &str, text: &str) -> Result<Machine, SpecError> {
    let loc = Locator { file, text };
    if text.len() as u64 > MAX_FILE_BYTES {
        return Err(loc.error(
            MAX_FILE_BYTES as usize..text.len(),
            format!(
                "the description has {} bytes, more than {MAX_FILE_BYTES} (1 MiB), the most a machine description may have",
                text.len()
            ),
        ));
    }
    let raw: RawMachine = toml::from_str(text).map_err(|e| {
        let span = e.span().unwrap_or(0..0);
        loc.error(span, e.message().trim().to_string())
    })?;
    Validator { loc: &loc }.machine(raw)
}

struct Validator<'a> {
    loc: &'a Locator<'a>,
}

type Res<T> = Result<T, SpecError>;
type Span = std::ops::Range<usize>;

fn join<'a>(names: impl IntoIterator<Item = &'a str>) -> String {
    names.into_iter().collect::<Vec<_>>().join(" ")
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
        let name = self.machine_name(raw_name)?;
        self.counts(&raw)?;

        // Checked and kept in the order of the file, not the order of the map.
        let mut raw_symbols: Vec<(&Spanned<String>, &Spanned<Num>)> = raw.symbols.iter().collect();
        raw_symbols.sort_by_key(|(k, _)| k.span().start);
        let mut symbols = Vec::new();
        for &(k, v) in &raw_symbols {
            self.symbol_name(k)?;
            let default = self.symbol_default(k, v)?;
            symbols.push(Symbol {
                name: k.get_ref().clone(),
                default,
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
        self.symbols_not_reserved(&raw_symbols, &axes)?;

        let squareness_order = self.squareness_order(&raw.errors, &axes, &axis_spans)?;
        let catalogue = build_catalogue(&axes, &squareness_order);
        self.symbols_not_errors(&raw_symbols, &catalogue)?;
        self.symbols_not_measurement_effects(&raw_symbols)?;
        let mut machine = Machine {
            name,
            description: self.description(raw.description.as_ref())?,
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
        self.sub_models(&raw.models, &mut machine)?;
        Ok(machine)
    }
}
