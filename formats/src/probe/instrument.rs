//! The probe instrument file (TOML, `docs/probe.md`): what a touch-probe campaign needs to
//! know of its instrument, read through [`crate::located`] so that every problem names the
//! file, line, column and key.
//!
//! ```toml
//! name = "TS 460, 6 mm stylus"   # optional
//! tip_radius_mm = 3               # the stylus tip's radius, mm (required)
//! sphere_radius_mm = 12.5         # the calibration sphere's calibrated radius, mm (required)
//! noise_um = 0.5                  # the probe's noise σ (repeatability), µm (optional)
//! pre_travel_um = 1.2             # the constant pre-travel, µm (optional)
//! lobing_um = [0.4, -0.3]         # the three-lobed pre-travel [cos 3φ, sin 3φ], µm (optional)
//! ```
//!
//! The pre-travel keys declare the probe's trigger delay (`docs/probe-simulation.md`): the probe
//! latches `δ = pre_travel + ρ·(L_c·cos 3φ + L_s·sin 3φ)` beyond the contact along the approach,
//! with `φ` the approach's azimuth about the stylus and `ρ` its part across the stylus (both in
//! the probe's frame). The simulator makes hits with it; a fit may remove it.
//!
//! It is a file of its own, not a table of the R-test instrument description
//! ([`model_spec::instrument`]): that one describes a nest of displacement sensors around a
//! ball, with its sensors required, and a probe campaign has none of them.

use crate::located::{Located, TomlText, in_order};
use model_spec::instrument::{MAX_BALL_RADIUS_MM, MAX_NOISE_UM, MAX_TIP_RADIUS_MM};
use model_spec::text::TextError;
use std::path::Path;
use toml::de::DeValue;

/// The largest probe instrument file read, bytes (64 KiB).
pub const MAX_PROBE_INSTRUMENT_BYTES: u64 = 64 << 10;

/// The longest instrument name, characters (64).
pub const MAX_NAME_CHARS: usize = 64;

/// The largest constant pre-travel, µm (100): a probe that triggers later than 0.1 mm after
/// the contact is broken, not calibrated.
pub const MAX_PRE_TRAVEL_UM: f64 = 100.0;

/// The largest magnitude of either lobing amplitude, µm (100).
pub const MAX_LOBING_UM: f64 = 100.0;

/// A touch probe and its calibration sphere.
#[derive(Clone, Debug, PartialEq)]
pub struct ProbeInstrument {
    /// A name for reports, when the file gives one.
    pub name: Option<String>,
    /// The radius of the stylus tip, mm (above 0, at most [`MAX_TIP_RADIUS_MM`]).
    pub tip_radius_mm: f64,
    /// The calibrated radius of the calibration sphere, mm (above 0, at most
    /// [`MAX_BALL_RADIUS_MM`]).
    pub sphere_radius_mm: f64,
    /// The probe's noise σ (the standard deviation of one hit along its approach direction),
    /// µm (above 0, at most [`MAX_NOISE_UM`]), when the file gives it.
    pub noise_um: Option<f64>,
    /// The probe's constant pre-travel `δ0`, µm (at least 0, at most [`MAX_PRE_TRAVEL_UM`]),
    /// when the file declares it: how far beyond the contact, along the approach, the tip
    /// centre is when the probe latches.
    pub pre_travel_um: Option<f64>,
    /// The three-lobed part of the pre-travel `[L_c, L_s]`, µm (each at most
    /// [`MAX_LOBING_UM`] in magnitude), when the file declares it: `ρ·(L_c·cos 3φ + L_s·sin 3φ)`
    /// is added to `δ0` for an approach of azimuth `φ` about the stylus and part `ρ` across it
    /// (probe frame).
    pub lobing_um: Option<[f64; 2]>,
}

/// A problem with a probe instrument file.
#[derive(Debug, thiserror::Error)]
pub enum ProbeInstrumentError {
    /// An invalid entry, located (`file:line:column: message`).
    #[error(transparent)]
    Invalid(#[from] Located),
    /// The file cannot be read, is larger than [`MAX_PROBE_INSTRUMENT_BYTES`] or is not UTF-8.
    #[error("probe instrument file: {0}")]
    Text(#[from] TextError),
}

/// The keys of the file, for messages.
const KEYS: &str = "name, tip_radius_mm, sphere_radius_mm, noise_um, pre_travel_um, lobing_um";

/// Reads the probe instrument TOML `text` (named `file` in messages).
///
/// # Errors
/// [`Located`] for the first problem: TOML syntax, an unknown key, a name that is not a string
/// or is empty or longer than [`MAX_NAME_CHARS`], a radius, noise or pre-travel that is not a
/// finite number or is out of its range, a lobing that is not two such numbers, a required key
/// missing.
pub fn parse_probe_instrument(file: &str, text: &str) -> Result<ProbeInstrument, Located> {
    let src = TomlText::new(file, text);
    let root = src.root()?;
    let mut name = None;
    let (mut tip, mut sphere, mut noise) = (None, None, None);
    let (mut pre_travel, mut lobing) = (None, None);
    for (k, v) in in_order(root.get_ref()) {
        let key = k.get_ref().as_ref();
        let what = format!("`{key}`");
        let range = |v: &crate::located::Val<'_>, unit: &str, max: f64, of: &str| {
            let (x, t) = src.number(v, &what)?;
            if x <= 0.0 || x > max {
                return Err(src.at(
                    v.span(),
                    format!("{what} is {t} {unit}; {of} must be above 0 and at most {max} {unit}"),
                ));
            }
            Ok(x)
        };
        match key {
            "name" => {
                let s = src.string(v, &what)?;
                if s.trim().is_empty() || s.chars().count() > MAX_NAME_CHARS {
                    return Err(src.at(
                        v.span(),
                        format!("{what} must be a name of 1 to {MAX_NAME_CHARS} characters"),
                    ));
                }
                name = Some(s);
            }
            "tip_radius_mm" => {
                tip = Some(range(
                    v,
                    "mm",
                    MAX_TIP_RADIUS_MM,
                    "the stylus tip's radius",
                )?)
            }
            "sphere_radius_mm" => {
                sphere = Some(range(
                    v,
                    "mm",
                    MAX_BALL_RADIUS_MM,
                    "the calibration sphere's radius",
                )?)
            }
            "noise_um" => noise = Some(range(v, "µm", MAX_NOISE_UM, "the probe's noise σ")?),
            "pre_travel_um" => {
                let (x, t) = src.number(v, &what)?;
                if !(0.0..=MAX_PRE_TRAVEL_UM).contains(&x) {
                    return Err(src.at(
                        v.span(),
                        format!(
                            "{what} is {t} µm; the probe's constant pre-travel must be at least 0 and at most {MAX_PRE_TRAVEL_UM} µm"
                        ),
                    ));
                }
                pre_travel = Some(x);
            }
            "lobing_um" => lobing = Some(lobing_pair(&src, v, &what)?),
            other => {
                return Err(src.at(
                    k.span(),
                    format!("unknown key `{other}` (a probe instrument file has {KEYS})"),
                ));
            }
        }
    }
    let missing = |key: &str, what: &str| {
        src.at(
            0..0,
            format!("missing `{key}`: {what}; a probe instrument file has {KEYS}"),
        )
    };
    let tip_radius_mm =
        tip.ok_or_else(|| missing("tip_radius_mm", "the stylus tip's radius, mm"))?;
    let sphere_radius_mm = sphere.ok_or_else(|| {
        missing(
            "sphere_radius_mm",
            "the calibration sphere's calibrated radius, mm",
        )
    })?;
    Ok(ProbeInstrument {
        name,
        tip_radius_mm,
        sphere_radius_mm,
        noise_um: noise,
        pre_travel_um: pre_travel,
        lobing_um: lobing,
    })
}

/// The lobing amplitudes `[L_c, L_s]` of `v` (µm): an array of two finite numbers, each at
/// most [`MAX_LOBING_UM`] in magnitude.
fn lobing_pair(
    src: &TomlText<'_>,
    v: &crate::located::Val<'_>,
    what: &str,
) -> Result<[f64; 2], Located> {
    let items = match v.get_ref() {
        DeValue::Array(a) if a.len() == 2 => a,
        DeValue::Array(a) => {
            return Err(src.at(
                v.span(),
                format!(
                    "{what} needs two numbers [cos 3φ, sin 3φ] (µm), got an array of {}",
                    a.len()
                ),
            ));
        }
        other => {
            return Err(src.at(
                v.span(),
                format!(
                    "{what} needs two numbers [cos 3φ, sin 3φ] (µm), not {}",
                    other.type_str()
                ),
            ));
        }
    };
    let mut out = [0.0; 2];
    for (slot, x) in out.iter_mut().zip(items.iter()) {
        let (value, text) = src.number(x, what)?;
        if value.abs() > MAX_LOBING_UM {
            return Err(src.at(
                x.span(),
                format!(
                    "{what} has {text} µm; a lobing amplitude must be at most {MAX_LOBING_UM} µm in magnitude"
                ),
            ));
        }
        *slot = value;
    }
    Ok(out)
}

/// Reads the probe instrument file at `path` (at most [`MAX_PROBE_INSTRUMENT_BYTES`], UTF-8);
/// see [`parse_probe_instrument`].
///
/// # Errors
/// [`ProbeInstrumentError::Text`] when the file cannot be read, is too large or is not UTF-8;
/// [`ProbeInstrumentError::Invalid`] as [`parse_probe_instrument`].
pub fn read_probe_instrument(path: &Path) -> Result<ProbeInstrument, ProbeInstrumentError> {
    let text = model_spec::text::read_text(path, MAX_PROBE_INSTRUMENT_BYTES)?;
    Ok(parse_probe_instrument(&path.display().to_string(), &text)?)
}

impl ProbeInstrument {
    /// The instrument as a TOML file that [`parse_probe_instrument`] reads back to the same
    /// instrument, bit for bit (each number the shortest decimal of its `f64`).
    pub fn to_toml(&self) -> String {
        let mut s = String::new();
        if let Some(n) = &self.name {
            s += &format!(
                "name = {}\n",
                serde_json::to_string(n).unwrap_or_else(|_| "\"\"".into())
            );
        }
        s += &format!("tip_radius_mm = {}\n", float(self.tip_radius_mm));
        s += &format!("sphere_radius_mm = {}\n", float(self.sphere_radius_mm));
        if let Some(x) = self.noise_um {
            s += &format!("noise_um = {}\n", float(x));
        }
        if let Some(x) = self.pre_travel_um {
            s += &format!("pre_travel_um = {}\n", float(x));
        }
        if let Some([c, si]) = self.lobing_um {
            s += &format!("lobing_um = [{}, {}]\n", float(c), float(si));
        }
        s
    }
}

/// `x` as a TOML number that reads back to the same bits.
fn float(x: f64) -> String {
    let s = format!("{x:?}");
    if s.contains(['.', 'e', 'E', 'i', 'n']) {
        s
    } else {
        format!("{s}.0")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn err(text: &str) -> String {
        parse_probe_instrument("p.toml", text)
            .unwrap_err()
            .to_string()
    }

    #[test]
    fn a_file_reads_back_bit_for_bit() {
        let p = parse_probe_instrument(
            "p.toml",
            "name = \"TS 460\"\ntip_radius_mm = 3\nsphere_radius_mm = 12.4997\nnoise_um = 0.25\n",
        )
        .unwrap();
        assert_eq!(p.name.as_deref(), Some("TS 460"));
        assert_eq!(
            (p.tip_radius_mm, p.sphere_radius_mm, p.noise_um),
            (3.0, 12.4997, Some(0.25))
        );
        for q in [
            p.clone(),
            ProbeInstrument {
                name: None,
                tip_radius_mm: 0.1 + 0.2,
                sphere_radius_mm: 1e-7,
                noise_um: None,
                pre_travel_um: None,
                lobing_um: None,
            },
            ProbeInstrument {
                name: Some("lobed \"3-point\"".into()),
                tip_radius_mm: 1.5,
                sphere_radius_mm: 12.5,
                noise_um: Some(0.1 + 0.2),
                pre_travel_um: Some(0.0),
                lobing_um: Some([-0.0, 1.0 / 3.0]),
            },
        ] {
            let back = parse_probe_instrument("q.toml", &q.to_toml()).unwrap();
            assert_eq!(back, q);
            assert_eq!(back.tip_radius_mm.to_bits(), q.tip_radius_mm.to_bits());
            let bits = |p: &ProbeInstrument| p.lobing_um.map(|l| l.map(f64::to_bits));
            assert_eq!(bits(&back), bits(&q));
        }
    }

    #[test]
    fn every_refusal_is_located() {
        let ok = "tip_radius_mm = 3\nsphere_radius_mm = 12.5\n";
        assert_eq!(
            err("tip_radius_mm = 3\n"),
            "p.toml:1:1: missing `sphere_radius_mm`: the calibration sphere's calibrated radius, mm; a probe instrument file has name, tip_radius_mm, sphere_radius_mm, noise_um, pre_travel_um, lobing_um"
        );
        assert_eq!(
            err("sphere_radius_mm = 3\n"),
            "p.toml:1:1: missing `tip_radius_mm`: the stylus tip's radius, mm; a probe instrument file has name, tip_radius_mm, sphere_radius_mm, noise_um, pre_travel_um, lobing_um"
        );
        assert_eq!(
            err(&format!("{ok}noise_um = 0\n")),
            "p.toml:3:12: `noise_um` is 0 µm; the probe's noise σ must be above 0 and at most 1000 µm"
        );
        assert_eq!(
            err("tip_radius_mm = -1\nsphere_radius_mm = 12.5\n"),
            "p.toml:1:17: `tip_radius_mm` is -1 mm; the stylus tip's radius must be above 0 and at most 50 mm"
        );
        assert_eq!(
            err("tip_radius_mm = 3\nsphere_radius_mm = 101\n"),
            "p.toml:2:20: `sphere_radius_mm` is 101 mm; the calibration sphere's radius must be above 0 and at most 100 mm"
        );
        assert_eq!(
            err(&format!("{ok}radius = 1\n")),
            "p.toml:3:1: unknown key `radius` (a probe instrument file has name, tip_radius_mm, sphere_radius_mm, noise_um, pre_travel_um, lobing_um)"
        );
        assert_eq!(
            err(&format!("name = \"\"\n{ok}")),
            "p.toml:1:8: `name` must be a name of 1 to 64 characters"
        );
        assert_eq!(
            err("tip_radius_mm = \"3\"\nsphere_radius_mm = 12.5\n"),
            "p.toml:1:17: `tip_radius_mm` must be a number, not string"
        );
        assert_eq!(
            err("tip_radius_mm = nan\nsphere_radius_mm = 12.5\n"),
            "p.toml:1:17: `tip_radius_mm` must be a finite number, not `nan`"
        );
        assert!(err("tip_radius_mm = \n").starts_with("p.toml:1:"));
    }

    #[test]
    fn the_declared_pre_travel_is_read_and_bounded() {
        let ok = "tip_radius_mm = 3\nsphere_radius_mm = 12.5\n";
        let p = parse_probe_instrument(
            "p.toml",
            &format!("{ok}pre_travel_um = 1.25\nlobing_um = [0.5, -2]\n"),
        )
        .unwrap();
        assert_eq!(
            (p.pre_travel_um, p.lobing_um),
            (Some(1.25), Some([0.5, -2.0]))
        );
        let p = parse_probe_instrument("p.toml", ok).unwrap();
        assert_eq!((p.pre_travel_um, p.lobing_um), (None, None));
        assert_eq!(
            parse_probe_instrument("p.toml", &format!("{ok}pre_travel_um = 0\n"))
                .unwrap()
                .pre_travel_um,
            Some(0.0)
        );
        assert_eq!(
            err(&format!("{ok}pre_travel_um = -0.5\n")),
            "p.toml:3:17: `pre_travel_um` is -0.5 µm; the probe's constant pre-travel must be at least 0 and at most 100 µm"
        );
        assert_eq!(
            err(&format!("{ok}pre_travel_um = 100.5\n")),
            "p.toml:3:17: `pre_travel_um` is 100.5 µm; the probe's constant pre-travel must be at least 0 and at most 100 µm"
        );
        assert_eq!(
            err(&format!("{ok}pre_travel_um = inf\n")),
            "p.toml:3:17: `pre_travel_um` must be a finite number, not `inf`"
        );
        assert_eq!(
            err(&format!("{ok}lobing_um = 2\n")),
            "p.toml:3:13: `lobing_um` needs two numbers [cos 3φ, sin 3φ] (µm), not integer"
        );
        assert_eq!(
            err(&format!("{ok}lobing_um = [1, 2, 3]\n")),
            "p.toml:3:13: `lobing_um` needs two numbers [cos 3φ, sin 3φ] (µm), got an array of 3"
        );
        assert_eq!(
            err(&format!("{ok}lobing_um = [1, \"2\"]\n")),
            "p.toml:3:17: `lobing_um` must be a number, not string"
        );
        assert_eq!(
            err(&format!("{ok}lobing_um = [1, -101]\n")),
            "p.toml:3:17: `lobing_um` has -101 µm; a lobing amplitude must be at most 100 µm in magnitude"
        );
        assert_eq!(
            err(&format!("{ok}lobing_um = [nan, 0]\n")),
            "p.toml:3:14: `lobing_um` must be a finite number, not `nan`"
        );
    }

    #[test]
    fn a_file_too_large_is_refused_unread() {
        let dir = std::env::temp_dir().join(format!("rtest-probe-inst-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("big.toml");
        let pad = "#".repeat(MAX_PROBE_INSTRUMENT_BYTES as usize + 1);
        std::fs::write(&path, pad).unwrap();
        let e = read_probe_instrument(&path).unwrap_err();
        assert!(matches!(
            e,
            ProbeInstrumentError::Text(TextError::TooLarge { .. })
        ));
        let good = dir.join("good.toml");
        std::fs::write(&good, "tip_radius_mm = 2\nsphere_radius_mm = 15\n").unwrap();
        assert_eq!(read_probe_instrument(&good).unwrap().tip_radius_mm, 2.0);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
