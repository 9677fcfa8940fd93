//! Writing machine descriptions: the text of a machine as given, and that text with a model
//! appended (what `rtest diagnose --model-out` writes: the base model and what the diagnosis
//! found, as a new sub-model the next identification can fit).
//!
//! The text is appended to, never rewritten: the comments, the order and the spelling of the
//! original stay as they were. The result is read back and checked before it is returned.

use crate::builtin::{BUILTIN, LoadError, file_text};
use crate::terms::{Effect, Term, errors_of};
use crate::{Machine, SpecError, SubModel, parse_machine};

/// Lines of the appended term list are shorter than this (in characters).
const LINE: usize = 100;

/// The TOML text of a machine given by built-in name (its text as compiled in) or by the path
/// of a file (read with [`crate::text::read_text`], at most
/// [`crate::limits::MAX_FILE_BYTES`] bytes, a byte-order mark dropped).
pub fn source_text(name_or_path: &str) -> Result<String, LoadError> {
    match BUILTIN.iter().find(|(n, _)| *n == name_or_path) {
        Some((_, text)) => Ok(text.to_string()),
        None => file_text(name_or_path),
    }
}

/// Why a model could not be appended to a machine description.
#[derive(Debug, thiserror::Error)]
pub enum AppendError {
    /// A term that is not a term of the machine's full model.
    #[error("term `{term}`: {message}")]
    Term {
        /// The term as given.
        term: String,
        /// Why it is not one.
        message: String,
    },
    /// A term given twice (spellings of one term count as one: `X0C` is `XOC`).
    #[error("term `{term}` is given twice")]
    Duplicate {
        /// The second spelling given.
        term: String,
    },
    /// The text with the model appended is not a valid description (the text was not one,
    /// or the model takes it beyond a limit of [`crate::limits`]).
    #[error(
        "the machine description with the model `{model}` appended does not read back: {error}"
    )]
    Reparse {
        /// The name of the appended model.
        model: String,
        /// The first problem found.
        error: SpecError,
    },
    /// The text with the model appended reads back as another machine, or with another model:
    /// the text is not that of the machine.
    #[error(
        "the machine description with the model `{model}` appended does not read back as machine `{machine}` with that model: is the text that of the machine?"
    )]
    NotSameMachine {
        /// The name of the appended model.
        model: String,
        /// The machine's name.
        machine: String,
    },
}

/// `s` as a TOML basic string: in double quotes, with `"`, `\` and the control characters
/// escaped; every other character as it is.
fn toml_string(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push_str("\\t"),
            c if c.is_control() => out.push_str(&format!("\\u{:04X}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// The first model name of `extended`, `extended2`, `extended3`, … that `m` does not have.
fn free_name(m: &Machine) -> String {
    std::iter::once("extended".to_string())
        .chain((2..).map(|i| format!("extended{i}")))
        .find(|n| !m.models.contains_key(n))
        .unwrap_or_default()
}

/// The items of a TOML array, four spaces in, wrapped to lines shorter than [`LINE`].
fn wrapped(items: &[String]) -> String {
    if items.is_empty() {
        return String::new();
    }
    crate::text::wrap(crate::text::list_pieces(items, ","), LINE - 5, "")
        .into_iter()
        .map(|l| format!("    {l}\n"))
        .collect()
}

/// The machine description `text` of `m` with a sub-model of `terms` appended, described by
/// `description` (trimmed, as descriptions are read; a character a description may not hold
/// is written `<U+XXXX>`, [`crate::text::visible_text`]). Returns the model's name and the new
/// text.
///
/// The model is called `extended`, or `extended2`, `extended3`, … if the name is taken. Each
/// term is `NAME` (constant) or `NAME@BASIS` ([`crate::terms`]), `NAME` an error of the
/// machine's full model or `dx0 dy0 dz0`; they are written in the order given, in their
/// canonical spelling (`x0c` is written `XOC`), wrapped to lines shorter than 100 characters.
/// The new text is read back and must be the same machine with exactly that model added.
pub fn append_model(
    m: &Machine,
    text: &str,
    terms: &[String],
    description: &str,
) -> Result<(String, String), AppendError> {
    let mut parsed: Vec<Term> = Vec::with_capacity(terms.len());
    for spelling in terms {
        let term = Term::parse(m, spelling).map_err(|e| AppendError::Term {
            term: spelling.clone(),
            message: e.0,
        })?;
        if let Effect::Error(id) = term.effect
            && !m.errors.contains(&id)
        {
            return Err(AppendError::Term {
                term: spelling.clone(),
                message: format!(
                    "error {} is not in the full model of machine {}",
                    m.catalogue[id].name, m.name
                ),
            });
        }
        if parsed.contains(&term) {
            return Err(AppendError::Duplicate {
                term: spelling.clone(),
            });
        }
        parsed.push(term);
    }
    let name = free_name(m);
    let description = crate::text::visible_text(description.trim());
    let items: Vec<String> = parsed.iter().map(|t| toml_string(&t.spelling(m))).collect();
    let mut out = text.to_string();
    if !out.is_empty() && !out.ends_with('\n') {
        out.push('\n');
    }
    out.push_str(&format!(
        "\n# Model {name}, appended by rtest.\n[models.{name}]\ndescription = {}\nerrors = [\n{}]\n",
        toml_string(&description),
        wrapped(&items)
    ));

    let back =
        parse_machine(&format!("<{} with model {name}>", m.name), &out).map_err(|error| {
            AppendError::Reparse {
                model: name.clone(),
                error,
            }
        })?;
    let mut without = back;
    let model = without.models.remove(&name);
    let expected = SubModel {
        description: description.clone(),
        errors: errors_of(&parsed),
        terms: parsed,
    };
    if without != *m || model.as_ref() != Some(&expected) {
        return Err(AppendError::NotSameMachine {
            model: name,
            machine: m.name.clone(),
        });
    }
    Ok((name, out))
}
