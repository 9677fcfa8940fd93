//! An instrument as the text of its TOML description: every key written, every number the
//! shortest decimal that reads back to the same `f64` (mm as mm, µm values with the decimal
//! point moved, [`crate::units::format_scaled`]), so that [`super::parse_instrument`] of the
//! text gives the same instrument.

use super::{Instrument, Tip};
use crate::units::format_scaled;

/// A string as a TOML basic string (quoted, escaped).
fn quoted(s: &str) -> String {
    toml::Value::String(s.to_string()).to_string()
}

fn mm(x: f64) -> String {
    format_scaled(x, 0)
}

fn vector(v: [f64; 3]) -> String {
    format!("[{}, {}, {}]", mm(v[0]), mm(v[1]), mm(v[2]))
}

/// The TOML text of `instrument`: `comments` as `# ` lines at the head (a comment of several
/// lines gives several), then every key of the description and of each `[[sensor]]`, the tip
/// positions as they are held (not moved onto the contact).
pub fn to_toml(instrument: &Instrument, comments: &[String]) -> String {
    let mut out = String::new();
    for c in comments {
        for l in c.lines() {
            out += "# ";
            out += l;
            out.push('\n');
        }
    }
    out += &format!("name = {}\n", quoted(&instrument.name));
    if !instrument.description.is_empty() {
        out += &format!("description = {}\n", quoted(&instrument.description));
    }
    out += &format!("ball_radius_mm = {}\n", mm(instrument.ball_radius_mm));
    out += &format!("frame = \"{}\"\n", instrument.frame.keyword());
    for s in &instrument.sensors {
        out += "\n[[sensor]]\n";
        out += &format!("name = {}\n", quoted(&s.name));
        out += &format!("direction = {}\n", vector(s.direction));
        out += &format!("tip = \"{}\"\n", s.tip.keyword());
        match s.tip {
            Tip::Flat { face_radius_mm } => {
                out += &format!("face_radius_mm = {}\n", mm(face_radius_mm));
            }
            Tip::Sphere { radius_mm } => {
                out += &format!("tip_radius_mm = {}\n", mm(radius_mm));
            }
        }
        out += &format!("position_mm = {}\n", vector(s.position_mm));
        out += &format!("gain = {}\n", mm(s.gain));
        out += &format!("noise_um = {}\n", format_scaled(s.noise_mm, 3));
        out += &format!("zero_um = {}\n", format_scaled(s.zero_mm, 3));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::super::{PRESETS, parse_instrument, preset};
    use super::*;

    #[test]
    fn presets_read_back_to_themselves() {
        for (name, _) in PRESETS {
            let i = preset(name).unwrap().unwrap();
            let text = to_toml(&i, &["written back".into()]);
            let back =
                parse_instrument("back.toml", &text).unwrap_or_else(|e| panic!("{e}\n{text}"));
            assert_eq!(back, i, "{text}");
        }
    }
}
