//! The innovation gate: an update whose normalised innovation squared (NIS) exceeds the
//! chi-square quantile for its number of rows is rejected. The default is the 99.9 % quantile,
//! which rejects a good measurement once in a thousand.

/// The chi-square 99.9 % quantiles for 1 to 6 degrees of freedom (a height; the constraints;
/// an odometer with them or a zero velocity; …; a position-and-velocity fix), checked against
/// the chi-square distribution in `tests/aids.rs`.
pub const CHI2_99_9: [f64; 6] = [
    10.827_566_170_662_733,
    13.815_510_557_964_274,
    16.266_236_196_238_13,
    18.466_826_952_903_17,
    20.515_005_652_432_873,
    22.457_744_484_825_323,
];

/// Which updates the filter takes: all, or those whose normalised innovation squared (NIS) is
/// within a chi-square value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Gate {
    /// Every update is applied.
    Off,
    /// An update whose NIS exceeds this value is rejected (and counted).
    ChiSquare(f64),
}

impl Gate {
    /// Whether an update of normalised innovation squared `nis` is rejected.
    #[must_use]
    pub fn rejects(self, nis: f64) -> bool {
        match self {
            Self::Off => false,
            Self::ChiSquare(x) => nis > x,
        }
    }

    /// Whether updates are gated at all.
    #[must_use]
    pub fn is_on(self) -> bool {
        matches!(self, Self::ChiSquare(_))
    }
}

/// The 99.9 % gate for an update of `rows` rows (1 to 6; off beyond).
#[must_use]
pub fn gate_99_9(rows: usize) -> Gate {
    match rows {
        1..=6 => Gate::ChiSquare(CHI2_99_9[rows - 1]),
        _ => Gate::Off,
    }
}
