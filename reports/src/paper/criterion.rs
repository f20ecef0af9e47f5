//! How `report paper` judges a figure against the paper's statement: each verdict is derived
//! from numeric criteria printed beside it ([`Criterion`]: a quantity of this run, a comparison
//! and a limit), never written by hand. A row agrees when every criterion holds; a row that
//! differs names the criteria that failed and, where the numbers of the run say why, the
//! reading of the failure.

use serde_json::{Value, json};

/// A comparison of a criterion.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Cmp {
    /// value < limit.
    Lt,
    /// value <= limit.
    Le,
    /// value > limit.
    Gt,
    /// value >= limit.
    Ge,
    /// value == limit (counts and yes/no flags, 1 yes and 0 no).
    Eq,
}

impl Cmp {
    /// The operator as printed and in report.json.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Lt => "<",
            Self::Le => "<=",
            Self::Gt => ">",
            Self::Ge => ">=",
            Self::Eq => "==",
        }
    }

    /// Parses [`Cmp::as_str`]'s text.
    pub fn parse(s: &str) -> Option<Self> {
        Some(match s {
            "<" => Self::Lt,
            "<=" => Self::Le,
            ">" => Self::Gt,
            ">=" => Self::Ge,
            "==" => Self::Eq,
            _ => return None,
        })
    }

    /// Whether `value` compares to `limit` so; a NaN never does.
    pub fn holds(self, value: f64, limit: f64) -> bool {
        match self {
            Self::Lt => value < limit,
            Self::Le => value <= limit,
            Self::Gt => value > limit,
            Self::Ge => value >= limit,
            Self::Eq => value == limit,
        }
    }
}

/// One numeric test: `quantity` (its unit in the name) of this run is `value`, which should be
/// `op` `limit`.
#[derive(Debug, Clone, PartialEq)]
pub struct Criterion {
    /// What is compared, with its unit.
    pub quantity: String,
    /// This run's value (NaN where it could not be computed: the criterion fails).
    pub value: f64,
    /// The comparison.
    pub op: Cmp,
    /// The limit.
    pub limit: f64,
}

impl Criterion {
    /// `quantity` = `value`, which should be `op` `limit`.
    pub fn new(quantity: impl Into<String>, value: f64, op: Cmp, limit: f64) -> Self {
        Self {
            quantity: quantity.into(),
            value,
            op,
            limit,
        }
    }

    /// A yes/no fact: `quantity` (1 yes, 0 no) should be `want`.
    pub fn flag(quantity: impl Into<String>, value: bool, want: bool) -> Self {
        Self::new(
            format!("{} (1 yes, 0 no)", quantity.into()),
            f64::from(u8::from(value)),
            Cmp::Eq,
            f64::from(u8::from(want)),
        )
    }

    /// Whether it holds.
    pub fn holds(&self) -> bool {
        self.op.holds(self.value, self.limit)
    }

    /// "quantity = value (op limit: yes|no)".
    pub fn text(&self) -> String {
        format!(
            "{} = {} ({} {}: {})",
            self.quantity,
            short(self.value),
            self.op.as_str(),
            short(self.limit),
            if self.holds() { "yes" } else { "no" }
        )
    }

    /// The criterion in report.json.
    pub fn json(&self) -> Value {
        json!({
            "quantity": self.quantity,
            "value": if self.value.is_finite() { json!(self.value) } else { Value::Null },
            "op": self.op.as_str(),
            "limit": self.limit,
            "holds": self.holds(),
        })
    }
}

/// A number in four significant digits (integers as integers).
fn short(v: f64) -> String {
    if !v.is_finite() {
        "NaN".into()
    } else if v == v.round() && v.abs() < 1e6 {
        format!("{v:.0}")
    } else if v != 0.0 && (v.abs() < 1e-3 || v.abs() >= 1e5) {
        format!("{v:.3e}")
    } else {
        format!("{}", (v * 1e4).round() / 1e4)
    }
}

/// A row's verdict.
#[derive(Debug, Clone, PartialEq)]
pub enum Judgement {
    /// Judged by criteria: agrees when every one holds. `reading` says why where one fails
    /// (derived from the run's numbers; empty for none).
    Criteria {
        /// The criteria.
        criteria: Vec<Criterion>,
        /// The reading of a failure.
        reading: String,
    },
    /// A figure with no numeric statement to test, shown for reference (why).
    Shown(String),
    /// Not made in this run (why).
    NotRun(String),
}

impl Judgement {
    /// Judged by `criteria`; `reading` is printed where one fails.
    pub fn by(criteria: Vec<Criterion>, reading: impl Into<String>) -> Self {
        Self::Criteria {
            criteria,
            reading: reading.into(),
        }
    }

    /// Some(true) when every criterion holds, Some(false) when one fails, None for a row
    /// without criteria.
    pub fn agrees(&self) -> Option<bool> {
        match self {
            Self::Criteria { criteria, .. } => Some(criteria.iter().all(Criterion::holds)),
            _ => None,
        }
    }

    /// The criteria (none for a shown or not-run row).
    pub fn criteria(&self) -> &[Criterion] {
        match self {
            Self::Criteria { criteria, .. } => criteria,
            _ => &[],
        }
    }

    /// "agrees", "differs (the failed criteria; the reading)", "shown (why)" or "not run (why)".
    pub fn verdict(&self) -> String {
        match self {
            Self::Criteria { criteria, reading } => {
                if criteria.iter().all(Criterion::holds) {
                    "agrees".into()
                } else {
                    let failed: Vec<&str> = criteria
                        .iter()
                        .filter(|c| !c.holds())
                        .map(|c| c.quantity.as_str())
                        .collect();
                    let mut v = format!("differs (fails: {}", failed.join("; "));
                    if !reading.is_empty() {
                        v.push_str(". ");
                        v.push_str(reading);
                    }
                    v.push(')');
                    v
                }
            }
            Self::Shown(why) => format!("shown ({why})"),
            Self::NotRun(why) => format!("not run ({why})"),
        }
    }

    /// The criteria as one line (empty for none).
    pub fn criteria_text(&self) -> String {
        self.criteria()
            .iter()
            .map(Criterion::text)
            .collect::<Vec<_>>()
            .join("; ")
    }
}

/// The rows of a `report.json` whose verdict does not follow from its own criteria, each as a
/// line naming the figure and the fault (empty: every verdict is derived): a criterion's
/// `holds` that its value, operator and limit contradict, `agrees` other than "every criterion
/// holds", a verdict text other than `agrees` / `differs` to match, or a row without criteria
/// that claims either.
pub fn inconsistent_rows(report: &Value) -> Vec<String> {
    let mut faults = Vec::new();
    let rows = report["rows"].as_array().cloned().unwrap_or_default();
    if rows.is_empty() {
        faults.push("report.json has no rows".into());
    }
    for r in &rows {
        let fig = r["figure"].as_str().unwrap_or("?");
        let verdict = r["verdict"].as_str().unwrap_or("");
        let criteria = r["criteria"].as_array().cloned().unwrap_or_default();
        let mut all = true;
        for c in &criteria {
            let value = c["value"].as_f64().unwrap_or(f64::NAN);
            let limit = c["limit"].as_f64().unwrap_or(f64::NAN);
            let Some(op) = c["op"].as_str().and_then(Cmp::parse) else {
                faults.push(format!("{fig}: a criterion without a known operator: {c}"));
                continue;
            };
            let holds = op.holds(value, limit);
            all &= holds;
            if c["holds"].as_bool() != Some(holds) {
                faults.push(format!(
                    "{fig}: {} says holds = {}, its numbers say {holds}",
                    c["quantity"], c["holds"]
                ));
            }
        }
        match (criteria.is_empty(), r["agrees"].as_bool()) {
            (true, None) => {
                if !(verdict.starts_with("shown") || verdict.starts_with("not run")) {
                    faults.push(format!(
                        "{fig}: no criteria, but the verdict is `{verdict}`"
                    ));
                }
            }
            (true, Some(_)) => faults.push(format!("{fig}: agrees/differs without a criterion")),
            (false, agrees) => {
                if agrees != Some(all) {
                    faults.push(format!(
                        "{fig}: agrees = {agrees:?}, its criteria say {all}"
                    ));
                }
                let want = if all { "agrees" } else { "differs" };
                if !verdict.starts_with(want) {
                    faults.push(format!(
                        "{fig}: the verdict `{verdict}` where the criteria say {want}"
                    ));
                }
            }
        }
    }
    faults
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_row_agrees_only_when_every_criterion_holds() {
        let ok = Criterion::new("a (pF)", 1.0, Cmp::Lt, 2.0);
        let bad = Criterion::new("b (V)", 3.0, Cmp::Le, 2.0);
        let j = Judgement::by(vec![ok.clone()], "never printed");
        assert_eq!(j.agrees(), Some(true));
        assert_eq!(j.verdict(), "agrees");
        let j = Judgement::by(vec![ok, bad], "b is too large");
        assert_eq!(j.agrees(), Some(false));
        assert_eq!(j.verdict(), "differs (fails: b (V). b is too large)");
        assert!(j.criteria_text().contains("b (V) = 3 (<= 2: no)"));
    }

    #[test]
    fn nan_fails_every_comparison_and_flags_compare_as_numbers() {
        for op in [Cmp::Lt, Cmp::Le, Cmp::Gt, Cmp::Ge, Cmp::Eq] {
            assert!(!Criterion::new("x", f64::NAN, op, 1.0).holds());
            assert_eq!(Cmp::parse(op.as_str()), Some(op));
        }
        assert!(Criterion::flag("depleted", false, false).holds());
        assert!(!Criterion::flag("depleted", true, false).holds());
        assert_eq!(
            Judgement::NotRun("--quick".into()).agrees(),
            None,
            "a row that was not run neither agrees nor differs"
        );
    }

    #[test]
    fn a_verdict_that_contradicts_its_criteria_is_found() {
        let good = json!({"rows": [{"figure": "f", "verdict": "differs (fails: a)", "agrees": false,
            "criteria": [{"quantity": "a", "value": 3.0, "op": "<", "limit": 1.0, "holds": false}]}]});
        assert!(
            inconsistent_rows(&good).is_empty(),
            "{:?}",
            inconsistent_rows(&good)
        );
        let said_agrees = json!({"rows": [{"figure": "f", "verdict": "agrees", "agrees": true,
            "criteria": [{"quantity": "a", "value": 3.0, "op": "<", "limit": 1.0, "holds": true}]}]});
        assert_eq!(inconsistent_rows(&said_agrees).len(), 3);
        let bare =
            json!({"rows": [{"figure": "f", "verdict": "agrees", "agrees": null, "criteria": []}]});
        assert_eq!(inconsistent_rows(&bare).len(), 1);
    }
}
