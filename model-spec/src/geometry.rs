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

/// An inclined axis: the direction as written and the axis's own frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inclined {
    /// The direction as written in the description (any finite non-zero vector).
    pub written: [f64; 3],
    /// The own frame: `z'` along the normalised direction, `x'` the machine x projected
    /// perpendicular to it, `y' = z' × x'` ([`crate::surd::unit_frame`]), exact where the
    /// components allow.
    pub frame: crate::surd::UnitFrame,
}

/// The direction of an axis: along a signed coordinate direction, or inclined.
///
/// An inclined axis is described in its own frame, where it moves along (turns about) `+z'`:
/// its errors are named with the letters of that frame (`EXB`, `EYB` radial, `EZB` axial,
/// `EAB`, `EBB` tilts, `ECB` positioning; `XOB YOB AOB BOB` location), so its tables read like
/// those of a C axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxisDirection {
    /// The direction in the axis's own frame: the coordinate direction itself for an axis along
    /// x, y or z; `+z` for an inclined axis.
    pub own: Direction,
    /// The inclination, for an inclined axis.
    pub inclined: Option<Inclined>,
}

impl AxisDirection {
    /// An axis along a signed coordinate direction.
    pub fn coordinate(d: Direction) -> AxisDirection {
        AxisDirection {
            own: d,
            inclined: None,
        }
    }

    /// The direction of the vector `v`: a signed coordinate direction when only one component
    /// is non-zero (`[-1, 0, 0]` is `-x`, exactly as `"-x"`), inclined otherwise. `None` for a
    /// zero or non-finite vector, or one whose own frame cannot be formed in `f64`.
    pub fn from_vector(v: [f64; 3]) -> Option<AxisDirection> {
        if v.iter().any(|x| !x.is_finite()) || v.iter().all(|&x| x == 0.0) {
            return None;
        }
        // A vector whose length or whose components' products leave the f64 range is scaled
        // by a power of two first (exact); ordinary vectors are kept as written, so that their
        // components are recognised exactly.
        let largest = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let v = if (1e-100..=1e100).contains(&largest) {
            v
        } else {
            let scale = 2f64.powi(-largest.log2().round() as i32);
            v.map(|x| x * scale)
        };
        let nonzero: Vec<usize> = (0..3).filter(|&i| v[i] != 0.0).collect();
        if let [i] = nonzero[..] {
            return Some(AxisDirection::coordinate(Direction {
                dir: Dir::ALL[i],
                negative: v[i] < 0.0,
            }));
        }
        let frame = crate::surd::unit_frame(v);
        // The frame must be orthonormal (it is, unless a component underflows to nothing).
        let f = frame.axes.map(|a| a.map(crate::surd::Real::to_f64));
        let orthonormal = (0..3).all(|i| {
            (0..3).all(|j| {
                let dot: f64 = (0..3).map(|k| f[i][k] * f[j][k]).sum();
                (dot - if i == j { 1.0 } else { 0.0 }).abs() < 1e-12
            })
        });
        orthonormal.then_some(AxisDirection {
            own: Direction {
                dir: Dir::Z,
                negative: false,
            },
            inclined: Some(Inclined { written: v, frame }),
        })
    }

    /// The signed coordinate direction, `None` for an inclined axis.
    pub fn as_coordinate(&self) -> Option<Direction> {
        self.inclined.is_none().then_some(self.own)
    }

    /// The own frame as floating-point rows `[x', y', z']` in machine coordinates (the identity
    /// for a coordinate axis).
    pub fn frame(&self) -> [[f64; 3]; 3] {
        match &self.inclined {
            Some(i) => i.frame.axes.map(|a| a.map(crate::surd::Real::to_f64)),
            None => [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        }
    }

    /// The unit vector of motion (linear) or of the rotation vector (rotary) for a positive
    /// command, in machine coordinates.
    pub fn unit(&self) -> [f64; 3] {
        match &self.inclined {
            Some(i) => i.frame.axes[2].map(crate::surd::Real::to_f64),
            None => {
                let mut u = [0.0; 3];
                u[self.own.dir.index()] = self.own.sign();
                u
            }
        }
    }
}

impl fmt::Display for AxisDirection {
    /// `+x`, or the written vector of an inclined axis (`[0, 1, 1]`).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.inclined {
            Some(i) => write!(f, "[{}, {}, {}]", i.written[0], i.written[1], i.written[2]),
            None => write!(f, "{}", self.own),
        }
    }
}
