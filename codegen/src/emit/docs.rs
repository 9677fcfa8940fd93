//! The doc comments of the emitted items: what the functions compute, in which units and frame,
//! where the gains hold, and when the slice helpers panic. Plain text, one `String` per line
//! (each line becomes one `#[doc = …]` attribute).

use crate::ir::OpCounts;

/// What the arguments hold, and which one a function does not read (its name then starts
/// with `_`).
fn arguments(reads_pose: bool, reads_params: bool) -> Vec<String> {
    let (pose, params) = (
        if reads_pose { "pose" } else { "_pose" },
        if reads_params { "params" } else { "_params" },
    );
    let mut lines = vec![
        format!(
            " `{pose}` holds the sines and cosines of the rotary commands and the linear commands"
        ),
        format!(" (mm); `{params}` holds the kinematic parameters (mm)."),
    ];
    lines.extend(
        match (reads_pose, reads_params) {
            (true, true) => None,
            (true, false) => Some(" These gains do not depend on the kinematic parameters."),
            (false, true) => Some(" These gains do not depend on the pose."),
            (false, false) => Some(" These gains are constants: they depend on neither argument."),
        }
        .map(String::from),
    );
    lines
}

/// Where the gains are exact.
fn precondition() -> Vec<String> {
    [
        " # Precondition",
        "",
        " The gains are the exact first-order gains only where the nominal tool point is on the",
        " nominal workpiece point: at every R-test pose, where the linear axes follow the ball.",
        " Away from such a pose they differ from the gains in the actual, slightly rotated tool",
        " frame by the tool frame's small rotation times the nominal gap between the two points.",
    ]
    .map(String::from)
    .to_vec()
}

/// What the docs of `gains` and `position_gains` end with: the arguments, the precondition and
/// the operation counts.
fn common_tail(counts: OpCounts, reads_pose: bool, reads_params: bool) -> Vec<String> {
    let mut lines = arguments(reads_pose, reads_params);
    lines.push(String::new());
    lines.extend(precondition());
    lines.push(String::new());
    lines.push(format!(
        " Straight-line code, no allocation, no branches: {counts}."
    ));
    lines
}

/// The doc of a model's `gains`.
pub fn gains(n: usize, counts: OpCounts, reads_pose: bool, reads_params: bool) -> Vec<String> {
    let mut lines = vec![
        format!(" First-order gains of the {n} errors at `pose`: `out[i] = [gx, gy, gz, gi, gj, gk]`"),
        " per unit of error `i` (the error named `ERRORS[i]`), in the nominal tool frame."
            .to_string(),
        String::new(),
        " `[gx, gy, gz]` is the displacement of the tool point relative to the workpiece point"
            .to_string(),
        " (tool minus workpiece): mm per mm of a translational error, mm per rad of an angular"
            .to_string(),
        " error. `[gi, gj, gk]` is the change of the unit tool direction relative to the workpiece:"
            .to_string(),
        " per mm of a translational error, per rad of an angular error.".to_string(),
        String::new(),
    ];
    lines.extend(common_tail(counts, reads_pose, reads_params));
    lines
}

/// The doc of a model's `position_gains`.
pub fn position_gains(counts: OpCounts, reads_pose: bool, reads_params: bool) -> Vec<String> {
    let mut lines = vec![
        " First-order position gains only, in the layout of three rows of an H matrix: `out[d][i]`"
            .to_string(),
        " is the gain of error `i` in direction `d` (x, y, z of the nominal tool frame; tool minus"
            .to_string(),
        " workpiece): mm per mm of a translational error, mm per rad of an angular error. The"
            .to_string(),
        " orientation rows are not computed.".to_string(),
        String::new(),
    ];
    lines.extend(common_tail(counts, reads_pose, reads_params));
    lines
}

/// The `# Panics` section of a slice helper whose slice arguments must have these lengths:
/// `(argument, what it holds, length)`.
pub fn panics(lengths: &[(&str, &str, usize)]) -> Vec<String> {
    let mut lines = vec![String::new(), " # Panics".to_string(), String::new()];
    for (k, (arg, what, len)) in lengths.iter().enumerate() {
        let lead = if k == 0 { " If" } else { " or if" };
        let end = if k + 1 == lengths.len() { "." } else { "," };
        lines.push(format!(
            "{lead} `{arg}` does not hold exactly {len} values ({what}){end}"
        ));
    }
    lines
}
