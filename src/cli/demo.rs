//! `rtest demo`: a tour of what exists so far on the seed machine (`seed-ac`): the machine, the
//! reduced model's gain table (the seed's Table 2), numeric gains along the K4 path, the
//! operation counts of the compiled models, and the files a user would take away.

use super::gains::{numeric_json, numeric_table, title};
use super::json::Json;
use super::pose::{self, Pose};
use super::{CliError, CliResult, Compiled, EXIT_CODES, Format};
use codegen::table::{self, render};
use model_spec::{FULL_MODEL, Machine};
use std::path::Path;

/// The machine of the demo.
const MACHINE: &str = "seed-ac";
/// Its reduced model (Table 2).
const REDUCED: &str = "reduced";
/// Directory the demo writes to, relative to the working directory.
const OUT_DIR: &str = "rtest-demo";
/// Samples of the K4 path.
const K4_SAMPLES: usize = 241;
/// Samples whose gains are printed.
const SHOWN: [usize; 3] = [0, 60, 120];

/// Flags of `rtest demo`.
#[derive(Debug, clap::Args)]
#[command(
    about = "Tour of rtest on the seed machine; writes ./rtest-demo/",
    long_about = "\
A tour of rtest on the seed's five-axis machine (seed-ac): prints the machine, the gain table of \
its reduced model (the seed's Table 2: ball set-up errors and location errors of A and C), the \
numeric gains at a few poses of the K4 path (sample i = 0..240: C = 1.5·i deg, \
A = -45·(1 - cos C) deg, linear axes in mm by the nominal tool-centre-point inverse kinematics), \
and the operation counts of the compiled full and reduced models. Gains are tool point minus \
workpiece point in the tool frame: mm/mm for translational errors (µm per µm), mm/rad for \
angular errors (µm per mrad). Writes, in ./rtest-demo/ (created if needed, files replaced \
atomically): seed_ac.rs (generated no_std Rust code of every model), gains-reduced.md (the \
Markdown gain table of the reduced model) and gains-k4.json (numeric gains of the reduced model \
at the 241 K4 samples: [{sample, A_deg, C_deg, X_mm, Y_mm, Z_mm, gains: {error: [gx, gy, gz]}}]).",
    after_help = EXIT_CODES
)]
pub struct DemoArgs {}

/// The rotary positions (degrees) of sample `i` of the K4 path: `C = 1.5·i`,
/// `A = -45·(1 - cos C)`.
pub fn k4_rotary(i: usize) -> (f64, f64) {
    let c = 1.5 * i as f64;
    let a = -45.0 * (1.0 - c.to_radians().cos());
    (a, c)
}

fn axis(m: &Machine, name: &str) -> CliResult<usize> {
    m.axis_by_name(name)
        .ok_or_else(|| CliError::failure(format!("demo: machine {} has no axis {name}", m.name)))
}

/// Runs `rtest demo`.
pub fn run(_args: &DemoArgs) -> CliResult {
    let m = super::load_machine(MACHINE)?;
    let (a, c) = (axis(&m, "A")?, axis(&m, "C")?);
    let full = Compiled::new(&m, &super::model_errors(&m, FULL_MODEL)?);
    let reduced = Compiled::new(&m, &super::model_errors(&m, REDUCED)?);
    let reduced_title = title(&m, Some(REDUCED), reduced.model.errors.len());

    let params = m.default_parameters();
    let path: Vec<Pose> = (0..K4_SAMPLES)
        .map(|i| {
            let (deg_a, deg_c) = k4_rotary(i);
            pose::complete(&m, &[(a, deg_a), (c, deg_c)], params.clone())
        })
        .collect::<CliResult<_>>()?;
    let path_gains: Vec<Vec<[f64; 3]>> = path
        .iter()
        .map(|p| reduced.position_gains(&p.commands, &p.params))
        .collect();

    // Everything is computed before anything is written.
    let code = codegen::emit::generate_machine(&m, &[])
        .map_err(|e| CliError::failure(format!("demo: machine {}: {e}", m.name)))?;
    let markdown = render(&m, &reduced.model, &reduced_title, table::Format::Markdown);
    let k4_json = k4_json(&m, &path, &reduced, &path_gains).render();

    let mut out = String::new();
    out.push_str("rtest demo: the seed's five-axis machine\n\n");
    out.push_str(&super::machines::describe(&m));
    out.push('\n');
    out.push_str(&render(
        &m,
        &reduced.model,
        &format!("{reduced_title} (the seed's Table 2)"),
        table::Format::Text,
    ));
    out.push_str(&format!(
        "\nNumeric gains of the reduced model on the K4 path ({K4_SAMPLES} samples: C = 1.5·i deg, A = -45·(1 - cos C) deg, linear axes by inverse kinematics); samples {}:\n",
        SHOWN.map(|i| i.to_string()).join(", ")
    ));
    for &i in &SHOWN {
        out.push('\n');
        out.push_str(&numeric_table(
            &m,
            &format!("K4 sample {i}"),
            &path[i],
            &reduced.model,
            &path_gains[i],
            Format::Text,
        ));
    }
    out.push_str("\nCompiled straight-line code (per evaluation of all gains):\n");
    for (name, c) in [(FULL_MODEL, &full), (REDUCED, &reduced)] {
        out.push_str(&format!(
            "  {name:<8} {:>2} errors: {}\n",
            c.model.errors.len(),
            c.program.op_counts()
        ));
    }

    let dir = Path::new(OUT_DIR);
    std::fs::create_dir_all(dir).map_err(|e| {
        CliError::failure(format!("demo: cannot create directory `{OUT_DIR}`: {e}"))
    })?;
    let files = [
        (
            "seed_ac.rs",
            code,
            "generated no_std Rust code of the full and reduced models",
        ),
        (
            "gains-reduced.md",
            markdown,
            "gain table of the reduced model, Markdown",
        ),
        (
            "gains-k4.json",
            k4_json,
            "numeric gains of the reduced model at the 241 K4 samples",
        ),
    ];
    out.push_str("\nWrote:\n");
    for (name, contents, what) in &files {
        let path = dir.join(name);
        super::write_atomic("demo", &path, contents)?;
        out.push_str(&format!("  {}  ({what})\n", path.display()));
    }
    print!("{out}");
    Ok(())
}

/// The K4 gains as JSON: one object per sample with its axis positions (degrees, mm).
fn k4_json(m: &Machine, path: &[Pose], model: &Compiled, gains: &[Vec<[f64; 3]>]) -> Json {
    let axes: Vec<(String, usize)> = m
        .rotary_axes()
        .map(|i| (format!("{}_deg", m.axes[i].name), i))
        .chain(
            m.linear_axes()
                .map(|i| (format!("{}_mm", m.axes[i].name), i)),
        )
        .collect();
    Json::Arr(
        path.iter()
            .zip(gains)
            .enumerate()
            .map(|(i, (p, g))| {
                let mut fields = vec![("sample".to_string(), Json::Int(i as i64))];
                fields.extend(
                    axes.iter()
                        .map(|(k, a)| (k.clone(), Json::Num(p.shown[*a]))),
                );
                fields.push(("gains".into(), numeric_json(&model.model, g)));
                Json::Obj(fields)
            })
            .collect(),
    )
}
