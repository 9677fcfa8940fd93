//! The test catalogue of a machine: for every rotary axis a turn, for every pair of rotary
//! axes a coupled motion, and on machines whose rotary axes are A and C the seed's K1, K2, K4.
//! Each test is a [`Sweep`]: which axis turns over which interval, in which steps, what a second
//! axis does meanwhile and where the others stand. The rules are those of docs/paths.md.

use super::clearance::{Clearance, TiltGauge, round_inward};
use model_spec::catalogue::iso_rank;
use model_spec::units::short;
use model_spec::{AxisId, AxisKind, Machine};

/// Default step of the turning axis of a turn test (and of the seed's K1, K2), degrees.
pub const DEFAULT_STEP_DEG: f64 = 1.0;

/// Default step of the primary axis of a pair test (and of the seed's K4), degrees.
pub const DEFAULT_PAIR_STEP_DEG: f64 = 1.5;

/// The largest excursion of the secondary axis of a pair test from its fixed value, degrees: a
/// quarter turn.
pub const MAX_PAIR_EXCURSION_DEG: f64 = 90.0;

/// The names of the seed's tests, on machines whose rotary axes are A and C.
pub const SEED_TESTS: [&str; 3] = ["K1", "K2", "K4"];

/// What kind of test.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TestKind {
    /// One rotary axis turns, the others stand still.
    Turn,
    /// Two rotary axes move together: the primary turns, the secondary follows it.
    Pair,
    /// One of the seed's tests K1, K2, K4 (fixed angles, whatever the clearance options).
    Seed,
}

/// The second axis of a pair test: `axis = base_deg + amplitude_deg·(1 − cos φ)` degrees, with
/// `φ = 360°·(p − from)/(to − from)` the phase of the primary's command `p` over its interval
/// (the primary's own angle when it turns a full turn from 0°).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Follower {
    /// The following axis.
    pub axis: AxisId,
    /// Its value at the primary's first and last samples, degrees.
    pub base_deg: f64,
    /// Half its excursion, degrees (its farthest value is `base_deg + 2·amplitude_deg`).
    pub amplitude_deg: f64,
}

/// The rotary motion of a test. The primary axis goes from `from_deg` to `to_deg` in equal
/// steps of at most the step asked for (`(to − from)/n`, `n` the whole number of steps), both
/// ends sampled; the linear axes follow the ball.
#[derive(Clone, Debug, PartialEq)]
pub struct Sweep {
    /// The axis that turns.
    pub primary: AxisId,
    /// Its first command, degrees.
    pub from_deg: f64,
    /// Its last command, degrees (above `from_deg`).
    pub to_deg: f64,
    /// The step when none is asked for, degrees.
    pub default_step_deg: f64,
    /// The axis that follows the primary, for a pair.
    pub follower: Option<Follower>,
    /// Every axis's command where it does not move, in axis order: degrees for rotary axes
    /// (0° or, outside its range, the end of the range nearest 0°); 0 for linear axes (they
    /// follow the ball).
    pub fixed_deg: Vec<f64>,
}

impl Sweep {
    /// The span of the primary, degrees.
    pub fn span_deg(&self) -> f64 {
        self.to_deg - self.from_deg
    }
}

/// In which order a test takes its poses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Order {
    /// As the sweep goes: the primary from `from_deg` to `to_deg`.
    Forward,
    /// The same poses in the reverse order (`T-rev`), times from 0 again: the primary from
    /// `to_deg` to `from_deg`.
    Reversed,
    /// There and back in one record (`T-back`): the forward poses, then the same poses
    /// reversed, the turning point (the last forward pose) taken once.
    ThereAndBack,
}

impl Order {
    /// The suffix of the test's name: none, `-rev`, `-back`.
    pub fn suffix(self) -> &'static str {
        match self {
            Order::Forward => "",
            Order::Reversed => "-rev",
            Order::ThereAndBack => "-back",
        }
    }

    /// The number of samples of a sweep of `steps` steps taken in this order: `steps + 1`,
    /// or `2·steps + 1` there and back.
    pub fn samples(self, steps: usize) -> usize {
        match self {
            Order::Forward | Order::Reversed => steps.saturating_add(1),
            Order::ThereAndBack => steps.saturating_mul(2).saturating_add(1),
        }
    }

    /// `poses` (the forward order) arranged in this order.
    pub fn arrange<T: Clone>(self, mut poses: Vec<T>) -> Vec<T> {
        match self {
            Order::Forward => poses,
            Order::Reversed => {
                poses.reverse();
                poses
            }
            Order::ThereAndBack => {
                let back: Vec<T> = poses.iter().rev().skip(1).cloned().collect();
                poses.extend(back);
                poses
            }
        }
    }
}

/// A test of a machine.
#[derive(Clone, Debug, PartialEq)]
pub struct TestSpec {
    /// Its name (`turn-C`, `pair-A-C`, `K4`), matched without regard to case.
    pub name: String,
    /// What it does, one line for people.
    pub description: String,
    /// Turn, pair or one of the seed's.
    pub kind: TestKind,
    /// The rotary axes it moves, the primary first; the linear axes follow the ball.
    pub moves: Vec<AxisId>,
    /// The motion.
    pub sweep: Sweep,
    /// The order of its poses: forward for the catalogue's tests, reversed (`T-rev`) or there
    /// and back (`T-back`) for their variants ([`TestSpec::in_order`]).
    pub order: Order,
}

impl TestSpec {
    /// This test (taken forward) with its poses in `order`: named `T-rev` or `T-back` (`T` its
    /// name), described as such, the same motion, the same checks.
    pub fn in_order(&self, order: Order) -> TestSpec {
        let n = super::sweep::steps(self.sweep.span_deg(), self.sweep.default_step_deg);
        let forward = Order::Forward.samples(n);
        let body = self
            .description
            .strip_suffix(&format!(" ({forward} samples)"))
            .unwrap_or(&self.description);
        let count = order.samples(n);
        let description = match order {
            Order::Forward => format!("{body} ({count} samples)"),
            Order::Reversed => {
                format!(
                    "reversed (the same poses from the last to the first): {body} ({count} samples)"
                )
            }
            Order::ThereAndBack => format!(
                "there and back (the poses forward, then reversed, the turning point once): {body} ({count} samples)"
            ),
        };
        TestSpec {
            name: format!("{}{}", self.name, order.suffix()),
            description,
            order,
            ..self.clone()
        }
    }
}

/// Every test of `tests` (taken forward) followed by its reversed and there-and-back versions:
/// `T`, `T-rev`, `T-back`.
pub fn with_orders(tests: &[TestSpec]) -> Vec<TestSpec> {
    tests
        .iter()
        .flat_map(|t| [Order::Forward, Order::Reversed, Order::ThereAndBack].map(|o| t.in_order(o)))
        .collect()
}

/// The value of rotary axis `a` where it stands still: 0°, or the end of its range nearest 0°.
fn rest_deg(m: &Machine, a: AxisId) -> f64 {
    let [lo, hi] = m.axes[a].limits;
    0.0f64.clamp(lo, hi)
}

/// What limits the interval of a turn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Limit {
    None,
    Range,
    Tilt,
    Both,
}

/// The commands of every axis at rest (rad for rotary axes, 0 for linear ones).
fn rest_commands(fixed: &[f64], m: &Machine) -> Vec<f64> {
    fixed
        .iter()
        .zip(&m.axes)
        .map(|(&d, a)| match a.kind {
            AxisKind::Rotary => d.to_radians(),
            AxisKind::Linear => 0.0,
        })
        .collect()
}

/// The interval (degrees) rotary axis `a` may take with the others at rest: its range, within
/// the interval around its rest value where the tilt rule holds; what limits it.
fn allowed(
    m: &Machine,
    gauge: &TiltGauge,
    fixed: &[f64],
    a: AxisId,
    clearance: &Clearance,
) -> ([f64; 2], Limit) {
    let [lo, hi] = m.axes[a].limits;
    let rest = rest_commands(fixed, m);
    let Some([tlo, thi]) = gauge.allowed_interval(&rest, a, fixed[a], clearance.max_tilt_deg)
    else {
        // The rest pose itself breaks the rule: the generation reports it at its first sample.
        return ([lo, hi], Limit::Range);
    };
    let (tlo, thi) = (round_inward(tlo, true), round_inward(thi, false));
    let (from, to) = (lo.max(tlo), hi.min(thi));
    let by_range = from == lo && lo.is_finite() || to == hi && hi.is_finite();
    let by_tilt = from == tlo && tlo > lo || to == thi && thi < hi;
    let limit = match (by_range, by_tilt) {
        (false, false) => Limit::None,
        (true, false) => Limit::Range,
        (false, true) => Limit::Tilt,
        (true, true) => Limit::Both,
    };
    ([from, to], limit)
}

/// The interval of a turn of axis `a`: a full turn where the allowed interval holds one (from
/// the rest value, or as near it as the interval allows), else the whole allowed interval.
fn turn_interval(allowed: [f64; 2], rest: f64) -> ([f64; 2], bool) {
    let [lo, hi] = allowed;
    if hi - lo >= 360.0 - 1e-9 {
        let s = rest.clamp(lo, (hi - 360.0).max(lo));
        ([s, s + 360.0], true)
    } else {
        ([lo, hi], false)
    }
}

/// The catalogue of machine `m` under the clearance rule `clearance` (see the module
/// documentation): the seed's tests first (machines whose rotary axes are A and C), then one
/// turn per rotary axis and one pair per two rotary axes, axes in ISO order (A B C, then the
/// other letters). Empty for a machine without rotary axes.
pub fn catalogue(m: &Machine, clearance: &Clearance) -> Vec<TestSpec> {
    let mut rotary: Vec<AxisId> = m.rotary_axes().collect();
    rotary.sort_by_key(|&a| iso_rank(&m.axes[a].name));
    let mut out = seed_tests(m, &rotary);
    let gauge = TiltGauge::new(m);
    let fixed: Vec<f64> = (0..m.axes.len())
        .map(|a| match m.axes[a].kind {
            AxisKind::Rotary => rest_deg(m, a),
            AxisKind::Linear => 0.0,
        })
        .collect();
    let allowed: Vec<([f64; 2], Limit)> = (0..m.axes.len())
        .map(|a| match m.axes[a].kind {
            AxisKind::Rotary => allowed(m, &gauge, &fixed, a, clearance),
            AxisKind::Linear => ([0.0, 0.0], Limit::None),
        })
        .collect();
    for &a in &rotary {
        let ([from, to], full) = turn_interval(allowed[a].0, fixed[a]);
        let sweep = Sweep {
            primary: a,
            from_deg: from,
            to_deg: to,
            default_step_deg: DEFAULT_STEP_DEG,
            follower: None,
            fixed_deg: fixed.clone(),
        };
        let why = match (full, allowed[a].1) {
            (true, _) => " (a full turn)".to_string(),
            (false, Limit::Range | Limit::None) => " (its range)".to_string(),
            (false, Limit::Tilt) => format!(
                " (where the tool axis stays within {}° of the table normal)",
                short(clearance.max_tilt_deg)
            ),
            (false, Limit::Both) => format!(
                " (its range, where the tool axis stays within {}° of the table normal)",
                short(clearance.max_tilt_deg)
            ),
        };
        out.push(TestSpec {
            name: format!("turn-{}", m.axes[a].name),
            description: describe(m, &sweep, &why),
            kind: TestKind::Turn,
            moves: vec![a],
            sweep,
            order: Order::Forward,
        });
    }
    for (i, &a) in rotary.iter().enumerate() {
        for &b in &rotary[i + 1..] {
            out.push(pair(m, a, b, &fixed, &allowed));
        }
    }
    out
}

/// The pair test of rotary axes `a` and `b` (ISO order): the axis with the longer turn
/// interval is the primary (the later in ISO order on a tie); the secondary swings to the end
/// of its allowed interval farther from its rest value (the lower end on a tie), at most
/// [`MAX_PAIR_EXCURSION_DEG`] away, and back.
fn pair(
    m: &Machine,
    a: AxisId,
    b: AxisId,
    fixed: &[f64],
    allowed: &[([f64; 2], Limit)],
) -> TestSpec {
    let turn = |x: AxisId| turn_interval(allowed[x].0, fixed[x]).0;
    let span = |x: AxisId| {
        let [lo, hi] = turn(x);
        hi - lo
    };
    let (primary, secondary) = if span(a) > span(b) { (a, b) } else { (b, a) };
    let [from, to] = turn(primary);
    let rest = fixed[secondary];
    let [lo, hi] = allowed[secondary].0;
    let low = lo.max(rest - MAX_PAIR_EXCURSION_DEG);
    let high = hi.min(rest + MAX_PAIR_EXCURSION_DEG);
    let end = if high - rest > rest - low { high } else { low };
    let sweep = Sweep {
        primary,
        from_deg: from,
        to_deg: to,
        default_step_deg: DEFAULT_PAIR_STEP_DEG,
        follower: Some(Follower {
            axis: secondary,
            base_deg: rest,
            amplitude_deg: (end - rest) / 2.0,
        }),
        fixed_deg: fixed.to_vec(),
    };
    TestSpec {
        name: format!("pair-{}-{}", m.axes[a].name, m.axes[b].name),
        description: describe(m, &sweep, ""),
        kind: TestKind::Pair,
        moves: vec![primary, secondary],
        sweep,
        order: Order::Forward,
    }
}

/// The seed's K1, K2, K4 when the rotary axes of `m` (ISO order) are exactly A and C.
fn seed_tests(m: &Machine, rotary: &[AxisId]) -> Vec<TestSpec> {
    let names: Vec<&str> = rotary.iter().map(|&a| m.axes[a].name.as_str()).collect();
    if names != ["A", "C"] {
        return Vec::new();
    }
    let (a, c) = (rotary[0], rotary[1]);
    let fixed = vec![0.0; m.axes.len()];
    let sweep = |primary, from_deg, to_deg, step, follower| Sweep {
        primary,
        from_deg,
        to_deg,
        default_step_deg: step,
        follower,
        fixed_deg: fixed.clone(),
    };
    let tests = [
        ("K1", sweep(c, 0.0, 360.0, DEFAULT_STEP_DEG, None), vec![c]),
        ("K2", sweep(a, -90.0, 30.0, DEFAULT_STEP_DEG, None), vec![a]),
        (
            "K4",
            sweep(
                c,
                0.0,
                360.0,
                DEFAULT_PAIR_STEP_DEG,
                Some(Follower {
                    axis: a,
                    base_deg: 0.0,
                    amplitude_deg: -45.0,
                }),
            ),
            vec![c, a],
        ),
    ];
    tests
        .into_iter()
        .map(|(name, sweep, moves)| TestSpec {
            name: name.to_string(),
            description: format!("the seed's {name}: {}", describe(m, &sweep, "")),
            kind: TestKind::Seed,
            moves,
            sweep,
            order: Order::Forward,
        })
        .collect()
}

/// `x` as the second operand of a sum for people: `+ 90`, `− 90`.
fn signed(x: f64) -> String {
    if x < 0.0 {
        format!("+ {}", short(-x))
    } else {
        format!("− {}", short(x))
    }
}

/// The follower's formula for people: `A = -45·(1 − cos C)°` (the primary turns a full turn
/// from 0°), `B = 10 + -45·(1 − cos(360°·(C + 90)/180))°` (the phase over another interval).
pub fn follower_formula(m: &Machine, sweep: &Sweep, f: &Follower) -> String {
    let p = &m.axes[sweep.primary].name;
    let phase = if sweep.from_deg == 0.0 && sweep.span_deg() == 360.0 {
        format!("cos {p}")
    } else if sweep.from_deg == 0.0 {
        format!("cos(360°·{p}/{})", short(sweep.span_deg()))
    } else {
        format!(
            "cos(360°·({p} {})/{})",
            signed(sweep.from_deg),
            short(sweep.span_deg())
        )
    };
    let base = if f.base_deg == 0.0 {
        String::new()
    } else {
        format!("{} + ", short(f.base_deg))
    };
    format!(
        "{} = {base}{}·(1 − {phase})°",
        m.axes[f.axis].name,
        short(f.amplitude_deg)
    )
}

/// One line: what turns, over what, in which steps, what follows, what stands still; `why`
/// after the interval.
fn describe(m: &Machine, sweep: &Sweep, why: &str) -> String {
    let p = &m.axes[sweep.primary].name;
    let n = super::sweep::steps(sweep.span_deg(), sweep.default_step_deg);
    let mut s = format!(
        "{p} turns {}° .. {}°{why} in {}° steps",
        short(sweep.from_deg),
        short(sweep.to_deg),
        short(sweep.span_deg() / n as f64)
    );
    if let Some(f) = &sweep.follower {
        s += &format!(", {}", follower_formula(m, sweep, f));
    }
    let moving: Vec<AxisId> = std::iter::once(sweep.primary)
        .chain(sweep.follower.map(|f| f.axis))
        .collect();
    let mut still: Vec<AxisId> = m.rotary_axes().filter(|a| !moving.contains(a)).collect();
    still.sort_by_key(|&a| iso_rank(&m.axes[a].name));
    for a in still {
        s += &format!(", {} at {}°", m.axes[a].name, short(sweep.fixed_deg[a]));
    }
    s + &format!(" ({} samples)", n + 1)
}
