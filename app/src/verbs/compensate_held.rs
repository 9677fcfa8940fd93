//! What a controller output holds of a corrected description and what it does not, in the
//! words the files' comments and the summary share (`--linuxcnc`, `--siemens`).

use compensation::kinematics::CorrectedDescription;
use model_spec::Machine;
use model_spec::units::readable;

/// One line per error the corrected description holds: location translations (an inclined
/// axis's error once, with its share along each machine coordinate), angular errors folded
/// into a direction, identified lengths.
pub fn held_lines(corrected: &CorrectedDescription) -> Vec<String> {
    let mut out = Vec::new();
    let mut seen: Vec<&str> = Vec::new();
    for f in &corrected.folded {
        if seen.contains(&f.name.as_str()) {
            continue;
        }
        seen.push(&f.name);
        let parts: Vec<_> = corrected
            .folded
            .iter()
            .filter(|g| g.name == f.name)
            .collect();
        let value = if parts.len() == 1 {
            format!("{} µm", readable(f.value_mm * 1e3, 4))
        } else {
            parts
                .iter()
                .map(|g| {
                    format!(
                        "{} µm along {}",
                        readable(g.value_mm * 1e3, 4),
                        g.coordinate
                    )
                })
                .collect::<Vec<_>>()
                .join(", ")
        };
        out.push(format!(
            "Held: {} = {value}, in the {} axis line.",
            f.name, f.axis
        ));
    }
    for d in &corrected.directions {
        for e in &d.errors {
            out.push(format!(
                "Held: {} = {} µrad, in the direction of the {} axis.",
                e.name,
                readable(e.value_rad * 1e6, 4),
                d.axis
            ));
        }
    }
    for s in &corrected.symbols {
        out.push(format!(
            "Held: {} changed by {} µm (a length of the description).",
            s.name,
            readable(s.change_mm * 1e3, 4)
        ));
    }
    out
}

/// One line per compensated term the corrected description could not hold, with its values
/// (µm or µrad) and why, except the errors in `held_elsewhere` (held by a table).
pub fn not_folded_lines(
    m: &Machine,
    corrected: &CorrectedDescription,
    held_elsewhere: &[&str],
) -> Vec<String> {
    let mut out = Vec::new();
    for n in &corrected.not_folded {
        let error = n.spelling.split('@').next().unwrap_or(&n.spelling);
        if held_elsewhere.contains(&error) {
            continue;
        }
        let factor = n.term.effect.display_factor(m);
        let unit = match n.term.unit(m) {
            "urad" => "µrad",
            "um" => "µm",
            other => other,
        };
        let values = n
            .values
            .iter()
            .map(|v| readable(v * factor, 4))
            .collect::<Vec<_>>()
            .join(", ");
        out.push(format!("{} = {values} {unit}: {}", n.spelling, n.reason));
    }
    out
}

/// The closing comment lines: `Not held: nothing.`, or the heading and one line per term.
pub fn not_held_block(not_held: &[String]) -> Vec<String> {
    if not_held.is_empty() {
        return vec!["Not held: nothing.".to_string()];
    }
    let mut out = vec![
        "Not held here (a program corrected with `rtest compensate --path` holds them):"
            .to_string(),
    ];
    out.extend(not_held.iter().map(|l| format!("  {l}")));
    out
}
