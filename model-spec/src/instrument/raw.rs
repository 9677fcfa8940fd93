//! The TOML layout of an instrument description, as read (before validation). Every field a
//! message may point at is `Spanned`.

use crate::raw::Num;
use serde::Deserialize;
use toml::Spanned;

/// A whole instrument description.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawInstrument {
    pub name: Option<Spanned<String>>,
    pub description: Option<Spanned<String>>,
    pub ball_radius_mm: Option<Spanned<Num>>,
    pub frame: Option<Spanned<String>>,
    pub sensor: Option<Spanned<Vec<Spanned<RawSensor>>>>,
}

/// One `[[sensor]]` entry.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawSensor {
    pub name: Option<Spanned<String>>,
    pub direction: Option<Spanned<Vec<Spanned<Num>>>>,
    pub tip: Option<Spanned<String>>,
    pub tip_radius_mm: Option<Spanned<Num>>,
    pub face_radius_mm: Option<Spanned<Num>>,
    pub position_mm: Option<Spanned<Vec<Spanned<Num>>>>,
    pub gain: Option<Spanned<Num>>,
    pub noise_um: Option<Spanned<Num>>,
    pub zero_um: Option<Spanned<Num>>,
}
