//! The TOML layout of a machine description, as read (before validation). Every field that a
//! validation message may point at is `Spanned`, so errors name the line and column.

use serde::Deserialize;
use serde::de::{self, Deserializer, Visitor};
use std::collections::BTreeMap;
use std::fmt;
use toml::Spanned;

/// A number (integer or float) as written in the file; `nan` and `inf` are read and rejected
/// by validation, so the message can say which number is wrong.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Num(pub f64);

impl<'de> Deserialize<'de> for Num {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl Visitor<'_> for V {
            type Value = Num;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("a number")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Num, E> {
                Ok(Num(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Num, E> {
                Ok(Num(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Num, E> {
                Ok(Num(v as f64))
            }
        }
        d.deserialize_any(V)
    }
}

/// A number or a symbol name, as written in an offset.
#[derive(Debug)]
pub enum RawValue {
    /// A number (mm).
    Number(f64),
    /// A symbol name.
    Name(String),
}

impl<'de> Deserialize<'de> for RawValue {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl Visitor<'_> for V {
            type Value = RawValue;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("a number (mm) or the name of a symbol")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<RawValue, E> {
                Ok(RawValue::Number(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<RawValue, E> {
                Ok(RawValue::Number(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<RawValue, E> {
                Ok(RawValue::Number(v as f64))
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<RawValue, E> {
                Ok(RawValue::Name(v.to_string()))
            }
        }
        d.deserialize_any(V)
    }
}

/// An axis direction as written: `"+x"` … `"-z"`, or a vector `[0, 1, 1]`.
#[derive(Debug, Deserialize)]
#[serde(untagged)]
pub enum RawDirection {
    /// `"+x"`, `"-z"`, ….
    Text(String),
    /// Any vector.
    Vector(Vec<Num>),
}

/// A whole description file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawMachine {
    pub name: Option<Spanned<String>>,
    pub description: Option<Spanned<String>>,
    #[serde(default)]
    pub symbols: BTreeMap<Spanned<String>, Spanned<Num>>,
    #[serde(default)]
    pub work: Option<Spanned<Vec<Spanned<RawLink>>>>,
    #[serde(default)]
    pub tool: Option<Spanned<Vec<Spanned<RawLink>>>>,
    #[serde(default)]
    pub errors: RawErrors,
    #[serde(default)]
    pub models: BTreeMap<Spanned<String>, Spanned<RawModel>>,
}

/// One `[[work]]` or `[[tool]]` entry: an axis, a fixed link or the end of the chain.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawLink {
    pub axis: Option<Spanned<String>>,
    #[serde(rename = "type")]
    pub kind: Option<Spanned<String>>,
    pub direction: Option<Spanned<RawDirection>>,
    pub offset: Option<Spanned<Vec<Spanned<RawValue>>>>,
    pub stroke: Option<Spanned<Vec<Spanned<Num>>>>,
    pub range: Option<Spanned<Vec<Spanned<Num>>>>,
    pub link: Option<Spanned<String>>,
    pub end: Option<Spanned<String>>,
}

/// The `[errors]` table.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawErrors {
    pub include: Option<Spanned<Vec<Spanned<String>>>>,
    pub exclude: Option<Spanned<Vec<Spanned<String>>>>,
    pub squareness_order: Option<Spanned<Vec<Spanned<String>>>>,
}

/// One `[models.NAME]` table.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawModel {
    pub description: Option<Spanned<String>>,
    pub errors: Option<Spanned<Vec<Spanned<String>>>>,
}
