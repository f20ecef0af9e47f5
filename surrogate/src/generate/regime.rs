//! The depletion regime of one training row: how many trapped-carrier pockets the exact solve
//! ended with, the largest one's level and their total volume (`hpge_solver::field::pockets`).
//!
//! Why these three: the small-signal c12 jumps where an undepleted region is pinched off from
//! its contact and becomes a floating pocket (the pinch-off voltage U_po(p)), and is smooth on
//! either side. The count says on which side of that switching surface a row lies; the volume
//! goes to zero continuously where the last pocket depletes (so the far edge of the pocket
//! regime is located by it, not guessed); the level of the largest pocket is the potential it
//! floats at (V), the quantity the weighting problem sees. Rows of runs made before these
//! columns existed are labelled by solving them again (`hpge-cv label`), never by guessing.

use hpge_solver::field::Pocket;

/// CSV names of the regime columns, in order (after `c12_err_pF`, before `seconds`).
pub const REGIME_COLUMNS: [&str; 3] = ["pockets", "pocket_level_V", "pocket_cm3"];

/// The pockets of one solved row.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Regime {
    /// Number of pockets at this bias (0: none).
    pub pockets: usize,
    /// Level of the largest pocket (by volume), V; NaN without a pocket.
    pub level_v: f64,
    /// Total semiconductor volume of the pockets, cm^3 (0 without a pocket).
    pub volume_cm3: f64,
}

impl Regime {
    /// No pocket.
    pub const NONE: Regime = Regime {
        pockets: 0,
        level_v: f64::NAN,
        volume_cm3: 0.0,
    };

    /// The regime of a solution with `pockets`: their count, the level of the largest
    /// (ties: the first in the solver's order) and sum_k V_k.
    pub fn from_pockets(pockets: &[Pocket]) -> Regime {
        Regime::from_levels(pockets.iter().map(|p| (p.level_v, p.volume_cm3)))
    }

    /// [`Regime::from_pockets`] from each pocket's (level V, volume cm^3).
    pub fn from_levels(pockets: impl IntoIterator<Item = (f64, f64)>) -> Regime {
        let mut r = Regime::NONE;
        let mut largest = f64::NEG_INFINITY;
        for (level_v, volume_cm3) in pockets {
            r.pockets += 1;
            r.volume_cm3 += volume_cm3;
            if volume_cm3 > largest {
                largest = volume_cm3;
                r.level_v = level_v;
            }
        }
        r
    }

    /// The three CSV fields (no leading comma); a failed solve (`None`) writes NaN in each.
    pub fn csv(r: Option<&Regime>) -> String {
        match r {
            Some(r) => format!("{},{},{}", r.pockets, r.level_v, r.volume_cm3),
            None => "NaN,NaN,NaN".to_string(),
        }
    }

    /// Parses the three fields as [`Regime::csv`] writes them (None: a failed row's NaNs, or
    /// text that is not a regime).
    ///
    /// ```
    /// use hpge_surrogate::generate::Regime;
    /// // One pocket at -12.5 V of 0.25 cm^3, as a row of rows.csv carries it.
    /// let r = Regime::parse("1", "-12.5", "0.25").expect("a regime");
    /// assert_eq!((r.pockets, r.level_v, r.volume_cm3), (1, -12.5, 0.25));
    /// assert_eq!(Regime::csv(Some(&r)), "1,-12.5,0.25");
    /// assert_eq!(Regime::parse("NaN", "NaN", "NaN"), None, "a failed row");
    /// ```
    pub fn parse(pockets: &str, level_v: &str, volume_cm3: &str) -> Option<Regime> {
        Some(Regime {
            pockets: pockets.trim().parse().ok()?,
            level_v: level_v.trim().parse().ok()?,
            volume_cm3: volume_cm3.trim().parse().ok()?,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_largest_pocket_gives_the_level_and_the_volumes_add() {
        let r = Regime::from_levels([(10.0, 0.5), (20.0, 2.0), (30.0, 1.0)]);
        assert_eq!(r.pockets, 3);
        assert_eq!(r.level_v, 20.0);
        assert!((r.volume_cm3 - 3.5).abs() < 1e-15);
        let none = Regime::from_pockets(&[]);
        assert_eq!(none.pockets, 0);
        assert!(none.level_v.is_nan());
        assert_eq!(none.volume_cm3, 0.0);
    }

    #[test]
    fn csv_fields_round_trip_and_a_failed_row_is_nan() {
        let r = Regime::from_levels([(-12.5, 0.25)]);
        let text = Regime::csv(Some(&r));
        let f: Vec<&str> = text.split(',').collect();
        assert_eq!(Regime::parse(f[0], f[1], f[2]), Some(r));
        assert_eq!(Regime::csv(None), "NaN,NaN,NaN");
        assert_eq!(Regime::parse("NaN", "NaN", "NaN"), None);
        let none = Regime::csv(Some(&Regime::NONE));
        assert_eq!(none, "0,NaN,0");
        let f: Vec<&str> = none.split(',').collect();
        let back = Regime::parse(f[0], f[1], f[2]).expect("parses");
        assert_eq!(back.pockets, 0);
    }
}
