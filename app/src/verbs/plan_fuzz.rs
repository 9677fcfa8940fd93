//! Fuzzing of `rtest plan`'s plan arguments (`--paths`, `--ball`, `--param`): valid lists with
//! random damage, and random text, are read into a plan or refused as a usage error naming its
//! flag in one short line, never a panic; a plan that is read is sound (at most
//! [`plan::MAX_TESTS`] tests, valid ball names, finite parameters within the largest length).
//!
//! The default run takes 600 cases; `RTEST_FUZZ_CASES=100000 cargo test -p app --lib
//! plan::fuzz` runs the documented pass (docs/conventions.md §9, "Fuzzing the readers").

use super::{PlanArgs, plan_error, plan_of};
use crate::verbs::EXIT_USAGE;
use clap::Parser;
use fitting::plan;
use proptest::prelude::*;
use proptest::test_runner::TestCaseError;
use std::panic::{AssertUnwindSafe, catch_unwind};

#[path = "../../../tests/all/support/fuzz.rs"]
mod fuzzing;

/// `rtest plan`'s flags alone.
#[derive(Parser)]
struct Flags {
    #[command(flatten)]
    args: PlanArgs,
}

/// The plan arguments: `--paths`, the `--ball` values and `--param`.
type Arguments = (String, Vec<String>, Option<String>);

/// Reads the arguments; `Ok(true)` when they make a plan whose tests all exist.
fn check(
    m: &model_spec::Machine,
    (paths, balls, param): &Arguments,
) -> Result<bool, TestCaseError> {
    let mut argv = vec![
        "plan".to_string(),
        "--machine=seed-ac".into(),
        "--model=reduced".into(),
        format!("--paths={paths}"),
    ];
    argv.extend(balls.iter().map(|b| format!("--ball={b}")));
    argv.extend(param.iter().map(|p| format!("--param={p}")));
    let Ok(flags) = Flags::try_parse_from(&argv) else {
        // clap's own usage error (exit code 2).
        return Ok(false);
    };
    let args = flags.args;
    let outcome = catch_unwind(AssertUnwindSafe(|| {
        let plan = plan_of(m, &args)?;
        plan.check(m).map_err(|e| plan_error(e, &args))?;
        for t in &plan.tests {
            plan.spec(m, &t.test).map_err(|e| {
                plan_error(
                    plan::PlanError::Generator {
                        test: t.test.clone(),
                        ball: plan.balls[t.ball].name.clone(),
                        error: e,
                    },
                    &args,
                )
            })?;
        }
        Ok::<_, crate::verbs::Error>(plan)
    }))
    .map_err(|_| TestCaseError::fail("panicked".to_string()))?;
    match outcome {
        Ok(plan) => {
            if plan.tests.is_empty() || plan.tests.len() > plan::MAX_TESTS {
                return Err(TestCaseError::fail(format!(
                    "{} tests read",
                    plan.tests.len()
                )));
            }
            for b in &plan.balls[1..] {
                if !plan::valid_ball_name(&b.name) {
                    return Err(TestCaseError::fail(format!("ball name `{}`", b.name)));
                }
            }
            let limit = model_spec::limits::MAX_LENGTH_MM;
            if plan
                .balls
                .iter()
                .flat_map(|b| &b.params)
                .any(|x| x.is_nan() || x.abs() > limit)
            {
                return Err(TestCaseError::fail(
                    "parameters beyond the largest length".to_string(),
                ));
            }
            Ok(true)
        }
        Err(e) => {
            let line = &e.message;
            let flagged = line.starts_with("--paths")
                || line.starts_with("--ball")
                || line.starts_with("--param");
            if e.exit_code() != EXIT_USAGE
                || !flagged
                || line.chars().count() > 600
                || line.contains('\n')
            {
                return Err(TestCaseError::fail(format!(
                    "exit code {}, message of {} characters: {}",
                    e.exit_code(),
                    line.chars().count(),
                    line.chars().take(300).collect::<String>()
                )));
            }
            Ok(false)
        }
    }
}

/// A list damaged (a character replaced, a range deleted, a token inserted, or cut), or
/// intact one time in three.
fn damaged(base: &'static str) -> impl Strategy<Value = String> {
    let tokens = proptest::sample::select(vec![
        ",".to_string(),
        ":".to_string(),
        "=".to_string(),
        " ".to_string(),
        ",,".to_string(),
        "::".to_string(),
        "base".to_string(),
        "high".to_string(),
        "Zw".to_string(),
        "1e308".to_string(),
        "nan".to_string(),
        "-0".to_string(),
        "1e400".to_string(),
        "\u{202e}".to_string(),
        "é".to_string(),
        "K4".to_string(),
        "turn-C".to_string(),
        "K4-rev".to_string(),
        "a".repeat(200),
        "K4,".repeat(60),
        "x".repeat(2_000),
    ]);
    (0.0f64..1.0, 0usize..6, tokens, 0usize..6).prop_map(move |(p, kind, token, n)| {
        let chars: Vec<char> = base.chars().collect();
        let at = ((p * chars.len() as f64) as usize).min(chars.len());
        let (head, tail): (String, String) =
            (chars[..at].iter().collect(), chars[at..].iter().collect());
        match kind {
            0 => format!("{head}{token}{}", tail.chars().skip(1).collect::<String>()),
            1 => format!("{head}{}", tail.chars().skip(n).collect::<String>()),
            2 => format!("{head}{token}{tail}"),
            3 => head,
            _ => base.to_string(),
        }
    })
}

fn arguments() -> impl Strategy<Value = Arguments> {
    let param = || {
        prop_oneof![
            3 => Just(None),
            1 => damaged("Xw=-200,Zw=180").prop_map(Some),
            1 => "[A-Za-z0-9,=. -]{0,30}".prop_map(Some),
        ]
    };
    let random_ball = prop_oneof![
        damaged("low:Zw=150,Xw=-20"),
        "[A-Za-z0-9:,=. +-]{0,40}",
        any::<String>(),
    ];
    prop_oneof![
        // The base position only.
        (damaged("K4,K1,K2,turn-C"), Just(Vec::new()), param()),
        // One named position, damaged on either side.
        (
            damaged("K4,K1:high,K2:high"),
            proptest::collection::vec(damaged("high:Zw=260"), 1..2),
            param()
        ),
        // Anything.
        (
            prop_oneof!["[A-Za-z0-9:,=. -]{0,60}", any::<String>()],
            proptest::collection::vec(random_ball, 0..4),
            param()
        ),
    ]
}

#[test]
fn plan_arguments_are_read_or_refused_as_usage_errors_naming_their_flag() {
    let m = model_spec::builtin("seed-ac").unwrap().unwrap();
    fuzzing::fuzz("plan arguments", &arguments(), |a| check(&m, &a), true);
}
