//! Coordinate directions and the ISO 230 letters that go with them.

use std::fmt;

/// One of the three coordinate directions of the machine reference frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Dir {
    /// The x direction.
    X,
    /// The y direction.
    Y,
    /// The z direction.
    Z,
}

impl Dir {
    /// All three directions in order x, y, z.
    pub const ALL: [Dir; 3] = [Dir::X, Dir::Y, Dir::Z];

    /// Index 0, 1 or 2.
    pub fn index(self) -> usize {
        match self {
            Dir::X => 0,
            Dir::Y => 1,
            Dir::Z => 2,
        }
    }

    /// The ISO letter of a translation along this direction (`X`, `Y`, `Z`).
    pub fn translation_letter(self) -> char {
        ['X', 'Y', 'Z'][self.index()]
    }

    /// The ISO letter of a rotation about this direction (`A`, `B`, `C`).
    pub fn rotation_letter(self) -> char {
        ['A', 'B', 'C'][self.index()]
    }

    /// The direction whose translation letter is `c` (`X`, `Y`, `Z`).
    pub fn from_translation_letter(c: char) -> Option<Dir> {
        match c {
            'X' => Some(Dir::X),
            'Y' => Some(Dir::Y),
            'Z' => Some(Dir::Z),
            _ => None,
        }
    }

    /// The direction whose rotation letter is `c` (`A`, `B`, `C`).
    pub fn from_rotation_letter(c: char) -> Option<Dir> {
        match c {
            'A' => Some(Dir::X),
            'B' => Some(Dir::Y),
            'C' => Some(Dir::Z),
            _ => None,
        }
    }

    /// The two directions perpendicular to this one, in x, y, z order.
    pub fn perpendicular(self) -> [Dir; 2] {
        match self {
            Dir::X => [Dir::Y, Dir::Z],
            Dir::Y => [Dir::X, Dir::Z],
            Dir::Z => [Dir::X, Dir::Y],
        }
    }
}

impl fmt::Display for Dir {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", ['x', 'y', 'z'][self.index()])
    }
}

/// A signed coordinate direction: the direction in which a linear axis moves, or about which a
/// rotary axis turns (right-hand rule), for a positive command.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Direction {
    /// The coordinate direction.
    pub dir: Dir,
    /// `true` when a positive command moves (turns) against the coordinate direction.
    pub negative: bool,
}

impl Direction {
    /// `+1.0` or `-1.0`.
    pub fn sign(self) -> f64 {
        if self.negative { -1.0 } else { 1.0 }
    }

    /// Parses `+x`, `x`, `-z`, … (case-insensitive).
    pub fn parse(s: &str) -> Option<Direction> {
        let t = s.trim().to_ascii_lowercase();
        let (negative, rest) = match t.strip_prefix('-') {
            Some(r) => (true, r),
            None => (false, t.strip_prefix('+').unwrap_or(&t)),
        };
        let dir = match rest {
            "x" => Dir::X,
            "y" => Dir::Y,
            "z" => Dir::Z,
            _ => return None,
        };
        Some(Direction { dir, negative })
    }
}

impl fmt::Display for Direction {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}{}", if self.negative { '-' } else { '+' }, self.dir)
    }
}
