//! From the TOML text to a validated [`Instrument`], with errors that name file, line and
//! column (`docs/instrument.md` lists them).

use super::raw::{RawInstrument, RawSensor};
use super::{
    GAIN_RANGE, Instrument, MAX_BALL_RADIUS_MM, MAX_CONTACT_ANGLE_DEG, MAX_NOISE_UM, MAX_SENSORS,
    MAX_TIP_RADIUS_MM, MAX_ZERO_UM, MIN_LAYOUT_SINGULAR_VALUE, MIN_SENSORS, POSITION_TOLERANCE_MM,
    ReadingsFrame, Sensor, Tip, dot, first_order_matrix, smallest_singular_value,
};
use crate::SpecError;
use crate::limits::{MAX_FILE_BYTES, MAX_NAME_CHARS};
use crate::locate::Locator;
use crate::raw::Num;
use crate::units::{compact, parse_scaled};
use toml::Spanned;

/// The longest sensor name, characters.
const MAX_SENSOR_NAME_CHARS: usize = 16;

/// The largest coordinate of a tip position, mm.
const MAX_POSITION_MM: f64 = 1000.0;

/// Sensor names that would give the columns of the error vector.
const RESERVED_SENSOR_NAMES: [&str; 3] = ["dx", "dy", "dz"];

type Res<T> = Result<T, SpecError>;
type Span = std::ops::Range<usize>;

/// Reads and validates an instrument description. `file` names the source in messages.
///
/// # Errors
/// A [`SpecError`] whose line and column point at the offending value, key or `[[sensor]]`
/// entry (see `docs/instrument.md`). No input panics.
pub fn parse_instrument(file: &str, text: &str) -> Result<Instrument, SpecError> {
    let loc = Locator { file, text };
    if text.len() as u64 > MAX_FILE_BYTES {
        return Err(loc.error(
            MAX_FILE_BYTES as usize..text.len(),
            format!(
                "the description has {} bytes, more than {MAX_FILE_BYTES} (1 MiB), the most an instrument description may have",
                text.len()
            ),
        ));
    }
    let raw: RawInstrument = toml::from_str(text).map_err(|e| {
        let span = e.span().unwrap_or(0..0);
        loc.error(span, e.message().trim().to_string())
    })?;
    V { loc: &loc }.instrument(raw)
}

struct V<'a> {
    loc: &'a Locator<'a>,
}

fn is_identifier(s: &str) -> bool {
    let mut c = s.chars();
    matches!(c.next(), Some(ch) if ch.is_ascii_alphabetic())
        && c.all(|ch| ch.is_ascii_alphanumeric() || ch == '_')
}

impl V<'_> {
    fn err<T>(&self, span: Span, msg: impl Into<String>) -> Res<T> {
        Err(self.loc.error(span, msg))
    }

    fn line(&self, span: &Span) -> usize {
        self.loc.line_col(span.start).0
    }

    fn instrument(&self, raw: RawInstrument) -> Res<Instrument> {
        let Some(name) = &raw.name else {
            return self.err(
                0..0,
                "no `name = \"...\"` at the top of the file: every instrument needs a short name",
            );
        };
        self.instrument_name(name)?;
        let Some(radius) = &raw.ball_radius_mm else {
            return self.err(
                name.span(),
                format!(
                    "instrument `{}` has no `ball_radius_mm` (the radius of the precision ball, mm: 12.7 for a ball of 25.4 mm)",
                    name.get_ref()
                ),
            );
        };
        let ball = self.number(
            radius,
            "`ball_radius_mm`",
            "mm",
            (0.0, MAX_BALL_RADIUS_MM),
            "the ball's radius must be above 0 and at most",
        )?;
        let frame = match &raw.frame {
            None => ReadingsFrame::Tool,
            Some(f) => ReadingsFrame::parse(f.get_ref()).ok_or_else(|| {
                self.loc.error(
                    f.span(),
                    format!(
                        "unknown frame `{}`: \"tool\" (the nest turns with the tool, the default) or \"machine\"",
                        f.get_ref()
                    ),
                )
            })?,
        };
        let entries: &[Spanned<RawSensor>] = raw.sensor.as_ref().map_or(&[], |s| s.get_ref());
        if entries.len() > MAX_SENSORS {
            return self.err(
                entries[MAX_SENSORS].span(),
                format!(
                    "the instrument has {} sensors, more than {MAX_SENSORS}, the most an instrument may have",
                    entries.len()
                ),
            );
        }
        let mut sensors: Vec<Sensor> = Vec::with_capacity(entries.len());
        let mut names: Vec<(String, Span)> = Vec::new();
        for entry in entries {
            let s = self.sensor(entry, ball, &names)?;
            names.push((
                s.name.clone(),
                entry
                    .get_ref()
                    .name
                    .as_ref()
                    .map_or(entry.span(), Spanned::span),
            ));
            sensors.push(s);
        }
        // Each sensor's fields first, then their number.
        if entries.len() < MIN_SENSORS {
            let span = entries.last().map_or(name.span(), Spanned::span);
            return self.err(
                span,
                format!(
                    "the instrument has {} sensor{}; at least {MIN_SENSORS} are needed to read the three components of the displacement (one [[sensor]] entry each)",
                    entries.len(),
                    if entries.len() == 1 { "" } else { "s" }
                ),
            );
        }
        let instrument = Instrument {
            name: name.get_ref().clone(),
            description: self.description(raw.description.as_ref())?,
            ball_radius_mm: ball,
            frame,
            sensors,
        };
        let sv = smallest_singular_value(&first_order_matrix(&instrument));
        if !(sv.is_finite() && sv >= MIN_LAYOUT_SINGULAR_VALUE) {
            return self.err(
                entries[0].span(),
                format!(
                    "the sensors' measuring directions do not span the three dimensions: a displacement in the worst direction moves the readings by only {} of its size (root sum of squares; at least {MIN_LAYOUT_SINGULAR_VALUE} is needed to determine the displacement)",
                    compact((sv * 1e4).round() / 1e4)
                ),
            );
        }
        Ok(instrument)
    }

    /// The `description`, trimmed; empty when there is none ([`crate::text::description_text`]).
    fn description(&self, raw: Option<&Spanned<String>>) -> Res<String> {
        crate::text::description_text(raw).or_else(|(span, why)| self.err(span, why))
    }

    fn instrument_name(&self, name: &Spanned<String>) -> Res<()> {
        let n = name.get_ref();
        if n.chars().count() > MAX_NAME_CHARS {
            return self.err(
                name.span(),
                format!(
                    "instrument name has {} characters, more than {MAX_NAME_CHARS}, the longest name",
                    n.chars().count()
                ),
            );
        }
        if n.is_empty()
            || !n
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
        {
            return self.err(
                name.span(),
                format!("instrument name `{n}` must be letters, digits, `-` or `_`"),
            );
        }
        Ok(())
    }

    /// A finite number of `what` in `unit`, above `bounds.0` (exclusive) and at most `bounds.1`.
    fn number(
        &self,
        v: &Spanned<Num>,
        what: &str,
        unit: &str,
        bounds: (f64, f64),
        rule: &str,
    ) -> Res<f64> {
        let x = v.get_ref().0;
        if !(x.is_finite() && x > bounds.0 && x <= bounds.1) {
            return self.err(
                v.span(),
                format!(
                    "{what} is {} {unit}; {rule} {} {unit}",
                    compact(x),
                    compact(bounds.1)
                ),
            );
        }
        Ok(x)
    }

    /// A value written in µm, in mm: the decimal point moved in the text as written, so that
    /// it is rounded once (`0.1` µm is the `f64` nearest 0.0001 mm).
    fn micrometres(&self, v: &Spanned<Num>) -> f64 {
        let text: String = self.loc.text[v.span()]
            .chars()
            .filter(|&c| c != '_')
            .collect();
        parse_scaled(&text, -3).unwrap_or(v.get_ref().0 / 1e3)
    }

    /// Three finite numbers of `what` (`direction`, `position_mm`), each at most `bound` in
    /// magnitude.
    fn vector(
        &self,
        sensor: &str,
        what: &str,
        list: &Spanned<Vec<Spanned<Num>>>,
        bound: f64,
    ) -> Res<[f64; 3]> {
        let v = list.get_ref();
        if v.len() != 3 {
            return self.err(
                list.span(),
                format!(
                    "sensor {sensor}: `{what}` needs three numbers [x, y, z] (nest frame), found {}",
                    v.len()
                ),
            );
        }
        let mut out = [0.0; 3];
        for (k, x) in v.iter().enumerate() {
            let value = x.get_ref().0;
            if !value.is_finite() || value.abs() > bound {
                return self.err(
                    x.span(),
                    format!(
                        "sensor {sensor}: `{what}` has the number {}; its entries must be finite and at most {} in magnitude",
                        compact(value),
                        compact(bound)
                    ),
                );
            }
            out[k] = value;
        }
        Ok(out)
    }

    fn sensor(
        &self,
        entry: &Spanned<RawSensor>,
        ball: f64,
        earlier: &[(String, Span)],
    ) -> Res<Sensor> {
        let raw = entry.get_ref();
        let Some(name_value) = &raw.name else {
            return self.err(
                entry.span(),
                "this [[sensor]] entry has no `name` (s1, s2, …; its CSV column is the name followed by `_um`)",
            );
        };
        let name = name_value.get_ref().clone();
        self.sensor_name(name_value, earlier)?;
        let Some(direction) = &raw.direction else {
            return self.err(
                name_value.span(),
                format!(
                    "sensor {name} has no `direction = [x, y, z]`: its measuring direction in the nest frame (the reading grows when the error vector, nest minus ball, moves along it)"
                ),
            );
        };
        let d = self.vector(&name, "direction", direction, f64::MAX)?;
        let norm2 = dot(d, d);
        if !(norm2.is_finite() && norm2 > 0.0) {
            return self.err(
                direction.span(),
                format!(
                    "sensor {name}: `direction` is the zero vector (or too large to normalise): give the measuring direction"
                ),
            );
        }
        // A unit vector is kept as written, so that a description written back reads back
        // to the same numbers.
        let direction_unit = if (norm2 - 1.0).abs() <= 4.0 * f64::EPSILON {
            d
        } else {
            d.map(|v| v / norm2.sqrt())
        };
        let tip = self.tip(&name, name_value, raw)?;
        let position = match &raw.position_mm {
            None => Sensor::default_position(direction_unit, tip, ball),
            Some(p) => self.vector(&name, "position_mm", p, MAX_POSITION_MM)?,
        };
        let gain = match &raw.gain {
            None => 1.0,
            Some(g) => {
                let x = g.get_ref().0;
                if !(x.is_finite() && x >= GAIN_RANGE.0 && x <= GAIN_RANGE.1) {
                    return self.err(
                        g.span(),
                        format!(
                            "sensor {name}: `gain` is {}; a calibrated gain (reading per plunger travel, 1 nominal) must be from {} to {}",
                            compact(x),
                            GAIN_RANGE.0,
                            GAIN_RANGE.1
                        ),
                    );
                }
                x
            }
        };
        let noise_mm = match &raw.noise_um {
            None => super::DEFAULT_NOISE_UM / 1e3,
            Some(n) => {
                self.number(
                    n,
                    &format!("sensor {name}: `noise_um`"),
                    "µm",
                    (0.0, MAX_NOISE_UM),
                    "the standard deviation of a reading must be above 0 and at most",
                )?;
                self.micrometres(n)
            }
        };
        let zero_mm = match &raw.zero_um {
            None => 0.0,
            Some(z) => {
                let x = z.get_ref().0;
                if !(x.is_finite() && x.abs() <= MAX_ZERO_UM) {
                    return self.err(
                        z.span(),
                        format!(
                            "sensor {name}: `zero_um` is {} µm; it must be finite and at most {} µm in magnitude",
                            compact(x),
                            compact(MAX_ZERO_UM)
                        ),
                    );
                }
                self.micrometres(z)
            }
        };
        let sensor = Sensor {
            name,
            direction: direction_unit,
            position_mm: position,
            tip,
            gain,
            noise_mm,
            zero_mm,
        };
        if let Some(p) = &raw.position_mm {
            self.contact(&sensor, ball, p.span())?;
        }
        Ok(sensor)
    }

    fn sensor_name(&self, v: &Spanned<String>, earlier: &[(String, Span)]) -> Res<()> {
        let n = v.get_ref();
        if n.chars().count() > MAX_SENSOR_NAME_CHARS || !is_identifier(n) {
            return self.err(
                v.span(),
                format!(
                    "sensor name `{n}` must be a letter, then letters, digits or `_`, at most {MAX_SENSOR_NAME_CHARS} characters (s1, s2, …)"
                ),
            );
        }
        if RESERVED_SENSOR_NAMES
            .iter()
            .any(|r| r.eq_ignore_ascii_case(n))
        {
            return self.err(
                v.span(),
                format!(
                    "sensor name `{n}` is reserved: its column `{n}_um` is a column of the error vector (dx_um, dy_um, dz_um)"
                ),
            );
        }
        if let Some((_, first)) = earlier.iter().find(|(e, _)| e.eq_ignore_ascii_case(n)) {
            return self.err(
                v.span(),
                format!(
                    "sensor name `{n}` is used twice (first on line {}; names are matched without regard to case, like CSV columns)",
                    self.line(first)
                ),
            );
        }
        Ok(())
    }

    fn tip(&self, name: &str, name_value: &Spanned<String>, raw: &RawSensor) -> Res<Tip> {
        let Some(kind) = &raw.tip else {
            return self.err(
                name_value.span(),
                format!(
                    "sensor {name} has no `tip`: \"flat\" (with `face_radius_mm`) or \"sphere\" (with `tip_radius_mm`)"
                ),
            );
        };
        let radius = |v: &Spanned<Num>, what: &str| {
            self.number(
                v,
                &format!("sensor {name}: `{what}`"),
                "mm",
                (0.0, MAX_TIP_RADIUS_MM),
                "it must be above 0 and at most",
            )
        };
        match kind.get_ref().as_str() {
            "flat" => {
                if let Some(r) = &raw.tip_radius_mm {
                    return self.err(
                        r.span(),
                        format!(
                            "sensor {name}: `tip_radius_mm` belongs to a ball tip (tip = \"sphere\"); a flat tip has `face_radius_mm`"
                        ),
                    );
                }
                let Some(r) = &raw.face_radius_mm else {
                    return self.err(
                        kind.span(),
                        format!(
                            "sensor {name}: a flat tip needs `face_radius_mm` (the radius of its face, mm)"
                        ),
                    );
                };
                Ok(Tip::Flat {
                    face_radius_mm: radius(r, "face_radius_mm")?,
                })
            }
            "sphere" => {
                if let Some(r) = &raw.face_radius_mm {
                    return self.err(
                        r.span(),
                        format!(
                            "sensor {name}: `face_radius_mm` belongs to a flat tip (tip = \"flat\"); a ball tip has `tip_radius_mm`"
                        ),
                    );
                }
                let Some(r) = &raw.tip_radius_mm else {
                    return self.err(
                        kind.span(),
                        format!(
                            "sensor {name}: a ball tip needs `tip_radius_mm` (the radius of the tip's ball, mm)"
                        ),
                    );
                };
                Ok(Tip::Sphere {
                    radius_mm: radius(r, "tip_radius_mm")?,
                })
            }
            other => self.err(
                kind.span(),
                format!("sensor {name}: unknown tip `{other}` (\"flat\" or \"sphere\")"),
            ),
        }
    }

    /// The given tip position touches the ball at zero reading: a ball tip's centre at
    /// `R + r` from the nest centre with its plunger pointing near it, a flat face on the plane
    /// tangent to the ball with the contact on the face.
    fn contact(&self, s: &Sensor, ball: f64, span: Span) -> Res<()> {
        let p = s.position_mm;
        let n = s.plunger_axis();
        let (name, tol) = (&s.name, POSITION_TOLERANCE_MM);
        match s.tip {
            Tip::Sphere { radius_mm } => {
                let rho = ball + radius_mm;
                let dist = dot(p, p).sqrt();
                if (dist - rho).abs() > tol {
                    return self.err(
                        span,
                        format!(
                            "sensor {name}: the tip centre is {} mm from the nest centre; a ball tip of radius {} mm touching the ball (radius {} mm) at zero reading is {} mm from it (within {tol} mm)",
                            compact((dist * 1e6).round() / 1e6),
                            compact(radius_mm),
                            compact(ball),
                            compact(rho)
                        ),
                    );
                }
                let cos = dot(n, p) / dist;
                if !(cos.is_finite() && cos >= MAX_CONTACT_ANGLE_DEG.to_radians().cos()) {
                    return self.err(
                        span,
                        format!(
                            "sensor {name}: the plunger axis points {}° away from the ball centre (the line from the ball centre to the tip centre and the plunger axis −direction); at most {MAX_CONTACT_ANGLE_DEG}°",
                            compact((cos.clamp(-1.0, 1.0).acos().to_degrees() * 10.0).round() / 10.0)
                        ),
                    );
                }
            }
            Tip::Flat { face_radius_mm } => {
                let along = dot(n, p);
                if (along - ball).abs() > tol {
                    return self.err(
                        span,
                        format!(
                            "sensor {name}: the face centre is {} mm from the nest centre along the plunger axis; a flat face touching the ball (radius {} mm) at zero reading is on the tangent plane at {} mm (within {tol} mm)",
                            compact((along * 1e6).round() / 1e6),
                            compact(ball),
                            compact(ball)
                        ),
                    );
                }
                let lateral = (dot(p, p) - along * along).max(0.0).sqrt();
                if lateral >= face_radius_mm {
                    return self.err(
                        span,
                        format!(
                            "sensor {name}: the ball touches the face {} mm from its centre at zero reading, beyond its radius of {} mm",
                            compact((lateral * 1e6).round() / 1e6),
                            compact(face_radius_mm)
                        ),
                    );
                }
            }
        }
        Ok(())
    }
}
