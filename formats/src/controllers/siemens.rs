//! SINUMERIK's files, written from plain values: a part program that sets a swivel data record
//! ([`carrier_program`]), the channel machine data of the five-axis transformation
//! ([`trafo_machine_data`]), and the initialisation programs of the measuring-system and sag
//! compensation tables ([`encoder_file`], [`cec_file`]). What the values mean and the manuals
//! cited: docs/controllers.md, section "Siemens".
//!
//! **Syntax** (function manual W1 2005 §2.5 and §4; K3 2013 §4.4): one assignment per line,
//! `$TC_CARRn[m]=value` with the kinematic type a quoted character (`$TC_CARR23[1]="P"`);
//! comments behind `;`; the compensation tables as K3's examples write them: a first line
//! `%_N_AX_EEC_INI` (`%_N_NC_CEC_INI`), `CHANDATA(1)`, the assignments, `M17`. The part program
//! of the record ends with `M30`, the end of a main program; the initialisation files with
//! `M17`, as K3's examples do.
//!
//! **Numbers** ([`number`]): the shortest decimal that reads back to the same `f64`, always in
//! plain notation (the NC's exponent notation is not `e`), `0` for zero.

/// The shortest decimal of `x` that reads back to the same `f64`, in plain notation (no
/// exponent), `0` for ±0. `x` must be finite.
pub fn number(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return if x.is_finite() {
            "0".into()
        } else {
            format!("{x}")
        };
    }
    let e = format!("{:e}", x.abs());
    let (mantissa, exp) = e.split_once('e').unwrap_or((&e, "0"));
    let exp: i64 = exp.parse().unwrap_or(0);
    let digits: String = mantissa.chars().filter(|c| *c != '.').collect();
    let point = exp + 1;
    let n = digits.len() as i64;
    let body = if point <= 0 {
        format!("0.{}{digits}", "0".repeat((-point) as usize))
    } else if point >= n {
        format!("{digits}{}", "0".repeat((point - n) as usize))
    } else {
        let (a, b) = digits.split_at(point as usize);
        format!("{a}.{b}")
    };
    format!("{}{body}", if x < 0.0 { "-" } else { "" })
}

/// `comments` as `;` lines (a line break inside one starts a line of its own).
fn comment_lines(comments: &[String]) -> String {
    let mut out = String::new();
    for c in comments {
        for line in c.lines() {
            out += if line.is_empty() { ";" } else { "; " };
            out += line;
            out.push('\n');
        }
    }
    out
}

/// The values of a swivel data record (mm; `v1`, `v2` unit vectors).
#[derive(Clone, Debug, PartialEq)]
pub struct CarrierRecord {
    /// The record's number `m` of `$TC_CARRn[m]` (at least 1).
    pub number: u32,
    /// `$TC_CARR23`: `T`, `P` or `M`.
    pub kind: char,
    /// `l1` (`$TC_CARR1..3`).
    pub l1: [f64; 3],
    /// `l2` (`$TC_CARR4..6`).
    pub l2: [f64; 3],
    /// `v1` (`$TC_CARR7..9`).
    pub v1: [f64; 3],
    /// `v2` (`$TC_CARR10..12`).
    pub v2: [f64; 3],
    /// `l3` (`$TC_CARR15..17`).
    pub l3: [f64; 3],
    /// `l4` (`$TC_CARR18..20`).
    pub l4: [f64; 3],
}

/// The fine offsets set to 0: of `l1`, `l2` (41–46), `l3`, `l4` (55–60) and of the rotary
/// axes' offsets (64, 65). (47–54 and 61–63 are not defined.)
pub const FINE_OFFSETS: [u32; 14] = [41, 42, 43, 44, 45, 46, 55, 56, 57, 58, 59, 60, 64, 65];

/// The part program that sets record `r`: the comments, then `$TC_CARR1…20` and `23`, the
/// rotary axes' offsets `24`, `25` and the fine offsets [`FINE_OFFSETS`] to 0, then `M30`.
pub fn carrier_program(comments: &[String], r: &CarrierRecord) -> String {
    let mut out = comment_lines(comments);
    let m = r.number;
    let mut set = |first: u32, v: &[f64; 3], what: &str| {
        let line = (0..3)
            .map(|k| format!("$TC_CARR{}[{m}]={}", first + k as u32, number(v[k] + 0.0)))
            .collect::<Vec<_>>()
            .join(" ");
        out += &format!("{line} ; {what}\n");
    };
    set(1, &r.l1, "l1, mm");
    set(4, &r.l2, "l2, mm");
    set(7, &r.v1, "v1, rotary axis 1");
    set(10, &r.v2, "v2, rotary axis 2");
    set(15, &r.l3, "l3, mm");
    set(18, &r.l4, "l4, mm");
    out += &format!("$TC_CARR23[{m}]=\"{}\" ; kinematic type\n", r.kind);
    out += &format!(
        "$TC_CARR24[{m}]=0 $TC_CARR25[{m}]=0 ; rotary axis offsets, degrees: the angle is the axis position\n"
    );
    let fine: Vec<String> = FINE_OFFSETS
        .iter()
        .map(|n| format!("$TC_CARR{n}[{m}]=0"))
        .collect();
    out += &format!("{} ; fine offsets\n", fine[..6].join(" "));
    out += &format!("{} ; fine offsets\n", fine[6..].join(" "));
    out += "M30\n";
    out
}

/// The channel machine data of transformation 1 as the TOOLCARRIER variant: type 72, its
/// kinematics taken from record `tcarr`: the comments, `CHANDATA(1)`,
/// `$MC_TRAFO_TYPE_1=72`, `$MC_TRAFO5_TCARR_NO_1`, `M17`.
pub fn trafo_machine_data(comments: &[String], tcarr: u32) -> String {
    let mut out = comment_lines(comments);
    out += "CHANDATA(1)\n";
    out += "$MC_TRAFO_TYPE_1=72 ; generic 5-axis transformation from a toolholder record\n";
    out += &format!("$MC_TRAFO5_TCARR_NO_1={tcarr} ; the swivel data record\n");
    out += "M17\n";
    out
}

/// A measuring-system compensation table of one machine axis (mm, or degrees on a rotary
/// axis).
#[derive(Clone, Debug, PartialEq)]
pub struct EncoderTable {
    /// The machine axis (`X1`).
    pub axis: String,
    /// The first point's position.
    pub min: f64,
    /// The distance between points.
    pub step: f64,
    /// The values at `min + k·step`: the deviation the NC adds to the actual value.
    pub values: Vec<f64>,
    /// A modulo table (a rotary axis over 0–360°).
    pub modulo: bool,
    /// A comment behind the table's first line.
    pub note: String,
}

impl EncoderTable {
    /// The last point's position.
    pub fn max(&self) -> f64 {
        self.min + self.step * (self.values.len().max(1) - 1) as f64
    }
}

/// `%_N_AX_EEC_INI`: the comments, `CHANDATA(1)`, for each table its values
/// `$AA_ENC_COMP[0,N,AX]` (1st measuring system), `_STEP`, `_MIN`, `_MAX`, `_IS_MODULO`, then
/// `M17`.
pub fn encoder_file(comments: &[String], tables: &[EncoderTable]) -> String {
    let mut out = "%_N_AX_EEC_INI\n".to_string();
    out += &comment_lines(comments);
    out += "CHANDATA(1)\n";
    for t in tables {
        let ax = &t.axis;
        out += &format!("; {}\n", t.note);
        for (n, v) in t.values.iter().enumerate() {
            out += &format!("$AA_ENC_COMP[0,{n},{ax}]={}\n", number(*v + 0.0));
        }
        out += &format!("$AA_ENC_COMP_STEP[0,{ax}]={}\n", number(t.step));
        out += &format!("$AA_ENC_COMP_MIN[0,{ax}]={}\n", number(t.min + 0.0));
        out += &format!("$AA_ENC_COMP_MAX[0,{ax}]={}\n", number(t.max() + 0.0));
        out += &format!("$AA_ENC_COMP_IS_MODULO[0,{ax}]={}\n", u8::from(t.modulo));
    }
    out += "M17\n";
    out
}

/// A sag (cross-axis) compensation table, mm.
#[derive(Clone, Debug, PartialEq)]
pub struct CecTable {
    /// The machine axis whose set-point is the input (`X1`).
    pub input: String,
    /// The machine axis the value is applied to (`Y1`).
    pub output: String,
    /// The first point's position.
    pub min: f64,
    /// The distance between points.
    pub step: f64,
    /// The values at `min + k·step`.
    pub values: Vec<f64>,
    /// A modulo table.
    pub modulo: bool,
    /// A comment behind the table's first line.
    pub note: String,
}

impl CecTable {
    /// The last point's position.
    pub fn max(&self) -> f64 {
        self.min + self.step * (self.values.len().max(1) - 1) as f64
    }
}

/// `%_N_NC_CEC_INI`: the comments, `CHANDATA(1)`, for table `t` (0, 1, … in order) its values
/// `$AN_CEC[t,N]`, input and output axis, `_STEP`, `_MIN`, `_MAX`, `_DIRECTION` 0 (both
/// directions), `_MULT_BY_TABLE` 0, `_IS_MODULO`, then `M17`.
pub fn cec_file(comments: &[String], tables: &[CecTable]) -> String {
    let mut out = "%_N_NC_CEC_INI\n".to_string();
    out += &comment_lines(comments);
    out += "CHANDATA(1)\n";
    for (t, c) in tables.iter().enumerate() {
        out += &format!("; table {t}: {}\n", c.note);
        for (n, v) in c.values.iter().enumerate() {
            out += &format!("$AN_CEC[{t},{n}]={}\n", number(*v + 0.0));
        }
        out += &format!("$AN_CEC_INPUT_AXIS[{t}]=({})\n", c.input);
        out += &format!("$AN_CEC_OUTPUT_AXIS[{t}]=({})\n", c.output);
        out += &format!("$AN_CEC_STEP[{t}]={}\n", number(c.step));
        out += &format!("$AN_CEC_MIN[{t}]={}\n", number(c.min + 0.0));
        out += &format!("$AN_CEC_MAX[{t}]={}\n", number(c.max() + 0.0));
        out += &format!("$AN_CEC_DIRECTION[{t}]=0\n");
        out += &format!("$AN_CEC_MULT_BY_TABLE[{t}]=0\n");
        out += &format!("$AN_CEC_IS_MODULO[{t}]={}\n", u8::from(c.modulo));
    }
    out += "M17\n";
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_the_shortest_plain_decimals_that_read_back() {
        for (x, s) in [
            (0.0, "0"),
            (-0.0, "0"),
            (1.0, "1"),
            (-184.67, "-184.67"),
            (0.1 + 0.2, "0.30000000000000004"),
            (1.5e-12, "0.0000000000015"),
            (-2.5e22, "-25000000000000000000000"),
            (std::f64::consts::FRAC_1_SQRT_2, "0.7071067811865476"),
        ] {
            assert_eq!(number(x), s);
            assert_eq!(s.parse::<f64>().unwrap(), x + 0.0);
        }
    }

    #[test]
    fn a_carrier_program_sets_every_value_of_its_record_and_ends_with_m30() {
        let r = CarrierRecord {
            number: 3,
            kind: 'P',
            l1: [0.0; 3],
            l2: [0.0, -120.0, -300.0],
            v1: [-1.0, 0.0, 0.0],
            v2: [0.0, 0.0, -1.0],
            l3: [0.012, 0.0, 80.0],
            l4: [-0.012, 120.0, 220.0],
        };
        let text = carrier_program(&["first\nsecond".into()], &r);
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], "; first");
        assert_eq!(lines[1], "; second");
        assert!(text.contains("$TC_CARR4[3]=0 $TC_CARR5[3]=-120 $TC_CARR6[3]=-300 ; l2, mm\n"));
        assert!(text.contains("$TC_CARR15[3]=0.012 "));
        assert!(text.contains("$TC_CARR23[3]=\"P\""));
        assert!(text.contains("$TC_CARR65[3]=0"));
        assert_eq!(*lines.last().unwrap(), "M30");
        // Every index 1..20 but the angles 13, 14 is set once.
        for n in (1..=12).chain(15..=20) {
            assert_eq!(text.matches(&format!("$TC_CARR{n}[3]=")).count(), 1, "{n}");
        }
    }

    #[test]
    fn compensation_files_follow_the_k3_examples() {
        let e = encoder_file(
            &["c".into()],
            &[EncoderTable {
                axis: "X1".into(),
                min: -200.0,
                step: 100.0,
                values: vec![0.003, 0.01, 0.012],
                modulo: false,
                note: "EXX".into(),
            }],
        );
        assert!(e.starts_with("%_N_AX_EEC_INI\n; c\nCHANDATA(1)\n; EXX\n"));
        assert!(e.contains("$AA_ENC_COMP[0,2,X1]=0.012\n"));
        assert!(e.contains("$AA_ENC_COMP_MAX[0,X1]=0\n"));
        assert!(e.ends_with("$AA_ENC_COMP_IS_MODULO[0,X1]=0\nM17\n"));
        let c = cec_file(
            &[],
            &[CecTable {
                input: "X1".into(),
                output: "Y1".into(),
                min: 0.0,
                step: 0.5,
                values: vec![0.0, -0.001],
                modulo: false,
                note: "EYX".into(),
            }],
        );
        assert!(c.contains(
            "$AN_CEC[0,1]=-0.001\n$AN_CEC_INPUT_AXIS[0]=(X1)\n$AN_CEC_OUTPUT_AXIS[0]=(Y1)\n"
        ));
        assert!(c.contains("$AN_CEC_MAX[0]=0.5\n"));
        let t = trafo_machine_data(&[], 2);
        assert!(t.contains("$MC_TRAFO_TYPE_1=72") && t.contains("$MC_TRAFO5_TCARR_NO_1=2"));
    }
}
