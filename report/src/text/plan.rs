//! A plan for people: the planned records, the predicted uncertainty of every parameter (or why
//! there is none), rank, condition number, the groups the plan cannot separate, and the
//! suggestion with the ranking of its best candidates and the candidates the generator refuses.

use super::{header, table, value};
use crate::json::plan::{CandidateReport, LargestReport, PlanReport};
use model_spec::units::{fixed, plural, short, symbol};

/// The whole plan text; the ranking shows the `top` best candidates.
pub fn plan(r: &PlanReport, top: usize) -> String {
    let mut out = intro(r);
    out.push('\n');
    out.push_str(&balls(r));
    out.push_str(&records(r));
    out.push('\n');
    out.push_str(&parameters(r));
    out.push('\n');
    out.push_str(&summary(r));
    out.push('\n');
    out.push_str(&suggestion(r, top));
    out.push_str(&separation(r));
    out
}

/// A position term and a time term the plan does not separate, and the reversed or
/// there-and-back test that does; empty when there is none.
fn separation(r: &PlanReport) -> String {
    let Some(sep) = &r.separation else {
        return String::new();
    };
    let pairs: Vec<String> = sep
        .pairs
        .iter()
        .map(|p| {
            format!(
                "{} and {} (correlation {})",
                p.position,
                p.time,
                fixed(p.correlation, 3)
            )
        })
        .collect();
    let mut out = format!(
        "\nPosition against time: the plan does not separate {} (the estimates of an error that depends on an axis's position and of a term of time correlate by {} or more: the axis moves monotonically in time).\n",
        pairs.join(", "),
        fixed(sep.threshold, 2)
    );
    match sep.candidates.first() {
        Some(best) => {
            out.push_str(&format!(
                "Separation: add {} to --paths: the largest such correlation is then {}",
                best.paths_item,
                fixed(best.largest_correlation, 3)
            ));
            let others: Vec<String> = sep.candidates[1..]
                .iter()
                .map(|c| format!("{} {}", c.paths_item, fixed(c.largest_correlation, 3)))
                .collect();
            if !others.is_empty() {
                out.push_str(&format!(" (the others: {})", others.join(", ")));
            }
            out.push_str(".\n");
        }
        None => out.push_str(
            "Separation: no reversed or there-and-back version of a planned test could be generated.\n",
        ),
    }
    out
}

/// What is planned and what the numbers assume.
fn intro(r: &PlanReport) -> String {
    let n = r.records.len();
    let setups = if r.shared_setup {
        "records at one ball position share one ball set-up"
    } else {
        "each record on its own ball set-up"
    };
    format!(
        "Plan on machine {}, model {} ({} parameter{}): {n} record{}, {} samples ({} readings), readings {}, {setups}.\n\
         Reading noise assumed: {}. The uncertainties are those a fit of these records would report \
         (generalized least squares under this noise, first order); nothing is measured.\n",
        r.machine,
        r.model,
        r.columns,
        plural(r.columns, "s"),
        plural(n, "s"),
        r.samples,
        r.readings,
        if r.zeroed {
            "zeroed at each record's first sample (each record's dx0 dy0 dz0 fitted)"
        } else {
            "not zeroed"
        },
        r.noise.text,
    )
}

/// The ball positions: the base's ball symbols, the others' parameters that differ from it.
fn balls(r: &PlanReport) -> String {
    let Some(base) = r.balls.first() else {
        return String::new();
    };
    let list = |b: &[&(String, f64)]| -> String {
        b.iter()
            .map(|(k, v)| format!("{k} = {}", short(*v)))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let own: Vec<&(String, f64)> = base
        .params_mm
        .0
        .iter()
        .filter(|(k, _)| r.ball_symbols.contains(k))
        .collect();
    let mut out = format!(
        "Ball positions (mm):\n  {}: {}\n",
        base.name,
        if own.is_empty() {
            "the machine's ball offset holds no symbol".to_string()
        } else {
            list(&own)
        }
    );
    for b in &r.balls[1..] {
        let diff: Vec<&(String, f64)> = b
            .params_mm
            .0
            .iter()
            .zip(&base.params_mm.0)
            .filter(|(x, y)| x.1 != y.1)
            .map(|(x, _)| x)
            .collect();
        out.push_str(&format!(
            "  {}: {}\n",
            b.name,
            if diff.is_empty() {
                format!("as {}", base.name)
            } else {
                format!("{} (the others as {})", list(&diff), base.name)
            }
        ));
    }
    out.push('\n');
    out
}

/// The planned records: label, test, ball position, set-up (left-aligned), samples.
fn records(r: &PlanReport) -> String {
    let rows: Vec<[String; 5]> = r
        .records
        .iter()
        .map(|x| {
            [
                x.label.clone(),
                x.test.clone(),
                x.ball.clone(),
                x.setup.clone(),
                x.samples.to_string(),
            ]
        })
        .collect();
    let head = ["record", "test", "ball", "set-up", "samples"];
    let mut w = head.map(|h| h.chars().count());
    for row in &rows {
        for (k, c) in row.iter().enumerate() {
            w[k] = w[k].max(c.chars().count());
        }
    }
    let line = |c: [&str; 5]| {
        format!(
            "{:<a$}  {:<b$}  {:<d$}  {:<e$}  {:>f$}\n",
            c[0],
            c[1],
            c[2],
            c[3],
            c[4],
            a = w[0],
            b = w[1],
            d = w[2],
            e = w[3],
            f = w[4]
        )
    };
    let mut out = line(head);
    let rules = w.map(|n| "-".repeat(n));
    out.push_str(&line([
        &rules[0], &rules[1], &rules[2], &rules[3], &rules[4],
    ]));
    for row in &rows {
        out.push_str(&line([&row[0], &row[1], &row[2], &row[3], &row[4]]));
    }
    out
}

/// The table of parameters: the predicted std with its unit, or why there is none.
fn parameters(r: &PlanReport) -> String {
    let cells: Vec<(String, String, String)> = r
        .parameters
        .iter()
        .map(|p| {
            let std = match p.std {
                Some(s) => value(s),
                None => {
                    let others = r
                        .confounded
                        .iter()
                        .find(|g| g.contains(&p.name))
                        .map(|g| {
                            g.iter()
                                .filter(|n| **n != p.name)
                                .cloned()
                                .collect::<Vec<_>>()
                                .join(", ")
                        })
                        .unwrap_or_default();
                    if others.is_empty() {
                        "not determined: these tests do not see it".to_string()
                    } else {
                        format!("not determined: confounded with {others}")
                    }
                }
            };
            (p.name.clone(), p.owner.clone(), std)
        })
        .collect();
    let width = |f: &dyn Fn(&(String, String, String)) -> usize, title: &str| {
        cells
            .iter()
            .map(f)
            .max()
            .unwrap_or(0)
            .max(title.chars().count())
    };
    let wn = width(&|c| c.0.chars().count(), "parameter");
    let wo = width(&|c| c.1.chars().count(), "owner");
    let wv = r
        .parameters
        .iter()
        .filter_map(|p| p.std.map(|s| value(s).chars().count()))
        .max()
        .unwrap_or(0)
        .max(10);
    let mut out = format!("{:<wn$}  {:<wo$}  predicted std\n", "parameter", "owner");
    out.push_str(&format!(
        "{}  {}  {}\n",
        "-".repeat(wn),
        "-".repeat(wo),
        "-".repeat(wv + 5)
    ));
    for (p, (name, owner, std)) in r.parameters.iter().zip(&cells) {
        let cell = match p.std {
            Some(_) => format!("{std:>wv$} {}", symbol(&p.unit)),
            None => std.clone(),
        };
        out.push_str(&format!("{name:<wn$}  {owner:<wo$}  {cell}\n"));
    }
    out
}

/// A largest uncertainty for people: `BOA 0.1234 µrad (0.025 of its target)`.
fn largest(l: &LargestReport) -> String {
    format!(
        "{} {} {} ({} of its target)",
        l.parameter,
        value(l.std),
        symbol(&l.unit),
        value(l.relative)
    )
}

/// Rank, condition number, confounded groups, near pairs, the largest uncertainty.
fn summary(r: &PlanReport) -> String {
    let mut out = format!(
        "rank {} of {} parameters; condition number {} (column-scaled H)\n",
        r.rank,
        r.columns,
        r.condition
            .map_or("undefined (rank 0)".into(), |c| fixed(c, 1))
    );
    if r.confounded.is_empty() {
        out.push_str("confounded groups: none (the plan determines every parameter)\n");
    } else {
        let groups: Vec<String> = r
            .confounded
            .iter()
            .map(|g| format!("[{}]", g.join(", ")))
            .collect();
        out.push_str(&format!(
            "confounded groups (the plan cannot separate them; no uncertainty for them): {}\n",
            groups.join(" ")
        ));
    }
    for p in &r.near_confounded {
        out.push_str(&format!(
            "nearly confounded: {} and {} (correlation {})\n",
            p.parameters[0],
            p.parameters[1],
            fixed(p.correlation, 4)
        ));
    }
    out.push_str(&format!(
        "targets: {} µm, {} µrad, {} ms; {}\n",
        short(r.targets.um),
        short(r.targets.urad),
        short(r.targets.ms),
        match &r.largest {
            Some(l) => format!("largest predicted uncertainty of interest: {}", largest(l)),
            None => "no parameter of interest is determined".into(),
        }
    ));
    out
}

/// `K2 at base`, `K2 at base.Zw+100`.
fn at(c: &CandidateReport) -> String {
    format!("{} at {}", c.test, c.ball)
}

/// The suggestion, the ranking of the `top` best and the skipped candidates.
fn suggestion(r: &PlanReport, top: usize) -> String {
    let s = &r.suggestion;
    let shared = r.parameters.iter().filter(|p| p.owner == "shared").count();
    let mut out = format!(
        "Parameters of interest: {}.\n",
        if shared > 0 {
            "the machine's (shared by every record); set-up errors and sensor zeros are each record's own"
        } else {
            "every parameter (the model has none shared by the records)"
        }
    );
    let tests: Vec<&str> = {
        let mut t: Vec<&str> = Vec::new();
        for c in &s.ranking {
            if !t.contains(&c.test.as_str()) {
                t.push(&c.test);
            }
        }
        for k in &s.skipped {
            if !t.contains(&k.test.as_str()) {
                t.push(&k.test);
            }
        }
        t
    };
    out.push_str(&format!(
        "Candidates: {} test{} at {} ball position{} (the planned ones, and each moved by {} mm along each ball symbol): {} evaluated, {} skipped.\n",
        tests.len(),
        plural(tests.len(), "s"),
        s.positions.len(),
        plural(s.positions.len(), "s"),
        short(s.step_mm),
        s.evaluated,
        s.skipped.len()
    ));
    let Some(best) = s.ranking.first() else {
        out.push_str("Suggestion: none (every candidate is refused by the generator).\n");
        out.push_str(&skipped(r));
        return out;
    };
    let gain = if best.newly_determined.is_empty() {
        "determines no further parameter of interest".to_string()
    } else {
        format!(
            "determines {} more: {}",
            best.newly_determined.len(),
            best.newly_determined.join(", ")
        )
    };
    let then = match (&r.largest, &best.largest) {
        (Some(b), Some(a)) => format!(
            "; largest uncertainty of interest {} -> {}",
            largest(b),
            largest(a)
        ),
        (None, Some(a)) => format!("; largest uncertainty of interest {}", largest(a)),
        _ => String::new(),
    };
    out.push_str(&format!(
        "Suggestion: add {} (rank {} of {}): {gain}{then}.\n",
        at(best),
        best.rank,
        best.columns
    ));
    out.push_str(&format!(
        "  To follow it: add {} to --paths{}.\n",
        best.paths_item,
        best.ball_arg
            .as_ref()
            .map_or(String::new(), |b| format!(" and --ball {b}"))
    ));
    out.push_str(&format!(
        "\nRanking ({}; the best {} of {}):\n",
        s.criterion,
        top.min(s.ranking.len()),
        s.ranking.len()
    ));
    let rows: Vec<Vec<String>> = s
        .ranking
        .iter()
        .take(top)
        .map(|c| {
            vec![
                c.place.to_string(),
                at(c),
                c.samples.to_string(),
                c.newly_determined.len().to_string(),
                format!("{}/{}", c.rank, c.columns),
                c.largest.as_ref().map_or("-".into(), |l| {
                    format!("{} {} {}", l.parameter, value(l.std), symbol(&l.unit))
                }),
                c.largest.as_ref().map_or("-".into(), |l| value(l.relative)),
                value(c.sum_squares),
            ]
        })
        .collect();
    out.push_str(&table(
        &header(&[
            "place",
            "candidate",
            "samples",
            "newly determined",
            "rank",
            "largest std",
            "std/target",
            "sum (std/target)^2",
        ]),
        &rows,
    ));
    out.push_str(&skipped(r));
    out
}

/// The skipped candidates, one line each.
fn skipped(r: &PlanReport) -> String {
    let s = &r.suggestion.skipped;
    if s.is_empty() {
        return String::new();
    }
    let mut out = format!(
        "\nSkipped candidate{} (the generator refuses {} at that ball position):\n",
        plural(s.len(), "s"),
        if s.len() == 1 { "it" } else { "them" }
    );
    for k in s {
        out.push_str(&format!("  {} at {}: {}\n", k.test, k.ball, k.reason));
    }
    out
}
