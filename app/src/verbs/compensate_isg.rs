//! `rtest compensate --isg FILE`: the machine's identified errors as ISG-kernel's volumetric
//! compensation file (Beckhoff TwinCAT CNC, format `ISG_CSV`): the position errors, then one
//! block per axis of its component errors against its position. See docs/controllers.md.

use super::{Error, VerbResult};
use compensation::controllers::isg::{IsgError, isg_volumetric};
use compensation::tables::Pitch;
use compensation::values::{CompensationError, MachineErrors};
use formats::controllers::isg::isg_csv;
use model_spec::Machine;

/// The text of `--isg` and the summary's lines.
pub fn isg_file(
    m: &Machine,
    errors: &MachineErrors,
    pitch: Pitch,
    params_file: &str,
) -> VerbResult<(String, String)> {
    let v = isg_volumetric(m, errors, pitch).map_err(|e| match e {
        IsgError::NotCovered { .. } => Error::usage(format!("--isg: {e}")),
        IsgError::Tables(CompensationError::Pitch { .. }) => Error::usage(format!("--isg: {e}")),
        IsgError::Tables(other) => Error::computation(format!("--isg: {other}")),
    })?;
    let mut comments = vec![
        format!(
            "ISG volumetric compensation (ISG_CSV) of machine {} (fingerprint {}) with the values of {}, written by rtest.",
            m.name,
            m.fingerprint(),
            params_file.replace(['\n', '\r'], " ")
        ),
        "Values: the identified errors in the ISO 230-1 sign convention (along or about the positive coordinate directions), mm and rad; arguments mm and degrees. ISG's documentation does not say whether it takes errors or corrections: check one axis on the machine, and use the list file's `negate` if it takes corrections.".to_string(),
        format!(
            "Chains: workpiece side from the workpiece, then tool side from the bed: {} ({} on the workpiece side); the list file's `chain` and `workpiece_axes` describe them, in an order ISG's documentation does not define here: check it against its example (CBYXZ for an X Y Z B C machine with B and C on the workpiece side).",
            v.chain, v.workpiece_axes
        ),
        "Blocks: the position errors (rtest's XOC is ISG's X0C), then one block per axis with component errors, every row a position of its axis.".to_string(),
    ];
    if v.not_held.is_empty() {
        comments.push("Not held: nothing.".to_string());
    } else {
        comments.push("Not held:".to_string());
        comments.extend(v.not_held.iter().map(|(t, why)| format!("  {t}: {why}")));
    }
    let text =
        isg_csv(&comments, &v.blocks).map_err(|e| Error::computation(format!("--isg: {e}")))?;
    let mut summary = format!(
        "ISG volumetric compensation: {} block{} ({})\n",
        v.blocks.len(),
        if v.blocks.len() == 1 { "" } else { "s" },
        v.blocks
            .iter()
            .map(|b| b.columns.join(" "))
            .collect::<Vec<_>>()
            .join("; ")
    );
    for (t, why) in &v.not_held {
        summary += &format!("  not held: {t}: {why}\n");
    }
    Ok((text, summary))
}
