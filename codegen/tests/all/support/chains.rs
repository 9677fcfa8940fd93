//! Synthetic machines of any length, for the scaling benchmark, the `chain_scaling` example and
//! the tests of long chains: a serial arm on the tool side and a rotary table stack on the work
//! side, with every offset a kinematic symbol.
//!
//! `rotary` rotary axes in all, taken in turn by the arm (axes 0, 2, 4, …, from its base to the
//! tool) and the table (axes 1, 3, 5, …, from the bed to the workpiece), so that each machine
//! is the one before with one more axis at the end of one chain. Along the arm the axes turn
//! about x, z, −y and `[0, 1, 1]` in turn (an inclined axis, frame entries in `√2`), along the
//! table about z, x, `[1, 1, 1]` (`√2`, `√3`) and −y. With `linear`, the tool chain starts with
//! X, Y and Z slides (so that the tool-centre-point inverse kinematics puts the tool on the
//! ball); a machine has at most 16 axes, so `linear` allows at most 13 rotary axes.

/// The letters of the rotary axes, in order (no E, O or W; X, Y and Z are the slides).
const LETTERS: &[u8] = b"ABCDFGHIJKLMNPQRSTUV";

/// The direction of the `k`-th rotary axis of the arm (`arm`) or the table.
fn direction(k: usize, arm: bool) -> &'static str {
    const ARM: [&str; 4] = ["\"+x\"", "\"+z\"", "\"-y\"", "[0, 1, 1]"];
    const TABLE: [&str; 4] = ["\"+z\"", "\"+x\"", "[1, 1, 1]", "\"-y\""];
    if arm { ARM[k % 4] } else { TABLE[k % 4] }
}

/// The description of the synthetic machine with `rotary` rotary axes (1 to 16; at most 13
/// with `linear`).
pub fn synthetic_machine(rotary: usize, linear: bool) -> String {
    assert!(
        (1..=16).contains(&rotary) && (!linear || rotary <= 13),
        "1 to 16 rotary axes, at most 13 with the three slides"
    );
    let arm = rotary.div_ceil(2);
    let mut symbols = String::from("[symbols]\n");
    let mut work = String::new();
    let mut tool = String::new();
    let axis = |out: &mut String, symbols: &mut String, i: usize, arm: bool| {
        let letter = LETTERS[i] as char;
        // Lever arms of a few hundred mm along the arm, small lateral offsets; the table
        // stack is compact.
        let (x, y, z) = if arm {
            (10.0 + i as f64, -5.0 - i as f64, 150.0 + 10.0 * i as f64)
        } else {
            (20.0 + i as f64, 15.0 - i as f64, 40.0 + 5.0 * i as f64)
        };
        symbols.push_str(&format!(
            "{letter}x = {x}\n{letter}y = {y}\n{letter}z = {z}\n"
        ));
        out.push_str(&format!(
            "[[{side}]]\naxis = \"{letter}\"\ntype = \"rotary\"\ndirection = {dir}\n\
             offset = [\"{letter}x\", \"{letter}y\", \"{letter}z\"]\n\n",
            side = if arm { "tool" } else { "work" },
            dir = direction(i / 2, arm),
        ));
    };
    for i in (1..rotary).step_by(2) {
        axis(&mut work, &mut symbols, i, false);
    }
    symbols.push_str("wx = 30.0\nwy = -20.0\nwz = 60.0\ntx = 0.0\nty = 0.0\ntz = -120.0\n");
    work.push_str("[[work]]\nend = \"ball\"\noffset = [\"wx\", \"wy\", \"wz\"]\n\n");
    if linear {
        for (name, stroke) in [("X", 2000), ("Y", 2000), ("Z", 2000)] {
            tool.push_str(&format!(
                "[[tool]]\naxis = \"{name}\"\ntype = \"linear\"\ndirection = \"+{}\"\n\
                 stroke = [-{stroke}, {stroke}]\n\n",
                name.to_ascii_lowercase()
            ));
        }
    }
    for i in (0..rotary).step_by(2) {
        axis(&mut tool, &mut symbols, i, true);
    }
    tool.push_str("[[tool]]\nend = \"probe\"\noffset = [\"tx\", \"ty\", \"tz\"]\n");
    format!(
        "name = \"chain-{rotary}{}\"\ndescription = \"Synthetic chain: {arm} rotary axes on the tool side, {} on the work side, every offset a symbol.\"\n\n{symbols}\n{work}{tool}",
        if linear { "-xyz" } else { "" },
        rotary - arm
    )
}

/// The synthetic machine, parsed.
pub fn synthetic(rotary: usize, linear: bool) -> model_spec::Machine {
    let text = synthetic_machine(rotary, linear);
    model_spec::parse_machine(&format!("chain-{rotary}.toml"), &text)
        .unwrap_or_else(|e| panic!("the synthetic chain is valid: {e}\n{text}"))
}
