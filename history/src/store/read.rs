//! Reading recorded checks back: every row of a check gathered into a [`Check`], checks in
//! the order of their measurement times (then of their ids).

use super::Store;
use crate::check::{Check, CheckKind, InputFile, Parameter};
use crate::error::HistoryError;
use formats::time::Timestamp;
use rusqlite::{Row, params};
use serde::Serialize;
use std::collections::HashMap;

/// A check as stored, with its id.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RecordedCheck {
    /// Its id in the database (1, 2, …; `rtest history` lists it).
    pub id: i64,
    /// The check.
    #[serde(flatten)]
    pub check: Check,
}

/// One machine id of a database and its checks, in short.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MachineSummary {
    /// The machine id.
    pub machine_id: String,
    /// Checks recorded.
    pub checks: usize,
    /// The descriptions' names it was identified with, first seen first.
    pub machines: Vec<String>,
    /// Their fingerprints, first seen first (more than one: the description changed).
    pub fingerprints: Vec<String>,
    /// The first measurement time.
    pub first: Timestamp,
    /// The last measurement time.
    pub last: Timestamp,
}

fn usize_of(x: i64) -> usize {
    usize::try_from(x).unwrap_or(0)
}

impl Store {
    /// Every check of `machine_id` (of every machine when `None`), ordered by measurement time,
    /// then id.
    ///
    /// # Errors
    /// A database failure; [`HistoryError::NotHistory`] for a stored time that cannot be read.
    pub fn checks(&self, machine_id: Option<&str>) -> Result<Vec<RecordedCheck>, HistoryError> {
        let sql = self.sql();
        // One read transaction: every query sees the same snapshot, whatever other processes
        // record meanwhile.
        let _snapshot = self.conn.unchecked_transaction().map_err(&sql)?;
        let filter = "(?1 IS NULL OR c.machine_id = ?1)";
        let mut stmt = self
            .conn
            .prepare(&format!(
                "SELECT c.id, c.machine_id, c.fingerprint, c.machine, c.model, c.base_model,
                        c.recorded_at, c.measured_at, c.rtest_version, c.kind, c.rank,
                        c.free_parameters, c.condition, c.residual_rms_um, c.sigma_um, c.samples,
                        c.dof, c.zeroed, c.constraint_text, c.refinement, c.noise_model,
                        c.recheck
                 FROM checks c WHERE {filter} ORDER BY c.measured_at, c.id"
            ))
            .map_err(&sql)?;
        let rows: Vec<(i64, Check, String, String)> = stmt
            .query_map(params![machine_id], check_row)
            .and_then(Iterator::collect)
            .map_err(&sql)?;
        let mut checks = Vec::with_capacity(rows.len());
        let mut at: HashMap<i64, usize> = HashMap::new();
        for (id, mut check, recorded, measured) in rows {
            check.recorded_at = self.time(id, "recorded_at", &recorded)?;
            check.measured_at = self.time(id, "measured_at", &measured)?;
            at.insert(id, checks.len());
            checks.push(RecordedCheck { id, check });
        }
        let of_machine =
            format!("check_id IN (SELECT c.id FROM checks c WHERE {filter}) ORDER BY check_id");
        self.each(
            &format!("SELECT check_id, term FROM check_terms WHERE {of_machine}, position"),
            machine_id,
            |r| {
                let (id, term): (i64, String) = (r.get(0)?, r.get(1)?);
                Ok((id, term))
            },
            &at,
            &mut checks,
            |c, t| c.terms.push(t),
        )?;
        self.each(
            &format!("SELECT check_id, label FROM check_paths WHERE {of_machine}, position"),
            machine_id,
            |r| Ok((r.get(0)?, r.get::<_, String>(1)?)),
            &at,
            &mut checks,
            |c, p| c.paths.push(p),
        )?;
        self.each(
            &format!("SELECT check_id, role, path, bytes, sha256 FROM check_inputs WHERE {of_machine}, position"),
            machine_id,
            |r| {
                Ok((
                    r.get(0)?,
                    InputFile {
                        role: r.get(1)?,
                        path: r.get(2)?,
                        bytes: u64::try_from(r.get::<_, i64>(3)?).unwrap_or(0),
                        sha256: r.get(4)?,
                    },
                ))
            },
            &at,
            &mut checks,
            |c, f| c.inputs.push(f),
        )?;
        self.each(
            &format!(
                "SELECT check_id, name, error, basis, owner, owner_of, value, std, unit, determined, fixed
                 FROM parameters WHERE {of_machine}, position"
            ),
            machine_id,
            |r| {
                Ok((
                    r.get(0)?,
                    Parameter {
                        name: r.get(1)?,
                        error: r.get(2)?,
                        basis: r.get(3)?,
                        owner: r.get(4)?,
                        of: r.get(5)?,
                        value: r.get(6)?,
                        std: r.get(7)?,
                        unit: r.get(8)?,
                        determined: r.get(9)?,
                        fixed: r.get(10)?,
                    },
                ))
            },
            &at,
            &mut checks,
            |c, q| c.parameters.push(q),
        )?;
        self.each(
            &format!(
                "SELECT check_id, grp, name FROM unidentifiable WHERE {of_machine}, grp, position"
            ),
            machine_id,
            |r| Ok((r.get(0)?, (usize_of(r.get(1)?), r.get::<_, String>(2)?))),
            &at,
            &mut checks,
            |c, (g, name)| {
                while c.unidentifiable.len() <= g {
                    c.unidentifiable.push(Vec::new());
                }
                c.unidentifiable[g].push(name);
            },
        )?;
        Ok(checks)
    }

    /// Runs `query` (rows of `(check id, item)`) and adds each item to its check.
    #[allow(clippy::too_many_arguments)]
    fn each<T>(
        &self,
        query: &str,
        machine_id: Option<&str>,
        row: impl FnMut(&Row<'_>) -> rusqlite::Result<(i64, T)>,
        at: &HashMap<i64, usize>,
        checks: &mut [RecordedCheck],
        mut add: impl FnMut(&mut Check, T),
    ) -> Result<(), HistoryError> {
        let sql = self.sql();
        let mut stmt = self.conn.prepare(query).map_err(&sql)?;
        let items: Vec<(i64, T)> = stmt
            .query_map(params![machine_id], row)
            .and_then(Iterator::collect)
            .map_err(&sql)?;
        for (id, item) in items {
            if let Some(&i) = at.get(&id) {
                add(&mut checks[i].check, item);
            }
        }
        Ok(())
    }

    fn time(&self, id: i64, field: &str, text: &str) -> Result<Timestamp, HistoryError> {
        Timestamp::parse(text).map_err(|e| {
            HistoryError::not_history(&self.path, format!("check {id}: `{field}`: {e}"))
        })
    }

    /// Every machine id with its checks in short, by machine id.
    ///
    /// # Errors
    /// As [`Store::checks`].
    pub fn machines(&self) -> Result<Vec<MachineSummary>, HistoryError> {
        let mut out: Vec<MachineSummary> = Vec::new();
        for rc in self.checks(None)? {
            let c = &rc.check;
            match out.iter_mut().find(|m| m.machine_id == c.machine_id) {
                Some(m) => {
                    m.checks += 1;
                    if !m.machines.contains(&c.machine) {
                        m.machines.push(c.machine.clone());
                    }
                    if !m.fingerprints.contains(&c.fingerprint) {
                        m.fingerprints.push(c.fingerprint.clone());
                    }
                    m.first = m.first.min(c.measured_at);
                    m.last = m.last.max(c.measured_at);
                }
                None => out.push(MachineSummary {
                    machine_id: c.machine_id.clone(),
                    checks: 1,
                    machines: vec![c.machine.clone()],
                    fingerprints: vec![c.fingerprint.clone()],
                    first: c.measured_at,
                    last: c.measured_at,
                }),
            }
        }
        out.sort_by(|a, b| a.machine_id.cmp(&b.machine_id));
        Ok(out)
    }
}

/// One row of `checks`, with its two times as text (parsed by the caller).
fn check_row(r: &Row<'_>) -> rusqlite::Result<(i64, Check, String, String)> {
    let kind: String = r.get(9)?;
    let check = Check {
        machine_id: r.get(1)?,
        fingerprint: r.get(2)?,
        machine: r.get(3)?,
        model: r.get(4)?,
        base_model: r.get(5)?,
        terms: Vec::new(),
        paths: Vec::new(),
        measured_at: Timestamp(0),
        recorded_at: Timestamp(0),
        rtest_version: r.get(8)?,
        kind: if kind == "campaign" {
            CheckKind::Campaign
        } else {
            CheckKind::Record
        },
        recheck: r.get(21)?,
        inputs: Vec::new(),
        parameters: Vec::new(),
        rank: usize_of(r.get(10)?),
        free_parameters: usize_of(r.get(11)?),
        condition: r.get(12)?,
        unidentifiable: Vec::new(),
        residual_rms_um: r.get(13)?,
        sigma_um: r.get(14)?,
        samples: usize_of(r.get(15)?),
        dof: usize_of(r.get(16)?),
        zeroed: r.get(17)?,
        constraint: r.get(18)?,
        refinement: r.get(19)?,
        noise_model: r.get(20)?,
    };
    Ok((r.get(0)?, check, r.get(6)?, r.get(7)?))
}
