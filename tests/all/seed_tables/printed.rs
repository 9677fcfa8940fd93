//! The seed's gain tables as the PDF extraction shows them, cell by cell, typos included.
//!
//! Source: the text extracted from the PDF of Y.-Y. Hsu's project report (the seed). Three tables:
//! - [`TABLE_1`]: the five-axis R-test paper's Table 1 ("Error model and sensitivity analysis",
//!   44 errors, columns ΔXp ΔYp ΔZp ΔIp ΔJp ΔKp). The extraction is cut after row EYC: the rows
//!   EZC EAC EBC ECC XOC YOC AOC BOC are not there ([`Table::missing_rows`]).
//! - [`TABLE_2`]: the same paper's Table 2 ("Reduced error model", 11 errors, ΔXp ΔYp ΔZp).
//! - [`TABLE_II`]: the three-axis paper's Table II ("Error model with parametric-independent",
//!   21 errors, ΔXr ΔYr ΔZr ΔIr ΔJr ΔKr), where many cells are blank in the extraction
//!   ([`Cell::Missing`]). That paper's Table I is not in the extraction at all.
//!
//! Each cell keeps the extraction's text verbatim (continuation lines of a cell joined by one
//! space) next to a closure that evaluates what it says. Reading rules, applied uniformly and
//! nowhere else:
//! - `\overline{0}`, `\mathbf{0}`, `\boldsymbol{0}`, `Ω`, `θ`, the letter `O` and `_{0}` are the
//!   OCR's renderings of the digit 0 (the same glyphs stand where a 0 must be in both papers;
//!   the comparison confirms every one), `\overline{1}`, `\mathbf{1}` of the digit 1;
//! - `Y_{7}` (Table 1, ECY, ΔXp) is read `Y_z`; `Sa` and `ca` are read `S_a`, `C_a`; `[*]` is `*`;
//! - `X_m`, `Y_m`, `Z_m` are the linear commands ([`Pose::xm`] …), `S_a = sin A`, `C_a = cos A`,
//!   `S_c = sin C`, `C_c = cos C`; every other `X_a`, `Z_w`, … is the kinematic symbol of that name;
//! - `X_h` is kept where printed (Table 1: EBY ECY EBZ ECZ BOZ) although the five-axis paper
//!   never defines it (its kinematic parameters are only named through the tables and Table 3);
//! - `X_s`, `Z_s` (Table II: EAY EBY ECY) are the paper's "strokes" ([`Pose::Xs`], [`Pose::Zs`]);
//! - a blank cell of Table II is [`Cell::Missing`]: nothing is guessed.
//!
//! Signs and term order are as printed, so a closure is exactly as wrong as its cell.

#![allow(non_snake_case)]

/// A pose and a set of kinematic symbols, in the seed's notation (mm, and sines/cosines). The
/// symbols of both machines are here by name (`Xw`, `Yw`, `Zw`, `Xz`, `Yz`, `Zz`, `Zh` mean the
/// same thing in both papers); a symbol a machine does not have stays 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    /// `S_a = sin A`.
    pub sa: f64,
    /// `C_a = cos A`.
    pub ca: f64,
    /// `S_c = sin C`.
    pub sc: f64,
    /// `C_c = cos C`.
    pub cc: f64,
    /// `X_m`: X command, mm.
    pub xm: f64,
    /// `Y_m`: Y command, mm.
    pub ym: f64,
    /// `Z_m`: Z command, mm.
    pub zm: f64,
    /// Five-axis machine: offset of the A axis from the X carriage, mm.
    pub Xa: f64,
    /// See [`Pose::Xa`].
    pub Ya: f64,
    /// See [`Pose::Xa`].
    pub Za: f64,
    /// Offset of the C axis from the A axis along z, mm.
    pub Zc: f64,
    /// Ball centre in the C table frame, mm.
    pub Xw: f64,
    /// See [`Pose::Xw`].
    pub Yw: f64,
    /// See [`Pose::Xw`].
    pub Zw: f64,
    /// Offset of the Z axis from the Y carriage, mm.
    pub Xz: f64,
    /// See [`Pose::Xz`].
    pub Yz: f64,
    /// See [`Pose::Xz`].
    pub Zz: f64,
    /// Offset of the spindle holder from the Z carriage (x), mm: printed in Table 1, never
    /// defined by the paper.
    pub Xh: f64,
    /// Offset of the spindle holder from the Z carriage (z), mm.
    pub Zh: f64,
    /// Probe (sensor nest) offset from the holder along z, mm.
    pub Zp: f64,
    /// Three-axis machine: offset of the X axis from the Y carriage, mm.
    pub Xx: f64,
    /// See [`Pose::Xx`].
    pub Yx: f64,
    /// See [`Pose::Xx`].
    pub Zx: f64,
    /// Three-axis machine: tool length, mm.
    pub Zt: f64,
    /// Three-axis machine: workpiece origin in the reference frame, mm.
    pub Xwo: f64,
    /// See [`Pose::Xwo`].
    pub Ywo: f64,
    /// See [`Pose::Xwo`].
    pub Zwo: f64,
    /// Three-axis paper: "stroke" `X_s` of Table II, mm.
    pub Xs: f64,
    /// Three-axis paper: "stroke" `Y_s` (named in the text, used by no printed cell), mm.
    pub Ys: f64,
    /// Three-axis paper: "stroke" `Z_s` of Table II, mm.
    pub Zs: f64,
}

impl Default for Pose {
    /// A = C = 0, every command and symbol 0.
    fn default() -> Self {
        Pose {
            sa: 0.0,
            ca: 1.0,
            sc: 0.0,
            cc: 1.0,
            xm: 0.0,
            ym: 0.0,
            zm: 0.0,
            Xa: 0.0,
            Ya: 0.0,
            Za: 0.0,
            Zc: 0.0,
            Xw: 0.0,
            Yw: 0.0,
            Zw: 0.0,
            Xz: 0.0,
            Yz: 0.0,
            Zz: 0.0,
            Xh: 0.0,
            Zh: 0.0,
            Zp: 0.0,
            Xx: 0.0,
            Yx: 0.0,
            Zx: 0.0,
            Zt: 0.0,
            Xwo: 0.0,
            Ywo: 0.0,
            Zwo: 0.0,
            Xs: 0.0,
            Ys: 0.0,
            Zs: 0.0,
        }
    }
}

impl Pose {
    /// The kinematic symbol called `name` (a machine's symbol name), if the pose has it.
    pub fn symbol_mut(&mut self, name: &str) -> Option<&mut f64> {
        Some(match name {
            "Xa" => &mut self.Xa,
            "Ya" => &mut self.Ya,
            "Za" => &mut self.Za,
            "Zc" => &mut self.Zc,
            "Xw" => &mut self.Xw,
            "Yw" => &mut self.Yw,
            "Zw" => &mut self.Zw,
            "Xz" => &mut self.Xz,
            "Yz" => &mut self.Yz,
            "Zz" => &mut self.Zz,
            "Xh" => &mut self.Xh,
            "Zh" => &mut self.Zh,
            "Zp" => &mut self.Zp,
            "Xx" => &mut self.Xx,
            "Yx" => &mut self.Yx,
            "Zx" => &mut self.Zx,
            "Zt" => &mut self.Zt,
            "Xwo" => &mut self.Xwo,
            "Ywo" => &mut self.Ywo,
            "Zwo" => &mut self.Zwo,
            _ => return None,
        })
    }
}

/// One cell of a printed table.
#[derive(Clone, Copy)]
pub enum Cell {
    /// What the cell says, as a function of the pose.
    Printed(fn(&Pose) -> f64),
    /// Blank or unreadable in the extraction.
    Missing,
}

use Cell::{Missing, Printed as P};

/// One row: an error and its cells (extraction text, reading), one per column.
pub struct Row {
    /// The error's name as printed (`EXX`, `XOC`, …).
    pub error: &'static str,
    /// `(text as extracted, reading)`, one per column of the table.
    pub cells: &'static [(&'static str, Cell)],
}

/// A printed table.
pub struct Table {
    /// Short id used in reports (`Table 1`).
    pub id: &'static str,
    /// Its caption and paper.
    pub title: &'static str,
    /// The column headers, in the seed's notation.
    pub columns: &'static [&'static str],
    /// The rows the extraction shows, in printed order.
    pub rows: &'static [Row],
    /// Rows the table must have (by the paper's own count) that the extraction does not show.
    pub missing_rows: &'static [&'static str],
}

macro_rules! row {
    ($name:literal, [$($cell:expr),* $(,)?]) => {
        Row { error: $name, cells: &[$($cell),*] }
    };
}

/// The five-axis paper's Table 1, rows EXX … EYC (the extraction stops there).
pub static TABLE_1: Table = Table {
    id: "Table 1",
    title: "five-axis R-test paper, Table 1 \"Error model and sensitivity analysis\"",
    columns: &["ΔXp", "ΔYp", "ΔZp", "ΔIp", "ΔJp", "ΔKp"],
    missing_rows: &["EZC", "EAC", "EBC", "ECC", "XOC", "YOC", "AOC", "BOC"],
    rows: &[
        row!(
            "EXX",
            [
                ("-1", P(|_| -1.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("$\\mathbf{0}$", P(|_| 0.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
            ]
        ),
        row!(
            "EYX",
            [
                ("$\\mathbf{0}$", P(|_| 0.0)),
                ("-1", P(|_| -1.0)),
                ("$\\mathbf{0}$", P(|_| 0.0)),
                ("$\\mathbf{0}$", P(|_| 0.0)),
                ("$\\mathbf{0}$", P(|_| 0.0)),
                ("$\\mathbf{0}$", P(|_| 0.0)),
            ]
        ),
        row!(
            "EZX",
            [
                ("$\\mathbf{0}$", P(|_| 0.0)),
                ("Ω", P(|_| 0.0)),
                ("-1", P(|_| -1.0)),
                ("$\\mathbf{0}$", P(|_| 0.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("$\\mathbf{0}$", P(|_| 0.0)),
            ]
        ),
        row!(
            "EAX",
            [
                ("Ω", P(|_| 0.0)),
                (
                    "+Z _a +C _a *Z _c +S _a *S _c *X _w $+S_a*C_c*Y_w+C_a*Z_w$",
                    P(|p| p.Za
                        + p.ca * p.Zc
                        + p.sa * p.sc * p.Xw
                        + p.sa * p.cc * p.Yw
                        + p.ca * p.Zw)
                ),
                (
                    "$-Y_a+ S_a * Z_w + S_a * Z_c$ $-C_a*C_c*Y_w-C_a*S_c*X_w$",
                    P(|p| -p.Ya + p.sa * p.Zw + p.sa * p.Zc
                        - p.ca * p.cc * p.Yw
                        - p.ca * p.sc * p.Xw)
                ),
                ("θ", P(|_| 0.0)),
                ("C_a", P(|p| p.ca)),
                ("S_a", P(|p| p.sa)),
            ]
        ),
        row!(
            "EBX",
            [
                (
                    "$\\overline{-Z_a}$ - C_a * Z_c - S_a * S_c * X_w $-S_a*C_c*Y_w-C_a*Z_w$",
                    P(|p| -p.Za
                        - p.ca * p.Zc
                        - p.sa * p.sc * p.Xw
                        - p.sa * p.cc * p.Yw
                        - p.ca * p.Zw)
                ),
                ("Ω", P(|_| 0.0)),
                (
                    "$X_a - S_c * Y_w + C_c * X_w$",
                    P(|p| p.Xa - p.sc * p.Yw + p.cc * p.Xw)
                ),
                ("$-C_a$", P(|p| -p.ca)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
            ]
        ),
        row!(
            "ECX",
            [
                (
                    "+Y _a -S _a *Z _c -C _a *S _c *X _w $-C_a*C_c*Y_w-S_a*Z_w$",
                    P(|p| p.Ya
                        - p.sa * p.Zc
                        - p.ca * p.sc * p.Xw
                        - p.ca * p.cc * p.Yw
                        - p.sa * p.Zw)
                ),
                (
                    "$-X_a-C_c*X_w+S_c*Y_w$",
                    P(|p| -p.Xa - p.cc * p.Xw + p.sc * p.Yw)
                ),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("$-S_a$", P(|p| -p.sa)),
                ("Ω", P(|_| 0.0)),
                ("Ω", P(|_| 0.0)),
            ]
        ),
        row!(
            "EXY",
            [
                ("$\\mathbf{1}$", P(|_| 1.0)),
                ("$\\mathbf{0}$", P(|_| 0.0)),
                ("$\\mathbf{0}$", P(|_| 0.0)),
                ("$\\mathbf{0}$", P(|_| 0.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
            ]
        ),
        row!(
            "EYY",
            [
                ("$\\overline{0}$", P(|_| 0.0)),
                ("$\\overline{1}$", P(|_| 1.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("$\\mathbf{0}$", P(|_| 0.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("θ", P(|_| 0.0)),
            ]
        ),
        row!(
            "EZY",
            [
                ("$\\overline{0}$", P(|_| 0.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("$\\overline{1}$", P(|_| 1.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
            ]
        ),
        row!(
            "EAY",
            [
                ("$\\overline{0}$", P(|_| 0.0)),
                ("$-Z_h-Z_p-Z_m-Z_z$", P(|p| -p.Zh - p.Zp - p.zm - p.Zz)),
                ("$+Y_z$", P(|p| p.Yz)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("-1", P(|_| -1.0)),
                ("Ω", P(|_| 0.0)),
            ]
        ),
        row!(
            "EBY",
            [
                ("$+Z_h+Z_p+Z_m+Z_z$", P(|p| p.Zh + p.Zp + p.zm + p.Zz)),
                ("Ω", P(|_| 0.0)),
                ("$-X_h-X_z$", P(|p| -p.Xh - p.Xz)),
                ("$\\mathbf{1}$", P(|_| 1.0)),
                ("Ω", P(|_| 0.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
            ]
        ),
        row!(
            "ECY",
            [
                ("$-Y_{7}$", P(|p| -p.Yz)),
                ("$+X_h+X_z$", P(|p| p.Xh + p.Xz)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
            ]
        ),
        row!(
            "EXZ",
            [
                ("$\\mathbf{1}$", P(|_| 1.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("Ω", P(|_| 0.0)),
                ("Ω", P(|_| 0.0)),
            ]
        ),
        row!(
            "EYZ",
            [
                ("$\\overline{0}$", P(|_| 0.0)),
                ("$\\mathbf{1}$", P(|_| 1.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("θ", P(|_| 0.0)),
                ("Ω", P(|_| 0.0)),
            ]
        ),
        row!(
            "EZZ",
            [
                ("$\\overline{0}$", P(|_| 0.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("$\\mathbf{1}$", P(|_| 1.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("Ω", P(|_| 0.0)),
            ]
        ),
        row!(
            "EAZ",
            [
                ("Ω", P(|_| 0.0)),
                ("$-Z_h-Z_p$", P(|p| -p.Zh - p.Zp)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("-1", P(|_| -1.0)),
                ("θ", P(|_| 0.0)),
            ]
        ),
        row!(
            "EBZ",
            [
                ("$+Z_h+Z_p$", P(|p| p.Zh + p.Zp)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("$-X_h$", P(|p| -p.Xh)),
                ("$\\mathbf{1}$", P(|_| 1.0)),
                ("$\\mathbf{0}$", P(|_| 0.0)),
                ("$\\mathbf{0}$", P(|_| 0.0)),
            ]
        ),
        row!(
            "ECZ",
            [
                ("Ω", P(|_| 0.0)),
                ("$+X_h$", P(|p| p.Xh)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("Ω", P(|_| 0.0)),
                ("θ", P(|_| 0.0)),
            ]
        ),
        row!(
            "COX",
            [
                (
                    "$+Y_a - S_a * Z_c - C_a * S_c * X_w$ $-C_a*C_c*Y_w-S_a*Z_w$",
                    P(|p| p.Ya
                        - p.sa * p.Zc
                        - p.ca * p.sc * p.Xw
                        - p.ca * p.cc * p.Yw
                        - p.sa * p.Zw)
                ),
                (
                    "$-X_m-X_a$ $-C_c * X_w + S_c * Y_w$",
                    P(|p| -p.xm - p.Xa - p.cc * p.Xw + p.sc * p.Yw)
                ),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("$-Sa$", P(|p| -p.sa)),
                ("Ω", P(|_| 0.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
            ]
        ),
        row!(
            "AOZ",
            [
                ("Ω", P(|_| 0.0)),
                ("$-Z_h-Z_p-Z_m$", P(|p| -p.Zh - p.Zp - p.zm)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("-1", P(|_| -1.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
            ]
        ),
        row!(
            "BOZ",
            [
                ("$+Z_h+Z_p+Z_m$", P(|p| p.Zh + p.Zp + p.zm)),
                ("$\\overline{\\mathbf{0}}$", P(|_| 0.0)),
                ("$-X_h$", P(|p| -p.Xh)),
                ("$\\mathbf{1}$", P(|_| 1.0)),
                ("$\\mathbf{0}$", P(|_| 0.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
            ]
        ),
        row!(
            "XOW",
            [
                ("- C_c", P(|p| -p.cc)),
                ("- $C_a * S_c$", P(|p| -p.ca * p.sc)),
                ("$-S_a * S_c$", P(|p| -p.sa * p.sc)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("Ω", P(|_| 0.0)),
                ("$\\mathbf{0}$", P(|_| 0.0)),
            ]
        ),
        row!(
            "YOW",
            [
                ("S_c", P(|p| p.sc)),
                ("$-C_a$ [*] C_c", P(|p| -p.ca * p.cc)),
                ("$-S_a$ [*] C_c", P(|p| -p.sa * p.cc)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("θ", P(|_| 0.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
            ]
        ),
        row!(
            "ZOW",
            [
                ("$\\overline{0}$", P(|_| 0.0)),
                ("S_a", P(|p| p.sa)),
                ("$-C_a$", P(|p| -p.ca)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("Ω", P(|_| 0.0)),
                ("Ω", P(|_| 0.0)),
            ]
        ),
        row!(
            "EXA",
            [
                ("-1", P(|_| -1.0)),
                ("$\\mathbf{0}$", P(|_| 0.0)),
                ("$\\mathbf{0}$", P(|_| 0.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("$\\mathbf{0}$", P(|_| 0.0)),
            ]
        ),
        row!(
            "EYA",
            [
                ("$\\overline{0}$", P(|_| 0.0)),
                ("-1", P(|_| -1.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("Ω", P(|_| 0.0)),
                ("θ", P(|_| 0.0)),
            ]
        ),
        row!(
            "EZA",
            [
                ("$\\mathbf{0}$", P(|_| 0.0)),
                ("$\\boldsymbol{0}$", P(|_| 0.0)),
                ("-1", P(|_| -1.0)),
                ("$\\boldsymbol{0}$", P(|_| 0.0)),
                ("$\\mathbf{0}$", P(|_| 0.0)),
                ("$\\boldsymbol{0}$", P(|_| 0.0)),
            ]
        ),
        row!(
            "EAA",
            [
                ("$\\overline{0}$", P(|_| 0.0)),
                (
                    "+ $S_a * S_c * X_w + S_a * C_c * Y_w$ + $C_a*(Z_w+Z_c)$",
                    P(|p| p.sa * p.sc * p.Xw + p.sa * p.cc * p.Yw + p.ca * (p.Zw + p.Zc))
                ),
                (
                    "$-C_a*C_c*Y_w+S_a*(Z_w+Z_c)$ $-C_a * S_c * X_w$",
                    P(|p| -p.ca * p.cc * p.Yw + p.sa * (p.Zw + p.Zc) - p.ca * p.sc * p.Xw)
                ),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("C_a", P(|p| p.ca)),
                ("S_a", P(|p| p.sa)),
            ]
        ),
        row!(
            "EBA",
            [
                (
                    "$-C_a*(Z_w+Z_c) - S_a*S_c*X_w$ $-S_a * C_c * Y_w$",
                    P(|p| -p.ca * (p.Zw + p.Zc) - p.sa * p.sc * p.Xw - p.sa * p.cc * p.Yw)
                ),
                ("Ω", P(|_| 0.0)),
                ("$-S_c*Y_w+C_c*X_w$", P(|p| -p.sc * p.Yw + p.cc * p.Xw)),
                ("$-C_a$", P(|p| -p.ca)),
                ("$\\mathbf{0}$", P(|_| 0.0)),
                ("$\\mathbf{0}$", P(|_| 0.0)),
            ]
        ),
        row!(
            "ECA",
            [
                (
                    "$-S_a*(Z_w+Z_c) + C_a*S_c*X_w$ $+ C_a * C_c * Y_w$",
                    P(|p| -p.sa * (p.Zw + p.Zc) + p.ca * p.sc * p.Xw + p.ca * p.cc * p.Yw)
                ),
                (
                    "$-C_c * X_w + S_c * Y_w$",
                    P(|p| -p.cc * p.Xw + p.sc * p.Yw)
                ),
                ("$\\mathbf{0}$", P(|_| 0.0)),
                ("$-S_a$", P(|p| -p.sa)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
            ]
        ),
        row!(
            "YOA",
            [
                ("$\\overline{0}$", P(|_| 0.0)),
                ("-1", P(|_| -1.0)),
                ("$\\mathbf{0}$", P(|_| 0.0)),
                ("$\\mathbf{0}$", P(|_| 0.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("$\\mathbf{0}$", P(|_| 0.0)),
            ]
        ),
        row!(
            "ZOA",
            [
                ("Ω", P(|_| 0.0)),
                ("$\\mathbf{0}$", P(|_| 0.0)),
                ("-1", P(|_| -1.0)),
                ("$\\boldsymbol{0}$", P(|_| 0.0)),
                ("$\\mathbf{0}$", P(|_| 0.0)),
                ("$\\boldsymbol{0}$", P(|_| 0.0)),
            ]
        ),
        row!(
            "BOA",
            [
                (
                    "$-C_a*(Z_w+Z_c) - S_a*S_c*X_w$ $-S_a$ * C_c * Y_w",
                    P(|p| -p.ca * (p.Zw + p.Zc) - p.sa * p.sc * p.Xw - p.sa * p.cc * p.Yw)
                ),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("$-S_c*Y_w+C_c*X_w$", P(|p| -p.sc * p.Yw + p.cc * p.Xw)),
                ("$-ca$", P(|p| -p.ca)),
                ("Ω", P(|_| 0.0)),
                ("Ω", P(|_| 0.0)),
            ]
        ),
        row!(
            "COA",
            [
                (
                    "$-S_a*(Z_w+Z_c)+C_a*S_c*X_w$ + C_a * C_c * Y_w",
                    P(|p| -p.sa * (p.Zw + p.Zc) + p.ca * p.sc * p.Xw + p.ca * p.cc * p.Yw)
                ),
                (
                    "$-C_c * X_w + S_c * Y_w$",
                    P(|p| -p.cc * p.Xw + p.sc * p.Yw)
                ),
                ("$\\mathbf{0}$", P(|_| 0.0)),
                ("$-S_a$", P(|p| -p.sa)),
                ("$\\mathbf{0}$", P(|_| 0.0)),
                ("$\\mathbf{0}$", P(|_| 0.0)),
            ]
        ),
        row!(
            "EXC",
            [
                ("-1", P(|_| -1.0)),
                ("$\\boldsymbol{0}$", P(|_| 0.0)),
                ("$\\boldsymbol{0}$", P(|_| 0.0)),
                ("$\\boldsymbol{0}$", P(|_| 0.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("$\\boldsymbol{0}$", P(|_| 0.0)),
            ]
        ),
        row!(
            "EYC",
            [
                ("$\\mathbf{0}$", P(|_| 0.0)),
                ("$-C_a$", P(|p| -p.ca)),
                ("$-S_a$", P(|p| -p.sa)),
                ("$\\mathbf{0}$", P(|_| 0.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("$\\overline{0}$", P(|_| 0.0)),
            ]
        ),
    ],
};

/// The five-axis paper's Table 2 (reduced model, 11 errors, position columns only).
pub static TABLE_2: Table = Table {
    id: "Table 2",
    title: "five-axis R-test paper, Table 2 \"Reduced error model\"",
    columns: &["ΔXp", "ΔYp", "ΔZp"],
    missing_rows: &[],
    rows: &[
        row!(
            "XOW",
            [
                ("$-C_c$", P(|p| -p.cc)),
                ("$-C_a * S_c$", P(|p| -p.ca * p.sc)),
                ("$-S_a * S_c$", P(|p| -p.sa * p.sc)),
            ]
        ),
        row!(
            "YOW",
            [
                ("$+ S_c$", P(|p| p.sc)),
                ("$-C_a$ * C_c", P(|p| -p.ca * p.cc)),
                ("$-S_a$ * C_c", P(|p| -p.sa * p.cc)),
            ]
        ),
        row!(
            "ZOW",
            [
                ("$\\overline{0}$", P(|_| 0.0)),
                ("$+ S_a$", P(|p| p.sa)),
                ("$-C_a$", P(|p| -p.ca)),
            ]
        ),
        row!(
            "YOA",
            [
                ("$\\overline{0}$", P(|_| 0.0)),
                ("-1", P(|_| -1.0)),
                ("$\\mathbf{0}$", P(|_| 0.0)),
            ]
        ),
        row!(
            "ZOA",
            [
                ("$\\mathbf{0}$", P(|_| 0.0)),
                ("Ω", P(|_| 0.0)),
                ("-1", P(|_| -1.0)),
            ]
        ),
        row!(
            "BOA",
            [
                (
                    "$-C_a*(Z_w+Z_c) - S_a*S_c*X_w - S_a*C_c*Y_w$",
                    P(|p| -p.ca * (p.Zw + p.Zc) - p.sa * p.sc * p.Xw - p.sa * p.cc * p.Yw)
                ),
                ("Ω", P(|_| 0.0)),
                ("$-S_c*Y_w+C_c*X_w$", P(|p| -p.sc * p.Yw + p.cc * p.Xw)),
            ]
        ),
        row!(
            "COA",
            [
                (
                    "$-S_a*(Z_w+Z_c)+C_a*S_c*X_w+C_a*C_c*Y_w$",
                    P(|p| -p.sa * (p.Zw + p.Zc) + p.ca * p.sc * p.Xw + p.ca * p.cc * p.Yw)
                ),
                ("$-C_c*X_w+S_c*Y_w$", P(|p| -p.cc * p.Xw + p.sc * p.Yw)),
                ("Ω", P(|_| 0.0)),
            ]
        ),
        row!(
            "XOC",
            [("-1", P(|_| -1.0)), ("Ω", P(|_| 0.0)), ("θ", P(|_| 0.0)),]
        ),
        row!(
            "YOC",
            [
                ("$\\overline{0}$", P(|_| 0.0)),
                ("$-C_a$", P(|p| -p.ca)),
                ("$-S_a$", P(|p| -p.sa)),
            ]
        ),
        row!(
            "AOC",
            [
                ("$\\overline{0}$", P(|_| 0.0)),
                (
                    "$+ S_c * S_a * X_w + C_c * S_a * Y_w + C_a * Z_w$",
                    P(|p| p.sc * p.sa * p.Xw + p.cc * p.sa * p.Yw + p.ca * p.Zw)
                ),
                (
                    "$-C_c*C_a*Y_w+S_a*Z_w-S_c*C_a*X_w$",
                    P(|p| -p.cc * p.ca * p.Yw + p.sa * p.Zw - p.sc * p.ca * p.Xw)
                ),
            ]
        ),
        row!(
            "BOC",
            [
                ("$-Z_w$", P(|p| -p.Zw)),
                (
                    "$-C_c * S_a * X_w + S_c * S_a * Y_w$",
                    P(|p| -p.cc * p.sa * p.Xw + p.sc * p.sa * p.Yw)
                ),
                (
                    "$-S_c*C_a*Y_w + C_c*C_a*X_w$",
                    P(|p| -p.sc * p.ca * p.Yw + p.cc * p.ca * p.Xw)
                ),
            ]
        ),
    ],
};

/// The three-axis paper's Table II; blank cells are [`Cell::Missing`].
pub static TABLE_II: Table = Table {
    id: "Table II",
    title: "three-axis paper, Table II \"Error model with parametric-independent\"",
    columns: &["ΔXr", "ΔYr", "ΔZr", "ΔIr", "ΔJr", "ΔKr"],
    missing_rows: &[],
    rows: &[
        row!(
            "EXX",
            [
                ("", Missing),
                ("Ω", P(|_| 0.0)),
                ("0", P(|_| 0.0)),
                ("θ", P(|_| 0.0)),
                ("0", P(|_| 0.0)),
                ("Ω", P(|_| 0.0)),
            ]
        ),
        row!(
            "EYX",
            [
                ("0", P(|_| 0.0)),
                ("", Missing),
                ("", Missing),
                ("0", P(|_| 0.0)),
                ("0", P(|_| 0.0)),
                ("0", P(|_| 0.0)),
            ]
        ),
        row!(
            "EZX",
            [
                ("0", P(|_| 0.0)),
                ("", Missing),
                ("", Missing),
                ("0", P(|_| 0.0)),
                ("Ω", P(|_| 0.0)),
                ("", Missing),
            ]
        ),
        row!(
            "EAX",
            [
                ("0", P(|_| 0.0)),
                ("$-Z_m$", P(|p| -p.zm)),
                ("", Missing),
                ("0", P(|_| 0.0)),
                ("-1", P(|_| -1.0)),
                ("0", P(|_| 0.0)),
            ]
        ),
        row!(
            "EBX",
            [
                ("Z_m", P(|p| p.zm)),
                ("θ", P(|_| 0.0)),
                ("", Missing),
                ("", Missing),
                ("Ω", P(|_| 0.0)),
                ("", Missing),
            ]
        ),
        row!(
            "ECX",
            [
                ("Ω", P(|_| 0.0)),
                ("0", P(|_| 0.0)),
                ("", Missing),
                ("0", P(|_| 0.0)),
                ("0", P(|_| 0.0)),
                ("Ω", P(|_| 0.0)),
            ]
        ),
        row!(
            "EXY",
            [
                ("", Missing),
                ("", Missing),
                ("", Missing),
                ("0", P(|_| 0.0)),
                ("0", P(|_| 0.0)),
                ("0", P(|_| 0.0)),
            ]
        ),
        row!(
            "EYY",
            [
                ("0", P(|_| 0.0)),
                ("", Missing),
                ("", Missing),
                ("0", P(|_| 0.0)),
                ("Ω", P(|_| 0.0)),
                ("", Missing),
            ]
        ),
        row!(
            "EZY",
            [
                ("Ω", P(|_| 0.0)),
                ("", Missing),
                ("", Missing),
                ("0", P(|_| 0.0)),
                ("0", P(|_| 0.0)),
                ("0", P(|_| 0.0)),
            ]
        ),
        row!(
            "EAY",
            [
                ("Ω", P(|_| 0.0)),
                ("$-(Z_s+Z_m)$", P(|p| -(p.Zs + p.zm))),
                ("0", P(|_| 0.0)),
                ("0", P(|_| 0.0)),
                ("-1", P(|_| -1.0)),
                ("0", P(|_| 0.0)),
            ]
        ),
        row!(
            "EBY",
            [
                ("Z_s+Z_m", P(|p| p.Zs + p.zm)),
                ("θ", P(|_| 0.0)),
                ("$X_s - X_m$", P(|p| p.Xs - p.xm)),
                ("", Missing),
                ("0", P(|_| 0.0)),
                ("", Missing),
            ]
        ),
        row!(
            "ECY",
            [
                ("0", P(|_| 0.0)),
                ("$-(X_s - X_m)$", P(|p| -(p.Xs - p.xm))),
                ("0", P(|_| 0.0)),
                ("0", P(|_| 0.0)),
                ("Ω", P(|_| 0.0)),
                ("0", P(|_| 0.0)),
            ]
        ),
        row!(
            "EXZ",
            [
                ("", Missing),
                ("0", P(|_| 0.0)),
                ("", Missing),
                ("0", P(|_| 0.0)),
                ("Ω", P(|_| 0.0)),
                ("0", P(|_| 0.0)),
            ]
        ),
        row!(
            "EYZ",
            [
                ("0", P(|_| 0.0)),
                ("", Missing),
                ("", Missing),
                ("O", P(|_| 0.0)),
                ("0", P(|_| 0.0)),
                ("", Missing),
            ]
        ),
        row!(
            "EZZ",
            [
                ("0", P(|_| 0.0)),
                ("", Missing),
                ("", Missing),
                ("0", P(|_| 0.0)),
                ("0", P(|_| 0.0)),
                ("0", P(|_| 0.0)),
            ]
        ),
        row!(
            "EAZ",
            [
                ("0", P(|_| 0.0)),
                ("0", P(|_| 0.0)),
                ("", Missing),
                ("0", P(|_| 0.0)),
                ("-1", P(|_| -1.0)),
                ("0", P(|_| 0.0)),
            ]
        ),
        row!(
            "EBZ",
            [
                ("0", P(|_| 0.0)),
                ("Ω", P(|_| 0.0)),
                ("", Missing),
                ("", Missing),
                ("0", P(|_| 0.0)),
                ("Ω", P(|_| 0.0)),
            ]
        ),
        row!(
            "ECZ",
            [
                ("0", P(|_| 0.0)),
                ("0", P(|_| 0.0)),
                ("", Missing),
                ("O", P(|_| 0.0)),
                ("0", P(|_| 0.0)),
                ("0", P(|_| 0.0)),
            ]
        ),
        row!(
            "COX",
            [
                ("Ω", P(|_| 0.0)),
                ("X_m", P(|p| p.xm)),
                ("", Missing),
                ("0", P(|_| 0.0)),
                ("0", P(|_| 0.0)),
                ("", Missing),
            ]
        ),
        row!(
            "AOZ",
            [
                ("$_{0}$", P(|_| 0.0)),
                ("$-Z_m$", P(|p| -p.zm)),
                ("", Missing),
                ("", Missing),
                ("-1", P(|_| -1.0)),
                ("0", P(|_| 0.0)),
            ]
        ),
        row!(
            "BOZ",
            [
                ("Z_m", P(|p| p.zm)),
                ("$\\overline{0}$", P(|_| 0.0)),
                ("0", P(|_| 0.0)),
                ("", Missing),
                ("θ", P(|_| 0.0)),
                ("θ", P(|_| 0.0)),
            ]
        ),
    ],
};
