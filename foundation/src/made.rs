//! What made a results file (issue 63: "each results file records the date, the program version
//! and a solver/physics revision"): one record, written under the key [`MADE_KEY`] of every
//! results file, so that a report can tell whether the results it quotes are older than the
//! solver it describes.
//!
//! The date is the UTC calendar date of the run, or of `SOURCE_DATE_EPOCH` where that is set
//! (the reproducible-builds convention: a run that must write byte-identical files sets it).

use std::time::{SystemTime, UNIX_EPOCH};

use serde::{Deserialize, Serialize};

/// The key under which a results file carries its [`Made`].
pub const MADE_KEY: &str = "made";

/// The program, version, date and physics revision of a run.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Made {
    /// The program's name (`hpge-cv`).
    pub program: String,
    /// The program's version (the workspace's version).
    pub version: String,
    /// The UTC date of the run, `YYYY-MM-DD`.
    pub date: String,
    /// The solver's physics revision (`hpge_solver::field::PHYSICS_REVISION`) of a run whose
    /// numbers depend on the solver; None for one that does not (a measurement of pulse files).
    pub solver_revision: Option<String>,
}

impl Made {
    /// This run, today, with the given solver revision.
    pub fn now(solver_revision: Option<&str>) -> Self {
        Self {
            program: "hpge-cv".into(),
            version: env!("CARGO_PKG_VERSION").into(),
            date: today_utc(),
            solver_revision: solver_revision.map(str::to_string),
        }
    }

    /// This record as a JSON value (for results files written as `serde_json::Value`).
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::to_value(self).expect("a record of strings serialises")
    }
}

/// Today's UTC date as `YYYY-MM-DD` (`SOURCE_DATE_EPOCH`, seconds since 1970, where set).
pub fn today_utc() -> String {
    let seconds = std::env::var("SOURCE_DATE_EPOCH")
        .ok()
        .and_then(|s| s.trim().parse::<i64>().ok())
        .unwrap_or_else(|| {
            SystemTime::now()
                .duration_since(UNIX_EPOCH)
                .map_or(0, |d| d.as_secs() as i64)
        });
    let (y, m, d) = civil_from_days(seconds.div_euclid(86_400));
    format!("{y:04}-{m:02}-{d:02}")
}

/// The proleptic Gregorian date (year, month, day) of `days` since 1970-01-01: the era-based
/// conversion of H. Hinnant, "chrono-Compatible Low-Level Date Algorithms" (2013): an era is
/// 400 years = 146 097 days, a year counted from 1 March so that the leap day comes last.
pub fn civil_from_days(days: i64) -> (i64, u32, u32) {
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097); // day of era, 0..=146096
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365; // year of era, 0..=399
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100); // day of year from 1 March, 0..=365
    let mp = (5 * doy + 2) / 153; // month from March, 0..=11
    let d = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let m = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    let y = yoe + era * 400 + i64::from(m <= 2);
    (y, m, d)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_dates() {
        assert_eq!(civil_from_days(0), (1970, 1, 1));
        assert_eq!(civil_from_days(-1), (1969, 12, 31));
        // 2000-02-29 (a leap day of a century divisible by 400) is day 11 016.
        assert_eq!(civil_from_days(11_016), (2000, 2, 29));
        assert_eq!(civil_from_days(11_017), (2000, 3, 1));
        // 2026-12-07 is 1 796 601 600 s after the epoch.
        assert_eq!(civil_from_days(1_796_601_600 / 86_400), (2026, 12, 7));
        // 2100 is no leap year: 28 February is followed by 1 March.
        let feb28 = 47_540;
        assert_eq!(civil_from_days(feb28), (2100, 2, 28));
        assert_eq!(civil_from_days(feb28 + 1), (2100, 3, 1));
    }

    #[test]
    fn every_day_follows_the_last() {
        // Day by day over 1900-2200: the date advances by one day, months and years roll over.
        let mut last = civil_from_days(-25_567);
        assert_eq!(last, (1900, 1, 1));
        for day in -25_566..84_000 {
            let (y, m, d) = civil_from_days(day);
            let next_day = (y, m, d) == (last.0, last.1, last.2 + 1);
            let next_month =
                d == 1 && ((y, m) == (last.0, last.1 + 1) || (m == 1 && y == last.0 + 1));
            assert!(next_day || next_month, "{last:?} -> {:?}", (y, m, d));
            last = (y, m, d);
        }
    }

    #[test]
    fn the_record_names_the_program_and_the_revision() {
        let made = Made::now(Some("r"));
        assert_eq!(made.program, "hpge-cv");
        assert_eq!(made.date.len(), 10);
        assert_eq!(made.to_json()["solver_revision"], "r");
    }
}
