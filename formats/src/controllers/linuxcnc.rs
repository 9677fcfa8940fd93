//! LinuxCNC's files: a HAL file that sets a kinematics module's pins ([`hal_file`]) and a joint
//! compensation file ([`comp_file`]).
//!
//! **HAL** (LinuxCNC's HAL manual, "halcmd" and the `setp` command): one `setp MODULE.PIN VALUE`
//! per pin, `#` comment lines before them. Loaded by a `[HAL] HALFILE =` line of the INI after
//! the file that loads the kinematics module. Values are the shortest decimals that read back
//! to the same `f64` (mm).
//!
//! **Joint compensation** (LinuxCNC's INI configuration manual, `[JOINT_n]` `COMP_FILE` and
//! `COMP_FILE_TYPE`): one line per point, three numbers separated by spaces, the joint's nominal
//! position and, for `COMP_FILE_TYPE = 1`, the correction added to the motor command while the
//! joint moves forward (its position increasing) and while it moves in reverse, in the joint's
//! units (mm or degrees). At most [`MAX_COMP_POINTS`] points, ascending; outside the first and
//! the last point LinuxCNC holds the end value. The file has no comment syntax (LinuxCNC stops
//! reading at the first line that is not three numbers, so a header line would silently
//! disable the table): what it is for is written in the HAL file's comments instead.

use model_spec::units::format_scaled;

/// The most points LinuxCNC's joint compensation reads per joint.
pub const MAX_COMP_POINTS: usize = 256;

/// One pin of a HAL component and its value.
#[derive(Clone, Debug, PartialEq)]
pub struct Pin {
    /// The pin's name after the component's (`x-rot-point`).
    pub name: &'static str,
    /// The value (mm).
    pub value: f64,
}

/// The HAL file of a kinematics module's pins: comment lines, then `setp` lines. The comments
/// are written as given, each behind `# ` (line breaks inside one become lines of their own).
pub fn hal_file(component: &str, comments: &[String], pins: &[Pin]) -> String {
    let mut out = String::new();
    for c in comments {
        for line in c.lines() {
            out += if line.is_empty() { "#" } else { "# " };
            out += line;
            out.push('\n');
        }
    }
    for p in pins {
        out += &format!(
            "setp {component}.{} {}\n",
            p.name,
            format_scaled(p.value + 0.0, 0)
        );
    }
    out
}

/// One point of a joint compensation table (joint units: mm or degrees).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CompPoint {
    /// The joint's nominal position.
    pub position: f64,
    /// What LinuxCNC adds to the motor command at this position while the joint moves forward.
    pub forward: f64,
    /// What it adds while the joint moves in reverse.
    pub reverse: f64,
}

/// Why a joint compensation table cannot be written.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum CompFileError {
    /// More points than LinuxCNC reads.
    #[error(
        "joint {joint}: {points} points, more than the {MAX_COMP_POINTS} LinuxCNC reads per joint"
    )]
    TooManyPoints {
        /// The joint number.
        joint: usize,
        /// How many points the table has.
        points: usize,
    },
    /// Positions not strictly ascending, or a value not finite.
    #[error("joint {joint}: point {point}: {why}")]
    BadPoint {
        /// The joint number.
        joint: usize,
        /// The 1-based point.
        point: usize,
        /// Why.
        why: String,
    },
}

/// The text of the compensation file of joint `joint`: one `position forward reverse` line per
/// point, nothing else.
///
/// # Errors
/// [`CompFileError`] for more than [`MAX_COMP_POINTS`] points, positions that do not ascend
/// strictly, or a value that is not finite.
pub fn comp_file(joint: usize, points: &[CompPoint]) -> Result<String, CompFileError> {
    if points.len() > MAX_COMP_POINTS {
        return Err(CompFileError::TooManyPoints {
            joint,
            points: points.len(),
        });
    }
    let mut out = String::new();
    for (k, p) in points.iter().enumerate() {
        let bad = |why: String| CompFileError::BadPoint {
            joint,
            point: k + 1,
            why,
        };
        if ![p.position, p.forward, p.reverse]
            .iter()
            .all(|v| v.is_finite())
        {
            return Err(bad("a value is not finite".into()));
        }
        if k > 0 && p.position <= points[k - 1].position {
            return Err(bad(format!(
                "position {} does not come after {}",
                p.position,
                points[k - 1].position
            )));
        }
        out += &format!(
            "{} {} {}\n",
            format_scaled(p.position + 0.0, 0),
            format_scaled(p.forward + 0.0, 0),
            format_scaled(p.reverse + 0.0, 0)
        );
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_hal_file_has_its_comments_then_one_setp_per_pin() {
        let text = hal_file(
            "xyzac-trt-kins",
            &["first\nsecond".into(), String::new()],
            &[
                Pin {
                    name: "x-rot-point",
                    value: 0.1,
                },
                Pin {
                    name: "y-offset",
                    value: -0.0,
                },
            ],
        );
        assert_eq!(
            text,
            "# first\n# second\nsetp xyzac-trt-kins.x-rot-point 0.1\nsetp xyzac-trt-kins.y-offset 0\n"
        );
    }

    #[test]
    fn a_comp_file_is_three_numbers_per_line_and_refuses_what_linuxcnc_would_misread() {
        let p = |position, forward, reverse| CompPoint {
            position,
            forward,
            reverse,
        };
        let text = comp_file(0, &[p(-10.0, 0.001, 0.002), p(0.0, 0.0, -0.0)]).unwrap();
        assert_eq!(text, "-10 0.001 0.002\n0 0 0\n");
        let e = comp_file(2, &[p(0.0, 0.0, 0.0), p(0.0, 0.0, 0.0)]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "joint 2: point 2: position 0 does not come after 0"
        );
        let e = comp_file(1, &[p(0.0, f64::NAN, 0.0)]).unwrap_err();
        assert!(e.to_string().contains("not finite"));
        let many: Vec<CompPoint> = (0..257).map(|k| p(k as f64, 0.0, 0.0)).collect();
        let e = comp_file(3, &many).unwrap_err();
        assert_eq!(
            e.to_string(),
            "joint 3: 257 points, more than the 256 LinuxCNC reads per joint"
        );
    }
}
