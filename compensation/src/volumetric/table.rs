//! A measured table: values at strictly increasing positions of one axis, interpolated
//! linearly between them (what a controller's compensation table does), and its
//! least-squares straight line (the reference line of a straightness, ISO 230-1).

/// Values of one quantity (mm or rad) at strictly increasing positions (mm) of one axis.
#[derive(Clone, Debug, PartialEq)]
pub struct Table {
    /// Positions, mm, strictly increasing, at least two.
    pub positions: Vec<f64>,
    /// The value at each position (mm or rad).
    pub values: Vec<f64>,
}

impl Table {
    /// The table of `values` at `positions` (same length, at least two, positions strictly
    /// increasing: the laser reader guarantees it).
    pub fn new(positions: Vec<f64>, values: Vec<f64>) -> Table {
        debug_assert!(positions.len() >= 2 && positions.len() == values.len());
        debug_assert!(positions.windows(2).all(|w| w[0] < w[1]));
        Table { positions, values }
    }

    /// `[first, last]` position, mm.
    pub fn range(&self) -> [f64; 2] {
        [self.positions[0], self.positions[self.positions.len() - 1]]
    }

    /// The value at `q` (mm), linear between the two measured positions around it. `q` is
    /// clamped to the measured range: callers check the range first
    /// ([`crate::volumetric::VolumetricModel::check_range`]).
    pub fn at(&self, q: f64) -> f64 {
        let p = &self.positions;
        let n = p.len();
        if q <= p[0] {
            return self.values[0];
        }
        if q >= p[n - 1] {
            return self.values[n - 1];
        }
        // The first position above q: 1 ≤ i ≤ n − 1.
        let i = p.partition_point(|&x| x <= q);
        let (q0, q1) = (p[i - 1], p[i]);
        let (v0, v1) = (self.values[i - 1], self.values[i]);
        let w = (q - q0) / (q1 - q0);
        v0 + w * (v1 - v0)
    }

    /// The least-squares straight line through the table's points: `(value at mean position,
    /// slope per mm, mean position)`.
    pub fn least_squares_line(&self) -> (f64, f64, f64) {
        let n = self.positions.len() as f64;
        let qm = self.positions.iter().sum::<f64>() / n;
        let vm = self.values.iter().sum::<f64>() / n;
        let (mut sqq, mut sqv) = (0.0, 0.0);
        for (q, v) in self.positions.iter().zip(&self.values) {
            sqq += (q - qm) * (q - qm);
            sqv += (q - qm) * (v - vm);
        }
        (vm, sqv / sqq, qm)
    }

    /// The table with its least-squares straight line taken out: the straightness relative to
    /// its reference straight line (ISO 230-1).
    pub fn without_line(&self) -> Table {
        let (vm, slope, qm) = self.least_squares_line();
        let values = self
            .positions
            .iter()
            .zip(&self.values)
            .map(|(q, v)| v - vm - slope * (q - qm))
            .collect();
        Table::new(self.positions.clone(), values)
    }
}

#[cfg(test)]
mod tests {
    use super::Table;

    #[test]
    fn interpolates_linearly_and_holds_the_ends() {
        let t = Table::new(vec![0.0, 10.0, 30.0], vec![1.0, 3.0, -1.0]);
        assert_eq!(t.at(0.0), 1.0);
        assert_eq!(t.at(5.0), 2.0);
        assert_eq!(t.at(10.0), 3.0);
        assert_eq!(t.at(20.0), 1.0);
        assert_eq!(t.at(30.0), -1.0);
        assert_eq!(t.at(-1.0), 1.0);
        assert_eq!(t.at(31.0), -1.0);
        assert_eq!(t.range(), [0.0, 30.0]);
    }

    #[test]
    fn the_least_squares_line_of_a_line_is_itself() {
        let t = Table::new(vec![-2.0, 1.0, 5.0], vec![-3.0, 3.0, 11.0]);
        let (vm, slope, qm) = t.least_squares_line();
        assert!((slope - 2.0).abs() < 1e-15);
        assert!((vm - (2.0 * qm + 1.0)).abs() < 1e-14);
        assert!(t.without_line().values.iter().all(|v| v.abs() < 1e-14));
    }
}
