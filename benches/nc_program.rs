//! Reading and writing back a program of 10⁵ lines for `seed-ac` (X Y Z A C), in both dialects:
//! 100 000 blocks that move, sampled from a K4-like five-axis path (C turning 1.5° a block, A
//! following `−45·(1 − cos C)`, X Y Z at three or four decimals), every fifth block leaving Y and
//! Z modal, a comment every fiftieth.
//!
//! - `nc_program/<dialect>/parse`: the text read into its poses;
//! - `nc_program/<dialect>/write`: written back with every command corrected by a few µm (every
//!   axis word rewritten, modal axes inserted where the correction changes them);
//! - `pose_csv/parse` and `pose_csv/write`: the same poses as a CSV of commanded poses.
//!
//! `cargo bench -p benches --bench nc_program`. The set-up prints the size of each text.

use criterion::{Criterion, criterion_group, criterion_main};
use formats::nc::{Dialect, WriteOptions, parse_program};
use formats::poses::{axis_words, read_pose_csv};
use std::hint::black_box;

const BLOCKS: usize = 100_000;

/// The poses of the path: X Y Z (mm), A C (degrees).
fn path() -> Vec<[f64; 5]> {
    (0..BLOCKS)
        .map(|i| {
            let c = 1.5 * i as f64;
            let a = -45.0 * (1.0 - c.to_radians().cos());
            let (s, co) = a.to_radians().sin_cos();
            [
                -217.504 + 30.0 * co,
                -0.279 + 211.537 * s,
                211.537 * co - 50.0,
                a,
                c % 360.0,
            ]
        })
        .collect()
}

fn iso_text(p: &[[f64; 5]]) -> String {
    let mut t = String::from("%\nO1000 (K4 PATH)\nG90 G21 G94 G17\n");
    for (i, q) in p.iter().enumerate() {
        let n = 10 * (i + 1);
        if i % 5 == 4 {
            t += &format!("N{n} X{:.3} A{:.4} C{:.4}\n", q[0], q[3], q[4]);
        } else {
            t += &format!(
                "N{n} G1 X{:.3} Y{:.3} Z{:.3} A{:.4} C{:.4} F2000\n",
                q[0], q[1], q[2], q[3], q[4]
            );
        }
        if i % 50 == 49 {
            t += "(SECTION)\n";
        }
    }
    t + "M30\n%\n"
}

fn heidenhain_text(p: &[[f64; 5]]) -> String {
    let mut t = String::from("0 BEGIN PGM K4 MM\n");
    for (i, q) in p.iter().enumerate() {
        let n = i + 1;
        if i % 5 == 4 {
            t += &format!("{n} L X{:+.3} A{:+.4} C{:+.4} R0 F2000\n", q[0], q[3], q[4]);
        } else {
            t += &format!(
                "{n} L X{:+.3} Y{:+.3} Z{:+.3} A{:+.4} C{:+.4} R0 F2000\n",
                q[0], q[1], q[2], q[3], q[4]
            );
        }
        if i % 50 == 49 {
            t += "* - SECTION\n";
        }
    }
    t + &format!("{} END PGM K4 MM\n", BLOCKS + 1)
}

fn csv_text(p: &[[f64; 5]]) -> String {
    let mut t = String::from("X,Y,Z,A,C,t_s\n");
    for (i, q) in p.iter().enumerate() {
        t += &format!("{},{},{},{},{},{i}\n", q[0], q[1], q[2], q[3], q[4]);
    }
    t
}

/// Every command of `poses` moved by a few µm (or µ°), different from pose to pose.
fn corrected(poses: &[Vec<f64>]) -> Vec<Vec<f64>> {
    poses
        .iter()
        .enumerate()
        .map(|(i, c)| {
            c.iter()
                .enumerate()
                .map(|(a, x)| x + 1e-3 * (((i * 7 + a * 3) % 11) as f64 - 5.0))
                .collect()
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let m = model_spec::builtin("seed-ac")
        .expect("built-in")
        .expect("valid");
    let axes = axis_words(&m);
    let p = path();
    let mut g = c.benchmark_group("nc_program");
    g.sample_size(20);
    for (dialect, text) in [
        (Dialect::Iso, iso_text(&p)),
        (Dialect::Heidenhain, heidenhain_text(&p)),
    ] {
        let name = dialect.name();
        let program = parse_program("k4", &text, dialect, &axes).expect("a valid program");
        println!(
            "{name}: {} lines, {} bytes, {} poses",
            text.lines().count(),
            text.len(),
            program.poses().len()
        );
        let poses: Vec<Vec<f64>> = program.poses().iter().map(|q| q.commands.clone()).collect();
        let moved = corrected(&poses);
        let options = WriteOptions::new();
        g.bench_function(format!("{name}/parse"), |b| {
            b.iter(|| parse_program("k4", black_box(&text), dialect, &axes).unwrap())
        });
        g.bench_function(format!("{name}/write"), |b| {
            b.iter(|| program.write(black_box(&moved), &options).unwrap())
        });
    }
    g.finish();
    let text = csv_text(&p);
    let table = read_pose_csv("k4.csv", &text, &axes).expect("a valid CSV");
    println!("csv: {} lines, {} bytes", text.lines().count(), text.len());
    let poses: Vec<Vec<f64>> = table.poses().iter().map(|q| q.commands.clone()).collect();
    let moved = corrected(&poses);
    let mut g = c.benchmark_group("pose_csv");
    g.sample_size(20);
    g.bench_function("parse", |b| {
        b.iter(|| read_pose_csv("k4.csv", black_box(&text), &axes).unwrap())
    });
    g.bench_function("write", |b| {
        b.iter(|| table.write(black_box(&moved)).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
