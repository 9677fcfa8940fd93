//! NC programs of commanded poses, read and written back in the same dialect
//! (`docs/nc-programs.md`).
//!
//! A program is read as the sequence of its **poses**: every block that moves (that has at
//! least one axis word) gives the command of every axis of the machine, the axes it does not
//! name keeping their values from earlier blocks (modal). Programs are in machine coordinates,
//! mm, absolute positions, tool centre point control off; everything that would make a
//! position in the program differ from the axis command (incremental positions, arcs, work
//! offsets, rotations, scaling, tool compensation, TCP, cycles, subprograms) is refused with
//! an error that names the file, line, column and word, and says why.
//!
//! Three dialects ([`Dialect`]): ISO G-code as Fanuc-type controls read it ([`Dialect::Iso`]:
//! `G90 G1 X10.5 Y-3 A0 C90 F2000`), LinuxCNC's G-code ([`Dialect::LinuxCnc`]: the same blocks,
//! read by the ISO rules but for what LinuxCNC reads otherwise) and Heidenhain conversational
//! ([`Dialect::Heidenhain`]: `7 L X+10.5 Y-3 A+0 C+90 R0 FMAX`).
//!
//! A program is held as its text and its poses ([`PoseList`]: 8 bytes per axis and 4 per pose),
//! nothing per word: the writer reads the blocks again (the same reading, so the same words) to
//! find the words it rewrites. At most [`MAX_POSES`] poses are read.
//!
//! Written back ([`NcProgram::writer`], pose after pose, or [`NcProgram::write`]), only the
//! axis words of the blocks that move change:
//! each keeps the decimals and the style of the program's word, and the words of axes a block
//! left modal are inserted after its last axis word where the correction changes them. Every
//! other byte is kept (lines, comments, block numbers, spaces, line ends). The largest
//! rounding per axis is reported ([`Written::rounding`]).
//!
//! ```
//! use model_spec::AxisKind::{Linear, Rotary};
//! use formats::nc::{Dialect, WriteOptions, parse_program};
//! use formats::poses::AxisWord;
//! let axes = [
//!     AxisWord { letter: 'X', kind: Linear },
//!     AxisWord { letter: 'Y', kind: Linear },
//!     AxisWord { letter: 'C', kind: Rotary },
//! ];
//! let text = "%\nN10 G90 G0 X0 Y0 C0\nN20 G1 X10.5 F500 (cut)\n%\n";
//! let p = parse_program("a.nc", text, Dialect::Iso, &axes).unwrap();
//! assert_eq!(p.pose_list().line(1), 3);
//! assert_eq!(p.pose_list().commands(1), [10.5, 0.0, 0.0]);
//! let corrected = [vec![0.0, 0.0, 0.0], vec![10.52, 0.004, 0.0]];
//! // At the program's resolution (0.1 mm for X, 1 mm for Y) nothing changes, at a cost:
//! let w = p.write(&corrected, &WriteOptions::new()).unwrap();
//! assert_eq!(w.text, text);
//! assert!((w.rounding[0] - 0.02).abs() < 1e-12 && (w.rounding[1] - 0.004).abs() < 1e-12);
//! // With three decimals at least, X is rewritten and Y, modal in N20, is inserted:
//! let w = p.write(&corrected, &WriteOptions::with_min_decimals(3)).unwrap();
//! assert_eq!(w.text, "%\nN10 G90 G0 X0 Y0 C0\nN20 G1 X10.520 Y0.004 F500 (cut)\n%\n");
//!
//! let e = parse_program("a.nc", "G91 G1 X1\n", Dialect::Iso, &axes).unwrap_err();
//! assert!(e.to_string().starts_with("a.nc:1:1: `G91`: incremental positions are refused"));
//! ```
//!
//! Files: `iso` (the block reader of ISO and LinuxCNC programs), `heidenhain` (that of
//! conversational ones), `program` (lines, modal positions, poses), `number` (the numbers of words and their style), `write`, `error`.

mod error;
mod heidenhain;
mod iso;
pub mod number;
mod program;
mod write;

use crate::poses::{AxisWord, CommandedPose, MAX_POSES, PoseList, read_keeping_bom};
pub use error::NcError;
use std::path::Path;
pub use write::{MAX_DECIMALS, ProgramWriter, RoundingAt, WriteOptions, Written};

/// A pose of a program: the 1-based line of the block and the command of every axis (in the
/// order of the axis words; mm and degrees).
pub type NcPose = CommandedPose;

/// The language of a program.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Dialect {
    /// ISO 6983 G-code as Fanuc-type controls read it: words of a letter and a number.
    Iso,
    /// G-code as LinuxCNC reads it (RS274/NGC): the words of [`Dialect::Iso`], dwells in
    /// seconds, no program number (`O` words are subroutines and loops there).
    LinuxCnc,
    /// Heidenhain conversational (Klartext, `.h` files): `L X+10 Y+5 R0 FMAX` blocks.
    Heidenhain,
}

impl Dialect {
    /// The name on the command line: `iso`, `linuxcnc` or `heidenhain`.
    pub fn name(self) -> &'static str {
        match self {
            Dialect::Iso => "iso",
            Dialect::LinuxCnc => "linuxcnc",
            Dialect::Heidenhain => "heidenhain",
        }
    }

    /// The dialect called `name` (`iso`, `linuxcnc`, `heidenhain`), `None` for another name.
    /// `fanuc` is not a name of [`Dialect::Iso`]: one name per dialect (see
    /// `docs/nc-programs.md`).
    pub fn from_name(name: &str) -> Option<Dialect> {
        match name {
            "iso" => Some(Dialect::Iso),
            "linuxcnc" => Some(Dialect::LinuxCnc),
            "heidenhain" => Some(Dialect::Heidenhain),
            _ => None,
        }
    }

    /// The names of every dialect, as the command line takes them.
    pub const NAMES: [&'static str; 3] = ["iso", "linuxcnc", "heidenhain"];

    /// Whether programs of this dialect are G-code (words of a letter and a number): ISO and
    /// LinuxCNC.
    pub fn is_g_code(self) -> bool {
        matches!(self, Dialect::Iso | Dialect::LinuxCnc)
    }
}

/// A program as read: its text and its poses.
#[derive(Clone, Debug)]
pub struct NcProgram {
    file: String,
    text: String,
    dialect: Dialect,
    axes: Vec<AxisWord>,
    poses: PoseList,
}

impl NcProgram {
    /// The poses, one per block that moves, in the order of the program, held flat.
    pub fn pose_list(&self) -> &PoseList {
        &self.poses
    }

    /// The poses, one per block that moves, in the order of the program, each copied out with
    /// a vector of its own ([`PoseList::to_poses`]): for short programs and tests;
    /// [`NcProgram::pose_list`] holds them without a copy.
    pub fn poses(&self) -> Vec<NcPose> {
        self.poses.to_poses()
    }

    /// The bytes the program holds on the heap: its text, its poses (8 bytes per axis and 4
    /// per pose), its file name and axes. Besides the text, 44 bytes a pose of five axes.
    pub fn held_bytes(&self) -> usize {
        self.text.capacity()
            + self.poses.held_bytes()
            + self.file.capacity()
            + self.axes.capacity() * size_of::<AxisWord>()
    }

    /// The dialect the program was read in.
    pub fn dialect(&self) -> Dialect {
        self.dialect
    }

    /// The file name given to the reader.
    pub fn file(&self) -> &str {
        &self.file
    }
}

/// Reads program `text` (named `file` in messages) of dialect `dialect` for the axes `axes` (see
/// the module documentation and `docs/nc-programs.md`).
///
/// # Errors
/// [`NcError::Block`] for the first block that cannot be read or is refused, with its line,
/// column and word; a move before every axis has a value; [`NcError::Program`] for a program
/// without a move, with more than [`MAX_POSES`] moves, or an axis letter that is a word of the
/// dialect (`F`, `M`, …); [`NcError::Text`] for a text longer than
/// [`crate::poses::MAX_FILE_BYTES`].
pub fn parse_program(
    file: &str,
    text: &str,
    dialect: Dialect,
    axes: &[AxisWord],
) -> Result<NcProgram, NcError> {
    program::parse(file, text.to_string(), dialect, axes, MAX_POSES)
}

/// Reads the program file at `path` (at most [`crate::poses::MAX_FILE_BYTES`], UTF-8, a
/// byte-order mark kept; named in messages as `path.display()` writes it); see
/// [`parse_program`].
///
/// # Errors
/// As [`parse_program`]; [`NcError::Text`] when the file cannot be read, is too large or is not
/// UTF-8.
pub fn read_program(
    path: &Path,
    dialect: Dialect,
    axes: &[AxisWord],
) -> Result<NcProgram, NcError> {
    let (text, _) = read_keeping_bom(path).map_err(NcError::Text)?;
    program::parse(&path.display().to_string(), text, dialect, axes, MAX_POSES)
}
