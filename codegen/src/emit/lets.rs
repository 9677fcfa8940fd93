//! Long runs of `let` statements carried as text through `syn` and `prettyplease`.
//!
//! A generated function is mostly one `let` per instruction (`let t12 = t3 * t7;`), thousands
//! of them for a long chain, and building them as tokens, parsing them back with `syn` and
//! printing them with `prettyplease` was most of the time to generate the code. The emitter
//! writes each of these statements as text, exactly as `prettyplease` prints it (a local bound
//! to an input, a literal, a negated local or a binary operation of two locals), and carries a
//! run of consecutive statements in the token stream as one marker statement,
//! `__rtest_lets!(r"…");`, whose string holds the run. [`crate::emit::pretty`] prints the file
//! and then replaces each marker line by its statements at the marker's indentation.
//!
//! A statement goes into a run only when it is short (at most [`MAX_LINE`] characters) and of
//! plain ASCII, so that `prettyplease` would have printed it on one line as written: the
//! markers sit in function bodies at most three levels deep, twelve spaces, well within its
//! margin of 89 columns. A longer statement (a kinematic parameter with a long name) goes
//! through `syn` as before. `codegen/tests/all/emitted.rs` checks that the generated files are a
//! fixed point of `syn` and `prettyplease` (printing the parsed file again gives the same
//! text) for every built-in machine and for long synthetic chains.

use proc_macro2::{Delimiter, Group, Ident, Literal, Punct, Spacing, Span, TokenStream, TokenTree};

/// The name of the marker macro (never a name of the emitted code).
const MARKER: &str = "__rtest_lets";

/// The longest statement carried in a run, in characters.
pub(crate) const MAX_LINE: usize = 60;

/// The deepest indentation a marker may have, in spaces (the lines stay within 80 columns).
const MAX_INDENT: usize = 20;

/// A run of statements being collected.
#[derive(Debug, Default)]
pub(crate) struct Run {
    text: String,
}

impl Run {
    /// Appends the statement `line` to the run, or, when it cannot be carried as text, ends
    /// the run into `out` and appends the statement's tokens there.
    pub(crate) fn push(&mut self, line: &str, out: &mut TokenStream) {
        let plain = line.len() <= MAX_LINE
            && line
                .bytes()
                .all(|b| b.is_ascii_alphanumeric() || b" _.[]=;+-*/".contains(&b));
        if plain {
            self.text.push_str(line);
        } else {
            self.flush(out);
            out.extend(
                line.parse::<TokenStream>()
                    .expect("an emitted statement is valid Rust"),
            );
        }
    }

    /// Ends the run: its marker statement `__rtest_lets!(r"…");` into `out`.
    pub(crate) fn flush(&mut self, out: &mut TokenStream) {
        if self.text.is_empty() {
            return;
        }
        // A raw string: the statements need no escape (plain ASCII, no quote), and building
        // it is a copy (a cooked literal escapes character by character).
        let literal: Literal = format!("r\"{}\"", std::mem::take(&mut self.text))
            .parse()
            .expect("a raw string literal of plain ASCII");
        out.extend([
            TokenTree::Ident(Ident::new(MARKER, Span::call_site())),
            TokenTree::Punct(Punct::new('!', Spacing::Alone)),
            TokenTree::Group(Group::new(
                Delimiter::Parenthesis,
                TokenTree::Literal(literal).into(),
            )),
            TokenTree::Punct(Punct::new(';', Spacing::Alone)),
        ]);
    }
}

/// Replaces each marker statement of `printed` (`prettyplease` writes it on one line, or on
/// three with the string on its own) by its run.
pub(crate) fn splice(printed: &str) -> String {
    let mut out = String::with_capacity(printed.len() * 2);
    let mut lines = printed.split_inclusive('\n');
    while let Some(line) = lines.next() {
        let trimmed = line.trim_start();
        if !trimmed.starts_with(MARKER) {
            out.push_str(line);
            continue;
        }
        let indent = &line[..line.len() - trimmed.len()];
        debug_assert!(
            indent.len() <= MAX_INDENT,
            "runs of statements are emitted in function bodies only"
        );
        let mut statement = trimmed.trim_end().to_string();
        while !statement.ends_with(");") {
            match lines.next() {
                Some(more) => statement.push_str(more.trim()),
                None => break,
            }
        }
        // The run, between the quotes of its raw string: statements one after the other, each
        // ending with its only `;`.
        let run = statement
            .find('"')
            .zip(statement.rfind('"'))
            .map_or("", |(a, b)| &statement[a + 1..b.max(a + 1)]);
        for s in run.split_inclusive(';') {
            out.push_str(indent);
            out.push_str(s);
            out.push('\n');
        }
    }
    out
}
