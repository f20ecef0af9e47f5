//! Named parameters and the small arithmetic expressions that geometry entries may use.
//!
//! A length in a detector file is either a number or a string such as `"5.0 + d_li_mm"`. The
//! grammar is: numbers (with optional exponent), parameter names, `+ - * /`, unary minus and
//! parentheses. Evaluation is exact IEEE arithmetic; a non-finite result is an error.
//!
//! The parser recurses once per parenthesis and unary sign, so nesting is bounded
//! ([`MAX_EXPRESSION_DEPTH`]): a deeper expression is an error, not a stack overflow.

use std::collections::BTreeMap;
use std::fmt;

use serde::de::{self, Visitor};
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::error::{Error, Result};

/// Named numeric parameters of a detector (e.g. `d_li_mm = 1.0`), in the units their names say.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Parameters {
    values: BTreeMap<String, f64>,
}

impl Parameters {
    /// An empty parameter set.
    pub fn new() -> Self {
        Self::default()
    }

    /// Sets `name` to `value`, replacing an earlier value.
    pub fn set(&mut self, name: impl Into<String>, value: f64) {
        self.values.insert(name.into(), value);
    }

    /// The value of `name`, if defined.
    pub fn get(&self, name: &str) -> Option<f64> {
        self.values.get(name).copied()
    }

    /// All parameters in name order.
    pub fn iter(&self) -> impl Iterator<Item = (&str, f64)> {
        self.values.iter().map(|(k, v)| (k.as_str(), *v))
    }

    /// Number of parameters.
    pub fn len(&self) -> usize {
        self.values.len()
    }

    /// True when no parameter is defined.
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// Parses `NAME=VALUE` (as given to `--param`); the error is an [`Error::Expression`].
    ///
    /// ```
    /// use hpge_solver::Parameters;
    /// let (name, value) = Parameters::parse_assignment("d_li_mm=2.5")?;
    /// assert_eq!((name.as_str(), value), ("d_li_mm", 2.5));
    /// let mut p = Parameters::new();
    /// p.set(name, value);
    /// assert_eq!(p.get("d_li_mm"), Some(2.5));
    /// assert!(Parameters::parse_assignment("d_li_mm").is_err(), "no value");
    /// assert!(Parameters::parse_assignment("d_li_mm=inf").is_err(), "not finite");
    /// # Ok::<(), hpge_solver::Error>(())
    /// ```
    pub fn parse_assignment(text: &str) -> Result<(String, f64)> {
        parse_assignment(text).map_err(|reason| Error::Expression {
            text: text.to_string(),
            reason,
        })
    }
}

/// [`Parameters::parse_assignment`], the reason of a failure as text.
fn parse_assignment(text: &str) -> Parsed<(String, f64)> {
    let (name, value) = text
        .split_once('=')
        .ok_or_else(|| format!("expected NAME=VALUE, got `{text}`"))?;
    let name = name.trim();
    if !is_identifier(name) {
        return Err(format!("`{name}` is not a valid parameter name"));
    }
    let value: f64 = value
        .trim()
        .parse()
        .map_err(|_| format!("`{}` is not a number", value.trim()))?;
    if !value.is_finite() {
        return Err(format!("the value of `{name}` must be finite"));
    }
    Ok((name.to_string(), value))
}

fn is_identifier(s: &str) -> bool {
    let mut chars = s.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// A number or an expression over [`Parameters`], as written in a detector file.
#[derive(Debug, Clone, PartialEq)]
pub enum Quantity {
    /// A literal number.
    Number(f64),
    /// An expression such as `"5.0 + d_li_mm"`.
    Expr(String),
}

impl Quantity {
    /// Evaluates the quantity; the error ([`Error::Expression`]) says what failed (unknown name,
    /// syntax, non-finite).
    pub fn eval(&self, params: &Parameters) -> Result<f64> {
        let value = match self {
            Quantity::Number(v) => *v,
            Quantity::Expr(text) => eval_expr(text, params)?,
        };
        if value.is_finite() {
            Ok(value)
        } else {
            Err(Error::Expression {
                text: self.to_string(),
                reason: format!("{self} is not a finite number"),
            })
        }
    }
}

impl From<f64> for Quantity {
    fn from(v: f64) -> Self {
        Quantity::Number(v)
    }
}

impl fmt::Display for Quantity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Quantity::Number(v) => write!(f, "{v}"),
            Quantity::Expr(s) => write!(f, "\"{s}\""),
        }
    }
}

impl Serialize for Quantity {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Quantity::Number(v) => s.serialize_f64(*v),
            Quantity::Expr(e) => s.serialize_str(e),
        }
    }
}

impl<'de> Deserialize<'de> for Quantity {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct QuantityVisitor;
        impl Visitor<'_> for QuantityVisitor {
            type Value = Quantity;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("a number or an expression string such as \"5.0 + d_li_mm\"")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Quantity, E> {
                Ok(Quantity::Number(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Quantity, E> {
                Ok(Quantity::Number(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Quantity, E> {
                Ok(Quantity::Number(v as f64))
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Quantity, E> {
                Ok(Quantity::Expr(v.to_string()))
            }
        }
        d.deserialize_any(QuantityVisitor)
    }
}

/// Deepest nesting of parentheses and unary signs an expression may have. The recursive-descent
/// parser takes one stack frame per level (a few hundred bytes); 256 levels are far beyond any
/// written length and far below the 2 MiB stack of a spawned thread, so a hostile expression
/// (200 000 `(`, or `- - - ...`) is refused instead of overflowing the stack (an abort).
pub const MAX_EXPRESSION_DEPTH: usize = 256;

/// Evaluates an arithmetic expression over `params`; the error is an [`Error::Expression`].
pub(crate) fn eval_expr(text: &str, params: &Parameters) -> Result<f64> {
    parse_and_eval(text, params).map_err(|reason| Error::Expression {
        text: text.to_string(),
        reason,
    })
}

/// The parser's own results: the reason of a failure as text, turned into an
/// [`Error::Expression`] by [`eval_expr`].
type Parsed<T> = std::result::Result<T, String>;

fn parse_and_eval(text: &str, params: &Parameters) -> Parsed<f64> {
    let tokens = tokenize(text)?;
    let mut p = ExprParser {
        tokens: &tokens,
        pos: 0,
        depth: 0,
        params,
    };
    let value = p.expr()?;
    if p.pos != tokens.len() {
        return Err(format!("unexpected `{}` in \"{text}\"", tokens[p.pos]));
    }
    Ok(value)
}

#[derive(Debug, Clone, PartialEq)]
enum Token {
    Num(f64),
    Ident(String),
    Op(char),
}

impl fmt::Display for Token {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Token::Num(v) => write!(f, "{v}"),
            Token::Ident(s) => write!(f, "{s}"),
            Token::Op(c) => write!(f, "{c}"),
        }
    }
}

fn tokenize(text: &str) -> Parsed<Vec<Token>> {
    let chars: Vec<char> = text.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        if c.is_whitespace() {
            i += 1;
        } else if "+-*/()".contains(c) {
            out.push(Token::Op(c));
            i += 1;
        } else if c.is_ascii_digit() || c == '.' {
            let start = i;
            while i < chars.len() && (chars[i].is_ascii_digit() || chars[i] == '.') {
                i += 1;
            }
            if i < chars.len() && (chars[i] == 'e' || chars[i] == 'E') {
                let mut j = i + 1;
                if j < chars.len() && (chars[j] == '+' || chars[j] == '-') {
                    j += 1;
                }
                if j < chars.len() && chars[j].is_ascii_digit() {
                    i = j;
                    while i < chars.len() && chars[i].is_ascii_digit() {
                        i += 1;
                    }
                }
            }
            let s: String = chars[start..i].iter().collect();
            let v: f64 = s
                .parse()
                .map_err(|_| format!("`{s}` is not a number in \"{text}\""))?;
            out.push(Token::Num(v));
        } else if c.is_ascii_alphabetic() || c == '_' {
            let start = i;
            while i < chars.len() && (chars[i].is_ascii_alphanumeric() || chars[i] == '_') {
                i += 1;
            }
            out.push(Token::Ident(chars[start..i].iter().collect()));
        } else {
            return Err(format!("unexpected character `{c}` in \"{text}\""));
        }
    }
    if out.is_empty() {
        return Err("empty expression".to_string());
    }
    Ok(out)
}

struct ExprParser<'a> {
    tokens: &'a [Token],
    pos: usize,
    /// Current nesting of parentheses and unary signs (bounded by [`MAX_EXPRESSION_DEPTH`]).
    depth: usize,
    params: &'a Parameters,
}

impl ExprParser<'_> {
    fn peek_op(&self) -> Option<char> {
        match self.tokens.get(self.pos) {
            Some(Token::Op(c)) => Some(*c),
            _ => None,
        }
    }

    fn expr(&mut self) -> Parsed<f64> {
        let mut acc = self.term()?;
        while let Some(op @ ('+' | '-')) = self.peek_op() {
            self.pos += 1;
            let rhs = self.term()?;
            acc = if op == '+' { acc + rhs } else { acc - rhs };
        }
        Ok(acc)
    }

    fn term(&mut self) -> Parsed<f64> {
        let mut acc = self.factor()?;
        while let Some(op @ ('*' | '/')) = self.peek_op() {
            self.pos += 1;
            let rhs = self.factor()?;
            if op == '/' && rhs == 0.0 {
                return Err("division by zero".to_string());
            }
            acc = if op == '*' { acc * rhs } else { acc / rhs };
        }
        Ok(acc)
    }

    /// A factor one nesting level down: refused beyond [`MAX_EXPRESSION_DEPTH`] (the message
    /// does not quote the expression, which may be huge).
    fn nested(&mut self, parse: fn(&mut Self) -> Parsed<f64>) -> Parsed<f64> {
        if self.depth >= MAX_EXPRESSION_DEPTH {
            return Err(format!(
                "nested deeper than {MAX_EXPRESSION_DEPTH} levels of parentheses or unary signs \
                 (the limit that keeps the parser's recursion bounded); write it flatter"
            ));
        }
        self.depth += 1;
        let v = parse(self);
        self.depth -= 1;
        v
    }

    fn factor(&mut self) -> Parsed<f64> {
        match self.tokens.get(self.pos) {
            Some(Token::Op('-')) => {
                self.pos += 1;
                Ok(-self.nested(Self::factor)?)
            }
            Some(Token::Op('+')) => {
                self.pos += 1;
                self.nested(Self::factor)
            }
            Some(Token::Op('(')) => {
                self.pos += 1;
                let v = self.nested(Self::expr)?;
                if self.peek_op() != Some(')') {
                    return Err("missing `)`".to_string());
                }
                self.pos += 1;
                Ok(v)
            }
            Some(Token::Num(v)) => {
                self.pos += 1;
                Ok(*v)
            }
            Some(Token::Ident(name)) => {
                self.pos += 1;
                self.params.get(name).ok_or_else(|| {
                    let known: Vec<&str> = self.params.iter().map(|(k, _)| k).collect();
                    format!(
                        "unknown parameter `{name}` (defined: {})",
                        if known.is_empty() {
                            "none".to_string()
                        } else {
                            known.join(", ")
                        }
                    )
                })
            }
            Some(t) => Err(format!("unexpected `{t}`")),
            None => Err("expression ends too early".to_string()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params() -> Parameters {
        let mut p = Parameters::new();
        p.set("d_li_mm", 1.5);
        p.set("r", 2.0);
        p
    }

    #[test]
    fn arithmetic_and_precedence() {
        let p = params();
        assert_eq!(eval_expr("5.0 + d_li_mm", &p).unwrap(), 6.5);
        assert_eq!(eval_expr("2 + 3 * r", &p).unwrap(), 8.0);
        assert_eq!(eval_expr("(2 + 3) * r", &p).unwrap(), 10.0);
        assert_eq!(eval_expr("-r - -1", &p).unwrap(), -1.0);
        assert_eq!(eval_expr("67 - d_li_mm / 2", &p).unwrap(), 66.25);
        assert_eq!(eval_expr("1e1 + 2.5E-1", &p).unwrap(), 10.25);
    }

    #[test]
    fn nesting_is_bounded_not_a_stack_overflow() {
        let p = params();
        let n = MAX_EXPRESSION_DEPTH;
        // At the limit: fine (parentheses and signs alike).
        let ok = format!("{}1{}", "(".repeat(n), ")".repeat(n));
        assert_eq!(eval_expr(&ok, &p).unwrap(), 1.0);
        assert_eq!(eval_expr(&format!("{}1", "- ".repeat(n)), &p).unwrap(), 1.0);
        // 200 000 deep: an error naming the limit, not an abort.
        for text in [
            format!("{}1{}", "(".repeat(200_000), ")".repeat(200_000)),
            format!("1 {}1", "+ -".repeat(200_000)),
        ] {
            let e = eval_expr(&text, &p).unwrap_err().to_string();
            assert!(e.contains("nested deeper than 256"), "{e}");
            assert!(e.len() < 300, "the message must not quote the expression");
        }
    }

    #[test]
    fn errors_are_explained() {
        let p = params();
        assert!(
            eval_expr("5 + d_li", &p)
                .unwrap_err()
                .to_string()
                .contains("unknown parameter `d_li`")
        );
        assert!(
            eval_expr("5 +", &p)
                .unwrap_err()
                .to_string()
                .contains("ends too early")
        );
        assert!(
            eval_expr("(5", &p)
                .unwrap_err()
                .to_string()
                .contains("missing `)`")
        );
        assert!(
            eval_expr("5 $ 2", &p)
                .unwrap_err()
                .to_string()
                .contains("unexpected character")
        );
        assert!(
            eval_expr("1 / 0", &p)
                .unwrap_err()
                .to_string()
                .contains("division by zero")
        );
        assert!(eval_expr("", &p).unwrap_err().to_string().contains("empty"));
        assert!(
            eval_expr("2 3", &p)
                .unwrap_err()
                .to_string()
                .contains("unexpected `3`")
        );
    }

    #[test]
    fn quantity_rejects_non_finite() {
        let p = params();
        assert!(Quantity::Number(f64::NAN).eval(&p).is_err());
        assert!(Quantity::Number(f64::INFINITY).eval(&p).is_err());
        assert_eq!(Quantity::Expr("r*r".into()).eval(&p).unwrap(), 4.0);
    }

    #[test]
    fn assignments() {
        assert_eq!(
            Parameters::parse_assignment("d_li_mm=3").unwrap(),
            ("d_li_mm".to_string(), 3.0)
        );
        assert!(Parameters::parse_assignment("d_li_mm").is_err());
        assert!(Parameters::parse_assignment("1x=3").is_err());
        assert!(Parameters::parse_assignment("x=abc").is_err());
        assert!(Parameters::parse_assignment("x=nan").is_err());
    }

    mod properties {
        use super::*;
        use proptest::prelude::*;

        proptest! {
            #![proptest_config(ProptestConfig { cases: 256, failure_persistence: None, ..ProptestConfig::default() })]

            /// Printing numbers into an expression and evaluating it is exact IEEE arithmetic.
            #[test]
            fn printed_arithmetic_round_trips(a in -1e6..1e6f64, b in -1e6..1e6f64, c in 0.5..100.0f64) {
                let mut p = Parameters::new();
                p.set("c_mm", c);
                let text = format!("({a:e}) + ({b:e}) * c_mm - -({a:e}) / c_mm");
                prop_assert_eq!(eval_expr(&text, &p).unwrap(), a + b * c - -a / c);
            }
        }
    }
}
