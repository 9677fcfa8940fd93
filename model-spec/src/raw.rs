//! The TOML layout of a machine description, as read (before validation). Every field that a
//! validation message may point at is `Spanned`, so errors name the line and column.

use serde::Deserialize;
use std::collections::BTreeMap;
use toml::Spanned;

/// A number or a symbol name, as written in an offset.
#[derive(Debug, Deserialize)]
#[serde(untagged)]
pub enum RawValue {
    /// A number (mm).
    Number(f64),
    /// A symbol name.
    Name(String),
}

/// A whole description file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawMachine {
    pub name: Spanned<String>,
    #[serde(default)]
    pub description: String,
    #[serde(default)]
    pub symbols: BTreeMap<Spanned<String>, Spanned<f64>>,
    #[serde(default)]
    pub work: Option<Spanned<Vec<Spanned<RawLink>>>>,
    #[serde(default)]
    pub tool: Option<Spanned<Vec<Spanned<RawLink>>>>,
    #[serde(default)]
    pub errors: RawErrors,
    #[serde(default)]
    pub models: BTreeMap<Spanned<String>, RawModel>,
}

/// One `[[work]]` or `[[tool]]` entry: an axis, a fixed link or the end of the chain.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawLink {
    pub axis: Option<Spanned<String>>,
    #[serde(rename = "type")]
    pub kind: Option<Spanned<String>>,
    pub direction: Option<Spanned<String>>,
    pub offset: Option<Spanned<Vec<Spanned<RawValue>>>>,
    pub stroke: Option<Spanned<Vec<Spanned<f64>>>>,
    pub range: Option<Spanned<Vec<Spanned<f64>>>>,
    pub link: Option<Spanned<String>>,
    pub end: Option<Spanned<String>>,
}

/// The `[errors]` table.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawErrors {
    pub include: Option<Spanned<Vec<Spanned<String>>>>,
    #[serde(default)]
    pub exclude: Vec<Spanned<String>>,
    pub squareness_order: Option<Spanned<Vec<Spanned<String>>>>,
}

/// One `[models.NAME]` table.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawModel {
    #[serde(default)]
    pub description: String,
    pub errors: Spanned<Vec<Spanned<String>>>,
}
