//! The markers that tie a number in a markdown report to its results file.
//!
//! ```text
//! <!-- n-from reports/fits/b-rz/summary.json -->      the file of the markers below it
//! chi^2 <!-- n /chi2 .1f -->39313.4<!-- /n --> for <!-- n /ndf d -->51<!-- /n --> degrees
//! <!-- n reports/fits/b-z/summary.json /refinement/*/seconds sum /60 .1f -->3.7<!-- /n --> min
//! ```
//!
//! A marker's words, after `n`: the results file (relative to the repository root; left out, the
//! last `n-from` file; a `.jsonl` file reads as the array of its lines, a `.csv` file as the
//! array of its rows keyed by the header), a JSON pointer (RFC 6901, with three additions: a `*`
//! segment selects every element or member, a `key=value` segment selects the elements of an
//! array whose `key` is `value`, and `~s` stands for a space), then in any order at most one reduction, one scale and one format
//! ([`super::format`]). The text between the marker and `<!-- /n -->` is the number as written;
//! `report numbers --write` replaces it, the test fails where it differs.

use std::ops::Range;

use serde_json::Value;

use super::format::{Format, Reduce};

/// The opening of a number's marker.
pub const OPEN: &str = "<!-- n ";
/// The marker that sets the file of the markers after it.
pub const FROM: &str = "<!-- n-from ";
/// The closing of a number.
pub const CLOSE: &str = "<!-- /n -->";

/// One number of a report.
#[derive(Debug, Clone, PartialEq)]
pub struct Marker {
    /// The line of the marker (from 1).
    pub line: usize,
    /// The marker's words as written (for messages).
    pub words: String,
    /// The results file, relative to the repository root.
    pub file: String,
    /// The pointer into it.
    pub pointer: String,
    /// The reduction of the values it selects.
    pub reduce: Option<Reduce>,
    /// The factor the value is multiplied by.
    pub scale: f64,
    /// How it is written.
    pub format: Format,
    /// The bytes of the number as the report writes it.
    pub text: Range<usize>,
}

/// The byte ranges of the fenced code blocks of markdown `text` (from a line starting with
/// three backticks to the next such line): markers there are examples, not numbers.
fn fenced_blocks(text: &str) -> Vec<Range<usize>> {
    let mut out = Vec::new();
    let (mut open, mut at) = (None, 0);
    for line in text.split_inclusive('\n') {
        if line.trim_start().starts_with("```") {
            match open.take() {
                Some(start) => out.push(start..at + line.len()),
                None => open = Some(at),
            }
        }
        at += line.len();
    }
    if let Some(start) = open {
        out.push(start..text.len());
    }
    out
}

/// Every marker of `text`, in order (those inside fenced code blocks are examples and left
/// out); an error names the line and what is wrong with it.
pub fn markers(text: &str) -> Result<Vec<Marker>, String> {
    let line_of = |at: usize| text[..at].matches('\n').count() + 1;
    let fences = fenced_blocks(text);
    let mut out = Vec::new();
    let mut from: Option<String> = None;
    let mut at = 0;
    while let Some(k) = next_marker(&text[at..]) {
        let start = at + k;
        if let Some(f) = fences.iter().find(|f| f.contains(&start)) {
            at = f.end;
            continue;
        }
        let line = line_of(start);
        let end = text[start..]
            .find("-->")
            .map(|e| start + e)
            .ok_or_else(|| format!("line {line}: a marker without its closing `-->`"))?;
        if text[start..].starts_with(FROM) {
            let words: Vec<&str> = text[start + FROM.len()..end].split_whitespace().collect();
            match words.as_slice() {
                [file] if !file.starts_with('/') => from = Some((*file).to_string()),
                _ => return Err(format!("line {line}: `n-from` takes one file")),
            }
            at = end + 3;
            continue;
        }
        let words_text = text[start + OPEN.len()..end].trim().to_string();
        let body = end + 3;
        let close = text[body..]
            .find(CLOSE)
            .map(|c| body + c)
            .ok_or_else(|| format!("line {line}: `{words_text}` has no closing `{CLOSE}`"))?;
        let number = &text[body..close];
        if number.contains('\n') || number.contains("<!--") {
            return Err(format!(
                "line {line}: `{words_text}`: its closing `{CLOSE}` is not on the same line"
            ));
        }
        let mut marker = parse_words(&words_text, from.as_deref())
            .map_err(|e| format!("line {line}: `{words_text}`: {e}"))?;
        marker.line = line;
        marker.text = body..close;
        out.push(marker);
        at = close + CLOSE.len();
    }
    Ok(out)
}

fn next_marker(s: &str) -> Option<usize> {
    match (s.find(OPEN), s.find(FROM)) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}

const WORDS: &str = "a reduction (sum, mean, min, max, count), a scale (*K, /K) or a format (.Nf, .N%, .Ne, Ng, d, d_, mmss, s)";

fn parse_words(words_text: &str, from: Option<&str>) -> Result<Marker, String> {
    let mut words = words_text.split_whitespace().peekable();
    let file = match words.peek() {
        Some(w) if w.starts_with('/') => from
            .ok_or("no results file: name one before the pointer or above with `n-from`")?
            .to_string(),
        Some(w) => {
            let f = (*w).to_string();
            words.next();
            f
        }
        None => return Err("no results file and no pointer".into()),
    };
    let pointer = match words.next() {
        Some(p) if p.starts_with('/') => p.to_string(),
        _ => return Err("no JSON pointer (it starts with `/`)".into()),
    };
    let (mut reduce, mut scale, mut format) = (None, None, None);
    for w in words {
        let as_scale = w
            .strip_prefix('*')
            .map(|k| (k, false))
            .or_else(|| w.strip_prefix('/').map(|k| (k, true)))
            .and_then(|(k, divide)| k.parse::<f64>().ok().map(|k| (k, divide)))
            .filter(|(k, _)| k.is_finite() && *k != 0.0);
        let slot_taken = |taken: bool| {
            if taken {
                Err(format!("`{w}`: a second one of its kind"))
            } else {
                Ok(())
            }
        };
        if let Some(r) = Reduce::parse(w) {
            slot_taken(reduce.is_some())?;
            reduce = Some(r);
        } else if let Some((k, divide)) = as_scale {
            slot_taken(scale.is_some())?;
            scale = Some(if divide { 1.0 / k } else { k });
        } else if let Some(f) = Format::parse(w) {
            slot_taken(format.is_some())?;
            format = Some(f);
        } else {
            return Err(format!("`{w}` is neither {WORDS}"));
        }
    }
    Ok(Marker {
        line: 0,
        words: words_text.to_string(),
        file,
        pointer,
        reduce,
        scale: scale.unwrap_or(1.0),
        format: format.unwrap_or(Format::AsIs),
        text: 0..0,
    })
}

/// The values `pointer` selects in `v` (RFC 6901 with `*` and `key=value` segments, and `~s`
/// for a space, which a marker's words cannot hold).
pub fn select<'a>(v: &'a Value, pointer: &str) -> Vec<&'a Value> {
    let mut current = vec![v];
    for raw in pointer.split('/').skip(1) {
        let seg = raw.replace("~1", "/").replace("~s", " ").replace("~0", "~");
        let mut next = Vec::new();
        for c in current {
            match c {
                Value::Array(items) if seg == "*" => next.extend(items.iter()),
                Value::Object(m) if seg == "*" => next.extend(m.values()),
                Value::Array(items) => {
                    if let Some((key, want)) = seg.split_once('=') {
                        next.extend(items.iter().filter(|x| match x.get(key) {
                            Some(Value::String(s)) => s == want,
                            Some(Value::Number(n)) => want.parse::<f64>().ok() == n.as_f64(),
                            Some(Value::Bool(b)) => want.parse::<bool>().ok() == Some(*b),
                            _ => false,
                        }));
                    } else if let Some(x) = seg.parse::<usize>().ok().and_then(|i| items.get(i)) {
                        next.push(x);
                    }
                }
                Value::Object(m) => next.extend(m.get(&seg)),
                _ => {}
            }
        }
        current = next;
    }
    current
}

/// The number `m` stands for in the results file's JSON `v`, written.
pub fn value_of(m: &Marker, v: &Value) -> Result<String, String> {
    let found = select(v, &m.pointer);
    let value = match (m.reduce, found.as_slice()) {
        (Some(r), vals) => r.apply(vals)?,
        (None, [one]) => (*one).clone(),
        (None, []) => return Err(format!("{}: nothing at {}", m.file, m.pointer)),
        (None, many) => {
            return Err(format!(
                "{}: {} selects {} values; name a reduction",
                m.file,
                m.pointer,
                many.len()
            ));
        }
    };
    let value = if m.scale == 1.0 {
        value
    } else {
        let x = value
            .as_f64()
            .ok_or_else(|| format!("{}: {} is not a number to scale", m.file, m.pointer))?;
        serde_json::Number::from_f64(x * m.scale).map_or(Value::Null, Value::Number)
    };
    m.format
        .write(&value)
        .map_err(|e| format!("{}: {}: {e}", m.file, m.pointer))
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn markers_with_and_without_a_file() {
        let t = "# T\n<!-- n-from a.json -->\nchi2 <!-- n /chi2 .1f -->3.0<!-- /n --> and \
                 <!-- n b.json /r/*/s sum /60 .1f -->1<!-- /n -->\n";
        let m = markers(t).unwrap();
        assert_eq!(m.len(), 2);
        assert_eq!(
            (m[0].file.as_str(), m[0].pointer.as_str(), m[0].line),
            ("a.json", "/chi2", 3)
        );
        assert_eq!(&t[m[0].text.clone()], "3.0");
        assert_eq!(
            (m[1].file.as_str(), m[1].reduce),
            ("b.json", Some(Reduce::Sum))
        );
        assert!((m[1].scale - 1.0 / 60.0).abs() < 1e-15);
        let v = json!({"r": [{"s": 60.0}, {"s": 120.0}]});
        assert_eq!(value_of(&m[1], &v).unwrap(), "3.0");
    }

    #[test]
    fn markers_in_code_blocks_are_examples() {
        let t =
            "```text\n<!-- n /x .1f -->1<!-- /n -->\n```\nok <!-- n a.json /y d -->2<!-- /n -->\n";
        let m = markers(t).unwrap();
        assert_eq!((m.len(), m[0].pointer.as_str(), m[0].line), (1, "/y", 4));
        assert!(markers("```\n<!-- n /x").unwrap().is_empty());
    }

    #[test]
    fn bad_markers_name_their_line() {
        for (t, want) in [
            (
                "\n<!-- n /x .1f -->1<!-- /n -->",
                "line 2: `/x .1f`: no results file",
            ),
            ("<!-- n a.json x -->1<!-- /n -->", "no JSON pointer"),
            ("<!-- n a.json /x .1q -->1<!-- /n -->", "`.1q` is neither"),
            ("<!-- n a.json /x .1f .2f -->1<!-- /n -->", "a second one"),
            ("<!-- n a.json /x -->1", "has no closing"),
            ("<!-- n a.json /x -->1\n<!-- /n -->", "not on the same line"),
            ("<!-- n a.json /x ", "without its closing"),
        ] {
            let e = markers(t).unwrap_err();
            assert!(e.contains(want), "{t:?}: {e}");
        }
    }

    #[test]
    fn selections() {
        let v = json!({"p": [{"name": "a", "x": 1}, {"name": "b", "x": 2}], "m": {"k/l": 3, "a b": 4, "~s": 5}});
        assert_eq!(select(&v, "/p/name=b/x"), [&json!(2)]);
        assert_eq!(select(&v, "/p/*/x").len(), 2);
        assert_eq!(select(&v, "/p/1/name"), [&json!("b")]);
        assert_eq!(select(&v, "/m/k~1l"), [&json!(3)]);
        assert_eq!(select(&v, "/m/a~sb"), [&json!(4)]);
        assert_eq!(select(&v, "/m/~0s"), [&json!(5)]);
        assert!(select(&v, "/q").is_empty());
        let m = markers("<!-- n f.json /p/*/x .1f -->1<!-- /n -->").unwrap();
        assert!(
            value_of(&m[0], &v)
                .unwrap_err()
                .contains("selects 2 values")
        );
        let m = markers("<!-- n f.json /q -->1<!-- /n -->").unwrap();
        assert!(value_of(&m[0], &v).unwrap_err().contains("nothing at /q"));
    }
}
