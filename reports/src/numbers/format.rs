//! How a number from a results file is written into a report: an optional reduction over the
//! values a pointer selects (`sum`, `mean`, `min`, `max`, `count`, `maxabs` the largest
//! magnitude, `rms` the root mean square), an optional scale (`*K` or
//! `/K`) and a format.
//!
//! | format | writes | example (value 0.012345) |
//! |---|---|---|
//! | `.Nf` | fixed, N decimals | `.3f`: `0.012` |
//! | `.N%` | times 100, N decimals, `%` | `.2%`: `1.23%` |
//! | `.Ne` | scientific, N decimals | `.1e`: `1.2e-2` |
//! | `Ng` | N significant digits, no exponent | `2g`: `0.012` |
//! | `d` | rounded integer | `d`: `0` |
//! | `d_` | rounded integer, thousands grouped by spaces | 11774: `11 774` |
//! | `mmss` | seconds as minutes and seconds | 222: `3 min 42 s` |
//! | `s` | a string or true/false as it stands; a number in its shortest form | |

use serde_json::Value;

/// A reduction of the values a pointer selects to one number.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reduce {
    /// Their sum.
    Sum,
    /// Their mean.
    Mean,
    /// The smallest.
    Min,
    /// The largest.
    Max,
    /// How many there are.
    Count,
    /// The largest magnitude, max |x|.
    MaxAbs,
    /// The root mean square, sqrt(sum x^2 / n).
    Rms,
}

impl Reduce {
    /// The reduction named `word`, if it names one.
    pub fn parse(word: &str) -> Option<Self> {
        Some(match word {
            "sum" => Self::Sum,
            "mean" => Self::Mean,
            "min" => Self::Min,
            "max" => Self::Max,
            "count" => Self::Count,
            "maxabs" => Self::MaxAbs,
            "rms" => Self::Rms,
            _ => return None,
        })
    }

    /// The reduction of `values` (each a number, except for `count`).
    pub fn apply(self, values: &[&Value]) -> Result<Value, String> {
        if self == Self::Count {
            return Ok(Value::from(values.len()));
        }
        let xs = values
            .iter()
            .map(|v| v.as_f64().ok_or_else(|| format!("{v} is not a number")))
            .collect::<Result<Vec<f64>, String>>()?;
        if xs.is_empty() {
            return Err("the pointer selects no values".into());
        }
        let x = match self {
            Self::Sum => xs.iter().sum(),
            Self::Mean => xs.iter().sum::<f64>() / xs.len() as f64,
            Self::Min => xs.iter().copied().fold(f64::INFINITY, f64::min),
            Self::Max => xs.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            Self::MaxAbs => xs.iter().fold(0.0, |m: f64, x| m.max(x.abs())),
            Self::Rms => (xs.iter().map(|x| x * x).sum::<f64>() / xs.len() as f64).sqrt(),
            Self::Count => unreachable!("handled above"),
        };
        Ok(number(x))
    }
}

fn number(x: f64) -> Value {
    serde_json::Number::from_f64(x).map_or(Value::Null, Value::Number)
}

/// How a value is written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// `.Nf`.
    Fixed(usize),
    /// `.N%`.
    Percent(usize),
    /// `.Ne`.
    Scientific(usize),
    /// `Ng`.
    Significant(usize),
    /// `d`.
    Integer,
    /// `d_`.
    Grouped,
    /// `mmss`.
    MinutesSeconds,
    /// `s`.
    AsIs,
}

impl Format {
    /// The format `word` names, if it names one.
    pub fn parse(word: &str) -> Option<Self> {
        let digits = |s: &str| s.parse::<usize>().ok().filter(|n| *n <= 17);
        Some(match word {
            "d" => Self::Integer,
            "d_" => Self::Grouped,
            "mmss" => Self::MinutesSeconds,
            "s" => Self::AsIs,
            _ => {
                if let Some(n) = word.strip_prefix('.').and_then(|w| w.strip_suffix('f')) {
                    Self::Fixed(digits(n)?)
                } else if let Some(n) = word.strip_prefix('.').and_then(|w| w.strip_suffix('%')) {
                    Self::Percent(digits(n)?)
                } else if let Some(n) = word.strip_prefix('.').and_then(|w| w.strip_suffix('e')) {
                    Self::Scientific(digits(n)?)
                } else if let Some(n) = word.strip_suffix('g') {
                    Self::Significant(digits(n).filter(|n| *n >= 1)?)
                } else {
                    return None;
                }
            }
        })
    }

    /// `value` written in this format.
    pub fn write(self, value: &Value) -> Result<String, String> {
        if self == Self::AsIs {
            return Ok(match value {
                Value::String(s) => s.clone(),
                other => other.to_string(),
            });
        }
        let x = value
            .as_f64()
            .ok_or_else(|| format!("{value} is not a number (use the format `s`)"))?;
        if !x.is_finite() {
            return Err(format!("{x} is not finite"));
        }
        Ok(match self {
            Self::Fixed(n) => format!("{x:.n$}"),
            Self::Percent(n) => format!("{:.n$}%", 100.0 * x),
            Self::Scientific(n) => format!("{x:.n$e}"),
            Self::Significant(n) => significant(x, n),
            Self::Integer => format!("{}", x.round() as i64),
            Self::Grouped => grouped(x.round() as i64),
            Self::MinutesSeconds => {
                let s = x.round() as i64;
                if s < 60 {
                    format!("{s} s")
                } else {
                    format!("{} min {} s", s / 60, s % 60)
                }
            }
            Self::AsIs => unreachable!("handled above"),
        })
    }
}

/// `x` to `n` significant digits in positional notation (`significant(0.012345, 2)` = `0.012`,
/// `significant(39313.0, 2)` = `39000`).
pub fn significant(x: f64, n: usize) -> String {
    if x == 0.0 {
        return "0".into();
    }
    let magnitude = x.abs().log10().floor() as i64;
    let decimals = (n as i64 - 1 - magnitude).max(0) as usize;
    if decimals > 0 {
        format!("{x:.decimals$}")
    } else {
        let unit = 10f64.powi((magnitude + 1 - n as i64) as i32);
        format!("{}", ((x / unit).round() * unit) as i64)
    }
}

/// `n` with its thousands grouped by spaces (`11 774`, `-1 234 567`).
pub fn grouped(n: i64) -> String {
    let digits = n.unsigned_abs().to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(' ');
        }
        out.push(c);
    }
    if n < 0 { format!("-{out}") } else { out }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn w(f: &str, v: Value) -> String {
        Format::parse(f).unwrap().write(&v).unwrap()
    }

    #[test]
    fn formats() {
        assert_eq!(w(".3f", json!(0.012345)), "0.012");
        assert_eq!(w(".2%", json!(0.012345)), "1.23%");
        assert_eq!(w(".1e", json!(8.3e-15)), "8.3e-15");
        assert_eq!(w("2g", json!(0.012345)), "0.012");
        assert_eq!(w("2g", json!(39313.0)), "39000");
        assert_eq!(w("3g", json!(563.4)), "563");
        assert_eq!(w("d", json!(51.6)), "52");
        assert_eq!(w("d_", json!(11774)), "11 774");
        assert_eq!(w("d_", json!(-1234567)), "-1 234 567");
        assert_eq!(w("d_", json!(774)), "774");
        assert_eq!(w("mmss", json!(222.4)), "3 min 42 s");
        assert_eq!(w("mmss", json!(42)), "42 s");
        assert_eq!(w("s", json!("b-rz")), "b-rz");
        assert_eq!(w("s", json!(true)), "true");
    }

    #[test]
    fn words_that_name_no_format_are_refused() {
        for word in ["f", ".f", ".3x", "0g", "x", ".99f", ""] {
            assert!(Format::parse(word).is_none(), "{word}");
        }
        assert!(Format::parse(".2f").unwrap().write(&json!("a")).is_err());
        assert!(Format::parse(".2f").unwrap().write(&Value::Null).is_err());
    }

    #[test]
    fn reductions() {
        let v = [json!(1.0), json!(2.0), json!(6.0)];
        let r: Vec<&Value> = v.iter().collect();
        assert_eq!(Reduce::Sum.apply(&r).unwrap(), json!(9.0));
        assert_eq!(Reduce::Mean.apply(&r).unwrap(), json!(3.0));
        assert_eq!(Reduce::Min.apply(&r).unwrap(), json!(1.0));
        assert_eq!(Reduce::Max.apply(&r).unwrap(), json!(6.0));
        assert_eq!(Reduce::Count.apply(&r).unwrap(), json!(3));
        let w = [json!(-4.0), json!(3.0)];
        let q: Vec<&Value> = w.iter().collect();
        assert_eq!(Reduce::MaxAbs.apply(&q).unwrap(), json!(4.0));
        assert_eq!(
            Reduce::Rms.apply(&q).unwrap(),
            json!((25.0_f64 / 2.0).sqrt())
        );
        assert!(Reduce::Sum.apply(&[]).is_err());
        assert!(Reduce::Sum.apply(&[&json!("a")]).is_err());
    }
}
