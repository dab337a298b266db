//! The schema description used for strict validation: every key of the scene file with its
//! meaning, unit, type, allowed range and default. The lists live next to the structs in
//! [`super::schema`]; a test checks they match the structs.
//!
//! Validation walks the parsed `toml::Table` against these lists before serde sees it, so
//! unknown keys, missing fields, wrong types and out-of-range numbers all get a message
//! naming the dotted key.
use toml::{Table, Value};

use super::error::SceneErrorKind;

/// Allowed values of a number.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Range {
    /// v > 0
    Positive,
    /// v >= 0
    NonNegative,
    /// lo < v < hi
    Open(f64, f64),
    /// lo < v <= hi
    LeftOpen(f64, f64),
    /// lo <= v <= hi
    Closed(f64, f64),
    /// |v| <= m
    AbsAtMost(f64),
    /// v <= m
    AtMost(f64),
    /// v >= m
    AtLeast(f64),
    /// any finite number
    Any,
}

impl Range {
    /// Whether the (finite) value is allowed.
    pub fn contains(&self, v: f64) -> bool {
        match *self {
            Range::Positive => v > 0.0,
            Range::NonNegative => v >= 0.0,
            Range::Open(lo, hi) => v > lo && v < hi,
            Range::LeftOpen(lo, hi) => v > lo && v <= hi,
            Range::Closed(lo, hi) => v >= lo && v <= hi,
            Range::AbsAtMost(m) => v.abs() <= m,
            Range::AtMost(m) => v <= m,
            Range::AtLeast(m) => v >= m,
            Range::Any => true,
        }
    }

    /// Short text such as `> 0` or `in (-1, 0.5)`.
    pub fn describe(&self) -> String {
        match *self {
            Range::Positive => "> 0".into(),
            Range::NonNegative => ">= 0".into(),
            Range::Open(lo, hi) => format!("in ({}, {})", fmt_num(lo), fmt_num(hi)),
            Range::LeftOpen(lo, hi) => format!("in ({}, {}]", fmt_num(lo), fmt_num(hi)),
            Range::Closed(lo, hi) => format!("in [{}, {}]", fmt_num(lo), fmt_num(hi)),
            Range::AbsAtMost(m) => format!("with absolute value <= {}", fmt_num(m)),
            Range::AtMost(m) => format!("<= {}", fmt_num(m)),
            Range::AtLeast(m) => format!(">= {}", fmt_num(m)),
            Range::Any => "any finite number".into(),
        }
    }
}

/// The TOML type (and constraint) of a key.
#[derive(Debug, Clone, Copy)]
pub enum Kind {
    /// A finite number (integer or float) in the range.
    Number(Range),
    /// A non-empty array of finite numbers, each in the range (a sweep).
    NumberList(Range),
    /// true or false.
    Bool,
    /// A non-empty string.
    Text,
    /// One of the listed strings.
    Choice(&'static [&'static str]),
    /// An array (possibly empty) of distinct strings, each one of the listed ones.
    ChoiceList(&'static [&'static str]),
    /// A sub-table with its own keys.
    Table(&'static [Field]),
}

/// Whether a key must be present.
#[derive(Debug, Clone, Copy)]
pub enum Presence {
    /// Always required.
    Required,
    /// Optional; the text gives the default.
    Default(&'static str),
    /// Required under a condition checked after parsing; the text states it.
    Conditional(&'static str),
}

/// One key of the scene file.
#[derive(Debug, Clone, Copy)]
pub struct Field {
    /// The TOML key.
    pub key: &'static str,
    /// What it is, with the paper symbol, e.g. `ball radius R_B`.
    pub what: &'static str,
    /// SI unit ("" for dimensionless or non-numeric keys).
    pub unit: &'static str,
    /// Type and constraint.
    pub kind: Kind,
    /// Required or default.
    pub presence: Presence,
    /// Extra explanation appended to a range violation ("" if none).
    pub note: &'static str,
}

impl Field {
    /// Short description: meaning, unit and allowed values,
    /// e.g. `ball radius R_B in m, > 0`.
    pub fn description(&self) -> String {
        match self.kind {
            Kind::Number(r) if self.unit.is_empty() => format!("{}, {}", self.what, r.describe()),
            Kind::Number(r) => format!("{} in {}, {}", self.what, self.unit, r.describe()),
            Kind::NumberList(r) if self.unit.is_empty() => format!("{}, each {}", self.what, r.describe()),
            Kind::NumberList(r) => format!("{} in {}, each {}", self.what, self.unit, r.describe()),
            Kind::Bool => format!("{}, true or false", self.what),
            Kind::Text => self.what.to_string(),
            Kind::Choice(c) => format!("{}: one of {}", self.what, quoted_list(c)),
            Kind::ChoiceList(c) => format!("{}: an array of {}", self.what, quoted_list(c)),
            Kind::Table(_) => self.what.to_string(),
        }
    }

    /// Description plus the presence condition, for missing-field messages.
    pub fn description_with_condition(&self) -> String {
        match self.presence {
            Presence::Conditional(c) => format!("{}; {}", self.description(), c),
            _ => self.description(),
        }
    }

    fn expected(&self) -> String {
        let t = match self.kind {
            Kind::Number(_) => "a number",
            Kind::NumberList(_) => "a non-empty array of numbers",
            Kind::Bool => "a boolean",
            Kind::Text | Kind::Choice(_) => "a string",
            Kind::ChoiceList(_) => "an array of strings",
            Kind::Table(_) => "a table",
        };
        format!("{t} ({})", self.description())
    }
}

/// Formats a number compactly: `0.5`, `90`, `2.1e11`, `2.3e-8`.
pub fn fmt_num(v: f64) -> String {
    let a = v.abs();
    if v != 0.0 && a.is_finite() && !(1e-3..1e6).contains(&a) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

fn quoted_list(c: &[&str]) -> String {
    c.iter().map(|s| format!("\"{s}\"")).collect::<Vec<_>>().join(", ")
}

fn join(prefix: &str, key: &str) -> String {
    if prefix.is_empty() {
        key.to_string()
    } else {
        format!("{prefix}.{key}")
    }
}

fn describe_value(v: &Value) -> String {
    match v {
        Value::String(s) => format!("the string \"{s}\""),
        Value::Integer(i) => format!("the integer {i}"),
        Value::Float(x) => format!("the number {}", fmt_num(*x)),
        Value::Boolean(b) => format!("the boolean {b}"),
        Value::Datetime(d) => format!("the date {d}"),
        Value::Array(_) => "an array".into(),
        Value::Table(_) => "a table".into(),
    }
}

/// Levenshtein edit distance.
pub fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for i in 1..=a.len() {
        let mut cur = vec![i; b.len() + 1];
        for j in 1..=b.len() {
            let sub = prev[j - 1] + usize::from(a[i - 1] != b[j - 1]);
            cur[j] = sub.min(prev[j] + 1).min(cur[j - 1] + 1);
        }
        prev = cur;
    }
    prev[b.len()]
}

/// The closest candidate within a tolerance that grows with the key length.
pub fn closest<'a>(key: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let tol = (key.chars().count() / 3).max(2);
    candidates
        .into_iter()
        .map(|c| (edit_distance(&key.to_lowercase(), c), c))
        .filter(|&(d, c)| d <= tol && d < c.len())
        .min_by_key(|&(d, _)| d)
        .map(|(_, c)| c)
}

/// Every dotted path of the schema whose last key is `key` (to suggest a key written in
/// the wrong section).
fn find_elsewhere(root: &'static [Field], key: &str, prefix: &str, out: &mut Vec<String>) {
    for f in root {
        let p = join(prefix, f.key);
        if f.key == key {
            out.push(p.clone());
        }
        if let Kind::Table(sub) = f.kind {
            find_elsewhere(sub, key, &p, out);
        }
    }
}

/// Looks a field up by dotted path.
pub fn lookup(root: &'static [Field], path: &str) -> Option<&'static Field> {
    let mut fields = root;
    let mut found = None;
    for part in path.split('.') {
        let f = fields.iter().find(|f| f.key == part)?;
        found = Some(f);
        fields = match f.kind {
            Kind::Table(sub) => sub,
            _ => &[],
        };
    }
    found
}

/// Walks `table` against `fields`: unknown keys, wrong types, non-finite or out-of-range
/// numbers, unknown choices, empty strings and missing required keys.
pub fn check_table(root: &'static [Field], table: &Table, fields: &'static [Field], prefix: &str) -> Result<(), SceneErrorKind> {
    for (key, value) in table {
        let path = join(prefix, key);
        let Some(field) = fields.iter().find(|f| f.key == key.as_str()) else {
            let suggestion = closest(key, fields.iter().map(|f| f.key)).map(str::to_string).or_else(|| {
                let mut elsewhere = Vec::new();
                find_elsewhere(root, key, "", &mut elsewhere);
                (elsewhere.len() == 1).then(|| elsewhere.remove(0))
            });
            return Err(SceneErrorKind::UnknownKey { path, suggestion, known: fields.iter().map(|f| f.key).collect() });
        };
        check_value(root, field, value, &path)?;
    }
    for f in fields {
        if matches!(f.presence, Presence::Required) && !table.contains_key(f.key) {
            let path = join(prefix, f.key);
            let description = f.description();
            return Err(match f.kind {
                Kind::Table(_) => SceneErrorKind::MissingSection { path, description },
                _ => SceneErrorKind::MissingField { path, description },
            });
        }
    }
    Ok(())
}

fn check_value(root: &'static [Field], field: &Field, value: &Value, path: &str) -> Result<(), SceneErrorKind> {
    let wrong = || SceneErrorKind::WrongType { path: path.to_string(), expected: field.expected(), found: describe_value(value) };
    let not_allowed = |shown: String, allowed: String| SceneErrorKind::NotAllowed { path: path.to_string(), value: shown, allowed };
    match field.kind {
        Kind::Number(range) => check_number(field, range, value, path)?,
        Kind::NumberList(range) => match value {
            Value::Array(items) if items.is_empty() => return Err(not_allowed("[]".into(), "must be a non-empty array of numbers".into())),
            Value::Array(items) => {
                for (i, item) in items.iter().enumerate() {
                    check_number(field, range, item, &format!("{path}[{i}]"))?;
                }
            }
            _ => return Err(wrong()),
        },
        Kind::Bool => {
            if !value.is_bool() {
                return Err(wrong());
            }
        }
        Kind::Text => match value {
            Value::String(s) if s.trim().is_empty() => return Err(not_allowed(format!("\"{s}\""), "must be a non-empty string".into())),
            Value::String(_) => {}
            _ => return Err(wrong()),
        },
        Kind::Choice(choices) => match value {
            Value::String(s) if choices.contains(&s.as_str()) => {}
            Value::String(s) => {
                let hint = closest(s, choices.iter().copied()).map(|c| format!(" (did you mean \"{c}\"?)")).unwrap_or_default();
                return Err(not_allowed(format!("\"{s}\""), format!("must be one of {}{hint}", quoted_list(choices))));
            }
            _ => return Err(wrong()),
        },
        Kind::ChoiceList(choices) => match value {
            Value::Array(items) => {
                for (i, item) in items.iter().enumerate() {
                    let p = format!("{path}[{i}]");
                    match item {
                        Value::String(s) if choices.contains(&s.as_str()) => {
                            if items[..i].contains(item) {
                                return Err(SceneErrorKind::NotAllowed {
                                    path: p,
                                    value: format!("\"{s}\""),
                                    allowed: "is listed twice".into(),
                                });
                            }
                        }
                        Value::String(s) => {
                            let hint = closest(s, choices.iter().copied()).map(|c| format!(" (did you mean \"{c}\"?)")).unwrap_or_default();
                            return Err(SceneErrorKind::NotAllowed {
                                path: p,
                                value: format!("\"{s}\""),
                                allowed: format!("must be one of {}{hint}", quoted_list(choices)),
                            });
                        }
                        _ => return Err(SceneErrorKind::WrongType { path: p, expected: field.expected(), found: describe_value(item) }),
                    }
                }
            }
            _ => return Err(wrong()),
        },
        Kind::Table(sub) => match value {
            Value::Table(t) => check_table(root, t, sub, path)?,
            _ => return Err(wrong()),
        },
    }
    Ok(())
}

/// One number of `field` (also an element of a list, whose `path` carries the index).
fn check_number(field: &Field, range: Range, value: &Value, path: &str) -> Result<(), SceneErrorKind> {
    let (v, shown) = match value {
        Value::Integer(i) => (*i as f64, i.to_string()),
        Value::Float(x) => (*x, fmt_num(*x)),
        _ => return Err(SceneErrorKind::WrongType { path: path.to_string(), expected: field.expected(), found: describe_value(value) }),
    };
    let not_allowed = |allowed: String| SceneErrorKind::NotAllowed { path: path.to_string(), value: shown.clone(), allowed };
    if !v.is_finite() {
        return Err(not_allowed("must be a finite number".into()));
    }
    if !range.contains(v) {
        let unit = if field.unit.is_empty() { String::new() } else { format!(" ({})", field.unit) };
        let note = if field.note.is_empty() { String::new() } else { format!("; {}", field.note) };
        return Err(not_allowed(format!("must be {}{unit}{note}", range.describe())));
    }
    Ok(())
}

/// A Markdown reference of the schema (one heading and table per section), the body of
/// docs/scene-reference.md.
pub fn reference_markdown(root: &'static [Field]) -> String {
    let mut out = String::new();
    write_section(&mut out, root, "", "scene name and sections", "");
    out
}

fn write_section(out: &mut String, fields: &'static [Field], prefix: &str, what: &str, presence: &str) {
    let title = if prefix.is_empty() { "top level".to_string() } else { format!("[{prefix}]") };
    out.push_str(&format!("## {title}\n\n{what}{presence}.\n\n"));
    let leaves: Vec<&Field> = fields.iter().filter(|f| !matches!(f.kind, Kind::Table(_))).collect();
    if !leaves.is_empty() {
        out.push_str("| key | meaning | unit | allowed | default |\n|---|---|---|---|---|\n");
        for f in leaves {
            let allowed = match f.kind {
                Kind::Number(r) => r.describe(),
                Kind::NumberList(r) => format!("array, each {}", r.describe()),
                Kind::Bool => "true, false".into(),
                Kind::Text => "non-empty string".into(),
                Kind::Choice(c) => quoted_list(c),
                Kind::ChoiceList(c) => format!("array of {}", quoted_list(c)),
                Kind::Table(_) => unreachable!(),
            };
            let note = if f.note.is_empty() { String::new() } else { format!(" ({})", f.note) };
            let unit = if f.unit.is_empty() { "-" } else { f.unit };
            out.push_str(&format!(
                "| `{}` | {} | {} | {} | {} |\n",
                f.key,
                table_cell(&format!("{}{note}", f.what)),
                table_cell(unit),
                table_cell(&allowed),
                table_cell(&presence_text(f.presence))
            ));
        }
        out.push('\n');
    }
    for f in fields {
        if let Kind::Table(sub) = f.kind {
            let presence = match f.presence {
                Presence::Default(d) => format!(" (optional; default {d})"),
                p => format!(" ({})", presence_text(p)),
            };
            write_section(out, sub, &join(prefix, f.key), f.what, &presence);
        }
    }
}

/// Text for a Markdown table cell: a bare `|` (as in |X| <= w) would end the cell.
fn table_cell(text: &str) -> String {
    text.replace('|', "\\|")
}

fn presence_text(p: Presence) -> String {
    match p {
        Presence::Required => "required".to_string(),
        Presence::Default(d) => format!("default {d}"),
        Presence::Conditional(c) => c.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edit_distance_basics() {
        assert_eq!(edit_distance("lod", "load"), 1);
        assert_eq!(edit_distance("kitten", "sitting"), 3);
        assert_eq!(edit_distance("", "abc"), 3);
        assert_eq!(closest("lod", ["load", "entrainment_speed"]), Some("load"));
        assert_eq!(closest("ball_raduis", ["ball_radius", "disc_track_radius"]), Some("ball_radius"));
        assert_eq!(closest("zzzzzz", ["load", "tilt_angle"]), None);
    }

    #[test]
    fn number_formatting() {
        assert_eq!(fmt_num(0.5), "0.5");
        assert_eq!(fmt_num(-1.0), "-1");
        assert_eq!(fmt_num(90.0), "90");
        assert_eq!(fmt_num(2.1e11), "2.1e11");
        assert_eq!(fmt_num(23e-9), "2.3e-8");
        assert_eq!(fmt_num(0.0), "0");
        assert_eq!(Range::Open(-1.0, 0.5).describe(), "in (-1, 0.5)");
        assert_eq!(Range::LeftOpen(0.0, 90.0).describe(), "in (0, 90]");
    }
}
