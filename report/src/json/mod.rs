//! The reports of rtest as serde types: what `identify`, `validate`, `diagnose` and
//! `compensate` write as JSON, what their text for people is rendered from
//! ([`crate::text`]), and the gain tables of `gains --format json`.
//!
//! Units: translational values in µm, angular values in µrad, lengths and positions in mm,
//! rotary positions in degrees (field names carry the unit: `_um`, `_deg`; a parameter has its
//! own `unit` field, `um` or `urad`).
//!
//! Two rules hold for every report:
//! - **Only finite numbers.** Every number is checked when the report is built; a non-finite
//!   one is a failed computation ([`NonFinite`]), never a `null` in the file.
//! - **`null` means "undetermined".** A value, an uncertainty or a condition number the data do
//!   not determine is `null`; nothing else is.
//!
//! A record is a campaign of one: one identification report
//! ([`identify::IdentificationReport`]) and one validation report
//! ([`validate::ValidationReport`]) hold one record or several, each with its set-up. An
//! identification is read back by one reader ([`read::read_identification`]), whatever its
//! version and number of records: `validate` and `compensate` take its model and values, after
//! checking that it belongs to the machine.

pub mod compensate;
pub mod diagnose;
pub mod diagnose_records;
pub mod fit_summary;
pub mod gains;
pub mod identify;
pub mod plan;
pub mod plan_probe;
pub mod probe;
pub mod read;
pub mod recheck;
pub mod tolerance;
pub mod validate;
pub mod verdict;

pub use diagnose::{DiagnosisReport, DiagnosisSource};
pub use gains::{GainTableReport, PoseGains, PoseGainsReport};
pub use identify::{CampaignSource, IdentificationReport};
pub use read::{IdentifiedValues, ReportError, read_identification};
pub use validate::{ValidationReport, ValidationSource};

use serde::Serialize;
use serde::de::{Deserialize, Deserializer, MapAccess, Visitor};
use serde::ser::{SerializeMap, Serializer};

/// A number that is not finite where a report needs one: the computation behind it failed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("the result has a non-finite value in `{field}` ({value}): the computation failed")]
pub struct NonFinite {
    /// The report field (`residual_rms_um`, `parameters[3].value`).
    pub field: String,
    /// The value.
    pub value: f64,
}

/// `x` if it is finite, else [`NonFinite`] naming `field`.
pub(crate) fn finite(field: impl FnOnce() -> String, x: f64) -> Result<f64, NonFinite> {
    if x.is_finite() {
        Ok(x + 0.0)
    } else {
        Err(NonFinite {
            field: field(),
            value: x,
        })
    }
}

/// [`finite`] of an optional number (`None` stays `None`: undetermined).
pub(crate) fn finite_opt(
    field: impl FnOnce() -> String,
    x: Option<f64>,
) -> Result<Option<f64>, NonFinite> {
    x.map(|x| finite(field, x)).transpose()
}

/// A JSON object whose keys keep the given order (the model's error order, the machine's
/// axis order), written and read in that order.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Ordered<T>(pub Vec<(String, T)>);

impl<'de, T: Deserialize<'de>> Deserialize<'de> for Ordered<T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Ordered<T>, D::Error> {
        struct Entries<T>(std::marker::PhantomData<T>);
        impl<'de, T: Deserialize<'de>> Visitor<'de> for Entries<T> {
            type Value = Ordered<T>;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("an object")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Ordered<T>, A::Error> {
                let mut out = Vec::new();
                while let Some((k, v)) = map.next_entry::<String, T>()? {
                    out.push((k, v));
                }
                Ok(Ordered(out))
            }
        }
        d.deserialize_map(Entries(std::marker::PhantomData))
    }
}

impl<T: Serialize> Serialize for Ordered<T> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut map = s.serialize_map(Some(self.0.len()))?;
        for (k, v) in &self.0 {
            map.serialize_entry(k, v)?;
        }
        map.end()
    }
}

/// The pretty-printed JSON text of a report, with a final newline.
///
/// # Errors
/// A serializer error (none of the report types produces one).
pub fn to_json<T: Serialize>(report: &T) -> Result<String, serde_json::Error> {
    Ok(serde_json::to_string_pretty(report)? + "\n")
}
