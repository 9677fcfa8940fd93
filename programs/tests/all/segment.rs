//! Cutting a streamed log into samples: a simulated run of a measurement program, segmented,
//! gives the static record of the same poses (and the same identified values); the program's
//! start is recovered, a drifting machine is followed, a continuous run is found; what cannot
//! be cut is refused with the sample and the times.

use crate::common;
use crate::one_record::identify_one;

use common::{Scratch, builtin};
use fitting::IdentifyOptions;
use formats::csv::{ReadOptions, parse_measurement};
use formats::nc::Dialect;
use formats::truth::builtin_truth;
use model_spec::Machine;
use programs::measure::{
    ContinuousTiming, MeasureMode, MeasureOptions, StaticTiming, TimingPlan, measurement_program,
};
use programs::segment::{
    Anchor, LogClock, SegmentOptions, Segmented, WindowFlag, format_segmented, format_windows,
    segment_file, segment_text,
};
use programs::stream::{StreamOptions, write_stream};
use simulation::model::Model;
use simulation::{Truth, builtin_path, simulate};

/// seed-ac, the plan of K4 (every `every`-th pose, at most `count` of them) in `mode`, and the
/// reduced truth with noise σ = `noise_um`.
fn setup(
    mode: MeasureMode,
    every: usize,
    count: usize,
    noise_um: f64,
) -> (Machine, TimingPlan, Truth) {
    let m = builtin("seed-ac");
    let mut k4 = builtin_path(&m, "K4").unwrap().unwrap();
    k4.samples = k4.samples.into_iter().step_by(every).take(count).collect();
    let p = measurement_program(&m, &k4, &MeasureOptions::new(&m, Dialect::Iso, mode)).unwrap();
    let mut truth = builtin_truth("seed-ac-reduced", &m).unwrap().unwrap();
    truth.noise_mm = noise_um * 1e-3;
    truth.seed = 7;
    (m, p.plan, truth)
}

fn stream(m: &Machine, truth: &Truth, plan: &TimingPlan, o: &StreamOptions) -> String {
    let mut log = Vec::new();
    write_stream(m, truth, plan, o, &mut log).unwrap();
    String::from_utf8(log).unwrap()
}

fn cut(text: &str, plan: &TimingPlan, o: &SegmentOptions) -> Segmented {
    segment_text("log.csv", text, plan, o).unwrap_or_else(|e| panic!("{e}"))
}

fn cut_err(text: &str, plan: &TimingPlan, o: &SegmentOptions) -> String {
    segment_text("log.csv", text, plan, o)
        .unwrap_err()
        .to_string()
}

fn static_mode() -> MeasureMode {
    MeasureMode::Static(StaticTiming::default())
}

#[test]
fn a_static_log_gives_the_static_record() {
    let (m, plan, truth) = setup(static_mode(), 1, 241, 0.0);
    let o = StreamOptions {
        lead_s: 7.3,
        move_time_factor: 1.1,
        ..StreamOptions::default()
    };
    let seg = cut(
        &stream(&m, &truth, &plan, &o),
        &plan,
        &SegmentOptions::default(),
    );
    // The program's start, to within one sampling period (the log's rows are 0.01 s apart).
    assert!((seg.start_s - 7.3).abs() <= 0.01, "{}", seg.start_s);
    assert_eq!(seg.anchored, 241);
    assert!(
        seg.runner_up.is_some_and(|(_, a)| a < 241),
        "{:?}",
        seg.runner_up
    );
    assert_eq!(seg.clock, LogClock::Seconds { first: 0.0 });
    // The machine's moves took 10 % longer than planned: the drift is followed.
    let moves: f64 = plan
        .rows
        .windows(2)
        .map(|w| w[1].arrive_s - w[0].depart_s)
        .sum();
    let last = seg.windows.last().unwrap();
    assert!(
        (last.shift_s - 0.1 * moves).abs() < 0.05,
        "{} {}",
        last.shift_s,
        0.1 * moves
    );
    assert!(
        seg.windows
            .iter()
            .all(|w| w.flags.is_empty() && w.readings >= 155)
    );
    assert_eq!(seg.windows[0].anchor, Anchor::Departure);
    assert_eq!(last.anchor, Anchor::Arrival);
    // At rest the stream reads what the static simulation reads at the same poses.
    let fixed = simulate(&m, &truth, &plan.record()).unwrap();
    for (w, r) in seg.windows.iter().zip(&fixed.measured) {
        for (a, b) in w.mean_mm.iter().zip(r) {
            assert!((a - b).abs() < 1e-12, "sample {}: {a} {b}", w.sample);
        }
    }
    // Written as a record, it is read as identify reads it, and identifies the same values.
    let csv = format_segmented(&m, &plan, &seg, &["segmented".into()]).unwrap();
    assert!(csv.starts_with("# segmented\nX,Y,Z,A,C,dx_um,dy_um,dz_um,t_s\n"));
    let record = parse_measurement("rec.csv", &csv, &m, &ReadOptions::default()).unwrap();
    let model = Model::of(&m, "reduced").unwrap();
    let a = identify_one(&m, &model, &record, &IdentifyOptions::default()).unwrap();
    let b = identify_one(&m, &model, &fixed, &IdentifyOptions::default()).unwrap();
    for (x, y) in a.fit.values.iter().zip(&b.fit.values) {
        assert!((x.unwrap() - y.unwrap()).abs() < 1e-9, "{x:?} {y:?}");
    }
    // The record's times are the windows' middles on the program clock.
    for (w, row) in seg.windows.iter().zip(&plan.rows).take(1) {
        assert!(
            (w.t_s - row.middle_s()).abs() < 0.01,
            "{} {}",
            w.t_s,
            row.middle_s()
        );
    }
}

#[test]
fn with_noise_the_values_agree_within_their_uncertainty() {
    let (m, plan, truth) = setup(static_mode(), 2, 121, 0.3);
    let o = StreamOptions {
        lead_s: 3.1,
        ..StreamOptions::default()
    };
    let seg = cut(
        &stream(&m, &truth, &plan, &o),
        &plan,
        &SegmentOptions::default(),
    );
    assert!((seg.start_s - 3.1).abs() <= 0.01);
    // The noise estimated from the log is the truth's, per reading.
    assert!(
        (seg.noise_mm / truth.noise_mm - 1.0).abs() < 0.1,
        "{}",
        seg.noise_mm
    );
    let csv = format_segmented(&m, &plan, &seg, &[]).unwrap();
    let record = parse_measurement("rec.csv", &csv, &m, &ReadOptions::default()).unwrap();
    let model = Model::of(&m, "reduced").unwrap();
    let a = identify_one(&m, &model, &record, &IdentifyOptions::default()).unwrap();
    let mut quiet = truth.clone();
    quiet.noise_mm = 0.0;
    let fixed = simulate(&m, &quiet, &plan.record()).unwrap();
    let b = identify_one(&m, &model, &fixed, &IdentifyOptions::default()).unwrap();
    for ((x, y), s) in a.fit.values.iter().zip(&b.fit.values).zip(&a.fit.std) {
        let (x, y, s) = (x.unwrap(), y.unwrap(), s.unwrap());
        assert!((x - y).abs() < 4.0 * s, "{x} {y} ± {s}");
    }
    // The spread of a window is the noise of a reading.
    let sd = seg.windows[10].sd_mm[0];
    assert!((sd / truth.noise_mm - 1.0).abs() < 0.25, "{sd}");
}

#[test]
fn a_unix_time_log_with_sensor_columns() {
    let (m, plan, truth) = setup(static_mode(), 2, 40, 0.1);
    let o = StreamOptions {
        unix_start: Some(1_717_171_717),
        ..StreamOptions::default()
    };
    let text = stream(&m, &truth, &plan, &o);
    // Four sensor columns and a status word, as a data logger might write them.
    let mut log = String::from("# logger export\nt_abs_s,status,s1_um,s2_um,s3_um,s4_um\n");
    for line in text.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let s4: f64 = f[1].parse::<f64>().unwrap() + f[2].parse::<f64>().unwrap();
        log += &format!("{},ok,{},{},{},{s4}\n", f[0], f[1], f[2], f[3]);
    }
    let seg = cut(&log, &plan, &SegmentOptions::default());
    assert_eq!(seg.columns, ["s1_um", "s2_um", "s3_um", "s4_um"]);
    assert_eq!(seg.ignored, ["status"]);
    assert_eq!(
        seg.clock,
        LogClock::Unix {
            first_whole: 1_717_171_717
        }
    );
    assert!(
        (seg.start_s - 1_717_171_722.0).abs() <= 0.01,
        "{}",
        seg.start_s
    );
    let csv = format_segmented(&m, &plan, &seg, &[]).unwrap();
    assert!(
        csv.starts_with("X,Y,Z,A,C,s1_um,s2_um,s3_um,s4_um,t_s\n"),
        "{csv}"
    );
    let windows = format_windows(&seg);
    assert!(windows.starts_with("sample,log_start_s,log_end_s,readings,t_s,shift_s,anchor,s1_um_sd,s2_um_sd,s3_um_sd,s4_um_sd,flags\n1,1717171723.2,"), "{windows}");
    // The same log on the t_s clock gives the same samples.
    let same = cut(&text, &plan, &SegmentOptions::default());
    let (a, b) = (&seg.windows[3], &same.windows[3]);
    assert!((a.mean_mm[0] - b.mean_mm[0]).abs() < 1e-15 && (a.t_s - b.t_s).abs() < 1e-6);
}

#[test]
fn a_given_offset_is_used() {
    let (m, plan, truth) = setup(static_mode(), 2, 40, 0.1);
    let text = stream(&m, &truth, &plan, &StreamOptions::default());
    let found = cut(&text, &plan, &SegmentOptions::default());
    let given = cut(
        &text,
        &plan,
        &SegmentOptions {
            offset_s: Some(5.0),
            ..SegmentOptions::default()
        },
    );
    assert!(given.start_given && !found.start_given);
    assert_eq!(given.start_s, 5.0);
    assert_eq!(given.windows, found.windows);
    // An offset far off puts the windows where the machine moves, or outside the log.
    let e = cut_err(
        &text,
        &plan,
        &SegmentOptions {
            offset_s: Some(400.0),
            ..SegmentOptions::default()
        },
    );
    assert!(
        e.starts_with("log.csv: ") && e.contains("poses not found"),
        "{e}"
    );
}

#[test]
fn a_continuous_run_is_found() {
    let mode = MeasureMode::Continuous(ContinuousTiming::default());
    let (m, plan, truth) = setup(mode, 1, 241, 0.1);
    let o = StreamOptions {
        lead_s: 6.2,
        move_time_factor: 1.2,
        ..StreamOptions::default()
    };
    let seg = cut(
        &stream(&m, &truth, &plan, &o),
        &plan,
        &SegmentOptions::default(),
    );
    let run = plan.rows.last().unwrap().arrive_s - plan.rows[0].depart_s;
    assert_eq!(seg.anchored, 2);
    // Both ends within a sampling period or two: the start, and the run's length.
    assert!((seg.start_s - 6.2).abs() <= 0.02, "{}", seg.start_s);
    assert!(
        (seg.time_scale - 1.2).abs() * run <= 0.02,
        "{}",
        seg.time_scale
    );
    // At the instants the readings are those of the static poses, to within what they change
    // in that time: the nest leaves the ball between poses (the chord of a 1.5° step), so near a
    // pose the readings change by up to 0.5 µm per ms on K4.
    let fixed = simulate(&m, &truth, &plan.record()).unwrap();
    for (w, r) in seg.windows.iter().zip(&fixed.measured) {
        for (a, b) in w.mean_mm.iter().zip(r) {
            assert!((a - b).abs() < 0.012, "sample {}: {a} {b}", w.sample);
        }
    }
}

#[test]
fn a_short_log_a_gap_and_a_sparse_window_are_refused() {
    let (m, plan, truth) = setup(static_mode(), 2, 40, 0.1);
    let text = stream(&m, &truth, &plan, &StreamOptions::default());
    let lines: Vec<&str> = text.lines().collect();
    let short: String = lines[..lines.len() * 2 / 3].join("\n");
    let e = cut_err(&short, &plan, &SegmentOptions::default());
    assert!(e.contains("the log is shorter than the program"), "{e}");
    assert!(
        e.starts_with("log.csv: 12 of 40 poses not found (samples 29, 30,"),
        "{e}"
    );
    // Rows missing over the whole window of sample 30.
    let row = &plan.rows[29];
    let (a, b) = (5.0 + row.arrive_s + 0.2, 5.0 + row.depart_s - 0.2);
    let gap: String = lines
        .iter()
        .filter(|l| {
            let t: f64 = l.split(',').next().unwrap().parse().unwrap_or(-1.0);
            !(a..b).contains(&t)
        })
        .copied()
        .collect::<Vec<_>>()
        .join("\n");
    let e = cut_err(&gap, &plan, &SegmentOptions::default());
    assert!(
        e.starts_with("log.csv: sample 30: its window ") && e.contains("has a gap there"),
        "{e}"
    );
    // Fewer rows in a window than asked for.
    let e = cut_err(
        &text,
        &plan,
        &SegmentOptions {
            min_readings: 200,
            ..SegmentOptions::default()
        },
    );
    assert!(e.starts_with("log.csv: sample 1: 161 log row(s) in its window 6.2 .. 7.8 s (log clock), fewer than 200"), "{e}");
    // A margin that leaves nothing.
    let e = cut_err(
        &text,
        &plan,
        &SegmentOptions {
            margin_s: Some(1.0),
            ..SegmentOptions::default()
        },
    );
    assert!(
        e.contains("leaves nothing of the shortest window (2 s)"),
        "{e}"
    );
}

#[test]
fn a_log_of_two_runs_is_ambiguous() {
    let (m, plan, truth) = setup(static_mode(), 2, 40, 0.1);
    let text = stream(&m, &truth, &plan, &StreamOptions::default());
    let rows: Vec<&str> = text.lines().skip(1).collect();
    let span = plan.duration_s() + 10.0 + 0.01;
    let mut two = String::from("t_s,dx_um,dy_um,dz_um\n");
    for shift in [0.0, span + 3.0] {
        for r in &rows {
            let (t, rest) = r.split_once(',').unwrap();
            two += &format!("{},{rest}\n", t.parse::<f64>().unwrap() + shift);
        }
    }
    let e = cut_err(&two, &plan, &SegmentOptions::default());
    assert!(
        e.contains("the alignment is ambiguous") && e.contains("--offset-s"),
        "{e}"
    );
    // Given the start of the second run, it is cut.
    let seg = cut(
        &two,
        &plan,
        &SegmentOptions {
            offset_s: Some(span + 3.0 + 5.0),
            ..SegmentOptions::default()
        },
    );
    assert_eq!(seg.windows.len(), plan.rows.len());
}

#[test]
fn a_disturbed_window_is_flagged() {
    let (m, plan, truth) = setup(static_mode(), 2, 40, 0.1);
    let text = stream(&m, &truth, &plan, &StreamOptions::default());
    let row = &plan.rows[12];
    let (a, b) = (5.0 + row.start_s + 0.5, 5.0 + row.start_s + 0.7);
    let mut log = String::new();
    for (i, l) in text.lines().enumerate() {
        let f: Vec<&str> = l.split(',').collect();
        let t: f64 = f[0].parse().unwrap_or(-1.0);
        if i > 0 && (a..b).contains(&t) {
            // A knock on the machine: ±2 µm in x.
            let x: f64 = f[1].parse::<f64>().unwrap() + if i % 2 == 0 { 2.0 } else { -2.0 };
            log += &format!("{},{x},{},{}\n", f[0], f[2], f[3]);
        } else {
            log += l;
            log.push('\n');
        }
    }
    let seg = cut(
        &log,
        &plan,
        &SegmentOptions {
            still_mm: Some(0.0005),
            ..SegmentOptions::default()
        },
    );
    let flagged: Vec<(usize, Vec<WindowFlag>)> = seg
        .windows
        .iter()
        .filter(|w| !w.flags.is_empty())
        .map(|w| (w.sample, w.flags.clone()))
        .collect();
    // The knock is both a spread and a break of the stillness.
    assert_eq!(
        flagged,
        [(13, vec![WindowFlag::Spread, WindowFlag::Motion])]
    );
}

#[test]
fn a_malformed_log_is_refused_at_its_line_and_column() {
    let (_, plan, _) = setup(static_mode(), 2, 40, 0.1);
    let cases = [
        ("", "log.csv:1: an empty log"),
        ("dx_um,dy_um\n", "log.csv:1: no time column"),
        ("t_s,x,y\n", "log.csv:1: no reading column"),
        (
            "t_s,dx_um,dy_um,dz_um,s1_um\n",
            "log.csv:1: column 5 `s1_um`: a reading column beside the error vector's `dx_um`",
        ),
        (
            "t_s,dy_um,dx_um\n",
            "log.csv:1: the error vector lacks dz_um",
        ),
        (
            "t_s,t_abs_s,dx_um\n",
            "log.csv:1: column 2 `t_abs_s`: a second time column",
        ),
        (
            "t_s,dx_um,DX_UM\n",
            "log.csv:1: column 3 `DX_UM`: column `DX_UM` appears twice",
        ),
        (
            "t_s,s1_um\n0,1\n",
            "log.csv: 1 row(s): a log needs at least two",
        ),
        (
            "t_s,s1_um\n0,1\n0.01,1,2\n",
            "log.csv:3: 3 fields, the header has 2",
        ),
        (
            "t_s,s1_um\n0,1\n0.01,nan\n",
            "log.csv:3: column 2 `s1_um`: `nan` is not a finite number",
        ),
        (
            "t_s,s1_um\n0,1\nx,1\n",
            "log.csv:3: column 1 `t_s`: `x` is not a finite number",
        ),
        (
            "# c\nt_s,s1_um\n0,1\n0.02,1\n0.01,1\n",
            "log.csv:5: column 1 `t_s`: the time 0.01 s does not increase (line 4: 0.02 s)",
        ),
        (
            "t_abs_s,s1_um\n1717171717.5,1\n-3,1\n",
            "log.csv:3: column 1 `t_abs_s`: `-3` is not a Unix time",
        ),
    ];
    for (text, needle) in cases {
        let e = cut_err(text, &plan, &SegmentOptions::default());
        assert!(e.starts_with(needle), "`{needle}` is not the start of: {e}");
    }
}

#[test]
fn a_log_file_is_read_twice_and_must_be_a_file() {
    let (m, plan, truth) = setup(static_mode(), 2, 40, 0.1);
    let dir = Scratch::new("segment-file");
    let path = dir.0.join("log.csv");
    let file = std::fs::File::create(&path).unwrap();
    write_stream(
        &m,
        &truth,
        &plan,
        &StreamOptions::default(),
        std::io::BufWriter::new(file),
    )
    .unwrap();
    let seg = segment_file(&path, &plan, &SegmentOptions::default()).unwrap();
    assert_eq!(seg.windows.len(), plan.rows.len());
    let e = segment_file(&dir.0, &plan, &SegmentOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("not a regular file"), "{e}");
}

/// A log of one hour at 1 kHz (3.6 million rows), written to a file and cut: the time and the
/// memory it takes. Run with `cargo test --release -p programs --test all segment:: -- --ignored
/// --nocapture`.
#[test]
#[ignore]
fn an_hour_at_one_kilohertz() {
    let m = builtin("seed-ac");
    let k1 = builtin_path(&m, "K1").unwrap().unwrap();
    let mode = MeasureMode::Static(StaticTiming {
        settle_s: 1.0,
        window_s: 8.7,
        ..StaticTiming::default()
    });
    let p = measurement_program(&m, &k1, &MeasureOptions::new(&m, Dialect::Iso, mode)).unwrap();
    let mut truth = builtin_truth("seed-ac-reduced", &m).unwrap().unwrap();
    truth.noise_mm = 3e-4;
    let dir = Scratch::new("segment-hour");
    let path = dir.0.join("log.csv");
    let o = StreamOptions {
        rate_hz: 1000.0,
        ..StreamOptions::default()
    };
    let t0 = std::time::Instant::now();
    let file = std::io::BufWriter::new(std::fs::File::create(&path).unwrap());
    let s = write_stream(&m, &truth, &p.plan, &o, file).unwrap();
    let written = t0.elapsed();
    let t1 = std::time::Instant::now();
    let seg = segment_file(&path, &p.plan, &SegmentOptions::default()).unwrap();
    let cut = t1.elapsed();
    let bytes = std::fs::metadata(&path).unwrap().len();
    let peak = std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM"))
                .map(str::to_string)
        })
        .unwrap_or_default();
    println!(
        "{} rows ({} MB, {} s of program), written in {written:?}; segmented in {cut:?}: {} samples, {} anchored, start {} s; {peak}",
        s.rows,
        bytes / 1_000_000,
        s.program_s,
        seg.windows.len(),
        seg.anchored,
        seg.start_s
    );
    assert_eq!(seg.windows.len(), 361);
}
