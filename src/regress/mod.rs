//! Regression checks on `summary.json` files: flattening to dotted keys, per-key
//! tolerances, comparison against a reference with a table of what moved, and the hard
//! suite's checks (issue 7), and an adaptive run's levels as a table. Pure Rust, no PETSc;
//! used by the `ehl-summary` tool that `ci/regress` and `ci/hard` call.
pub mod hard;
pub mod levels;

use crate::error::Error;
use serde_json::Value;
use std::collections::BTreeMap;

/// A leaf of a summary: number, string or boolean (null stands for NaN/inf in JSON).
#[derive(Debug, Clone, PartialEq)]
pub enum Leaf {
    Num(f64),
    Text(String),
    Bool(bool),
    Null,
}

impl std::fmt::Display for Leaf {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Leaf::Num(v) => write!(f, "{v:.10e}"),
            Leaf::Text(s) => write!(
                f,
                "\"{}\"",
                if s.chars().count() > 40 { format!("{}...", s.chars().take(40).collect::<String>()) } else { s.clone() }
            ),
            Leaf::Bool(b) => write!(f, "{b}"),
            Leaf::Null => write!(f, "null"),
        }
    }
}

/// Flattens a JSON document into dotted keys (`film.hc_m`, `solver.path[0]`).
pub fn flatten(v: &Value) -> BTreeMap<String, Leaf> {
    fn walk(prefix: &str, v: &Value, out: &mut BTreeMap<String, Leaf>) {
        match v {
            Value::Object(m) => {
                for (k, x) in m {
                    walk(&if prefix.is_empty() { k.clone() } else { format!("{prefix}.{k}") }, x, out);
                }
            }
            Value::Array(a) => {
                for (i, x) in a.iter().enumerate() {
                    walk(&format!("{prefix}[{i}]"), x, out);
                }
            }
            Value::Number(n) => {
                out.insert(prefix.to_string(), Leaf::Num(n.as_f64().unwrap_or(f64::NAN)));
            }
            Value::String(s) => {
                out.insert(prefix.to_string(), Leaf::Text(s.clone()));
            }
            Value::Bool(b) => {
                out.insert(prefix.to_string(), Leaf::Bool(*b));
            }
            Value::Null => {
                out.insert(prefix.to_string(), Leaf::Null);
            }
        }
    }
    let mut out = BTreeMap::new();
    walk("", v, &mut out);
    out
}

/// How one key is compared.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Tolerance {
    /// Not compared (timings, memory, rank count).
    Ignore,
    /// Numbers pass when |new - ref| <= max(abs, rel * max(|ref|, |new|)); other leaves
    /// must be equal.
    Within { rel: f64, abs: f64 },
}

impl std::fmt::Display for Tolerance {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Tolerance::Ignore => write!(f, "ignored"),
            Tolerance::Within { rel, abs } if *abs == 0.0 => write!(f, "rel {rel:.0e}"),
            Tolerance::Within { rel, abs } => write!(f, "rel {rel:.0e}, abs {abs:.0e}"),
        }
    }
}

/// Per-key tolerances: a default and glob patterns (`*` matches any run of characters);
/// an exact key wins, then the longest matching pattern.
#[derive(Debug, Clone)]
pub struct Tolerances {
    pub default: Tolerance,
    pub rules: Vec<(String, Tolerance)>,
}

impl Tolerances {
    /// Everything relative `rel`, nothing ignored.
    pub fn uniform(rel: f64) -> Self {
        Tolerances { default: Tolerance::Within { rel, abs: 0.0 }, rules: Vec::new() }
    }

    /// Parses the TOML tolerance file:
    /// ```toml
    /// default = 1e-6
    /// [keys]
    /// "timing.*" = "ignore"
    /// "fz" = { rel = 1e-6, abs = 1e-12 }
    /// ```
    pub fn parse(text: &str) -> Result<Self, Error> {
        let t: toml::Table = toml::from_str(text).map_err(|e| Error::invalid(format!("tolerance file: {e}")))?;
        let default = match t.get("default") {
            None => Tolerance::Within { rel: 1e-6, abs: 0.0 },
            Some(v) => parse_tolerance("default", v)?,
        };
        let mut rules = Vec::new();
        for (k, v) in t.iter() {
            match k.as_str() {
                "default" => {}
                "keys" => {
                    let keys = v.as_table().ok_or_else(|| Error::invalid("tolerance file: [keys] must be a table"))?;
                    for (pat, tv) in keys {
                        rules.push((pat.clone(), parse_tolerance(pat, tv)?));
                    }
                }
                other => return Err(Error::invalid(format!("tolerance file: unknown key '{other}' (allowed: default, [keys])"))),
            }
        }
        Ok(Tolerances { default, rules })
    }

    /// The tolerance that applies to `key`.
    pub fn for_key(&self, key: &str) -> Tolerance {
        if let Some((_, t)) = self.rules.iter().find(|(p, _)| p == key) {
            return *t;
        }
        self.rules.iter().filter(|(p, _)| glob(p, key)).max_by_key(|(p, _)| p.len()).map(|(_, t)| *t).unwrap_or(self.default)
    }

    /// Same rules with every relative tolerance replaced by `rel` (ignored keys and
    /// absolute floors kept): the rank-invariance comparison.
    pub fn with_rel(&self, rel: f64) -> Self {
        let set = |t: Tolerance| match t {
            Tolerance::Ignore => Tolerance::Ignore,
            Tolerance::Within { abs, .. } => Tolerance::Within { rel, abs },
        };
        Tolerances { default: set(self.default), rules: self.rules.iter().map(|(p, t)| (p.clone(), set(*t))).collect() }
    }
}

fn parse_tolerance(key: &str, v: &toml::Value) -> Result<Tolerance, Error> {
    let bad = || {
        Error::invalid(format!(
            "tolerance file: '{key}' = {v}: expected a relative tolerance (number >= 0), \"ignore\" or {{ rel = .., abs = .. }}"
        ))
    };
    let num = |x: &toml::Value| x.as_float().or_else(|| x.as_integer().map(|i| i as f64)).filter(|f| *f >= 0.0);
    match v {
        toml::Value::String(s) if s == "ignore" => Ok(Tolerance::Ignore),
        toml::Value::Table(t) => {
            if t.keys().any(|k| k != "rel" && k != "abs") {
                return Err(bad());
            }
            let rel = t.get("rel").map(|x| num(x).ok_or_else(bad)).transpose()?.unwrap_or(0.0);
            let abs = t.get("abs").map(|x| num(x).ok_or_else(bad)).transpose()?.unwrap_or(0.0);
            Ok(Tolerance::Within { rel, abs })
        }
        x => num(x).map(|rel| Tolerance::Within { rel, abs: 0.0 }).ok_or_else(bad),
    }
}

/// Glob match with `*` as the only wildcard.
fn glob(pattern: &str, s: &str) -> bool {
    let parts: Vec<&str> = pattern.split('*').collect();
    if parts.len() == 1 {
        return pattern == s;
    }
    let (first, last) = (parts[0], parts[parts.len() - 1]);
    if !s.starts_with(first) || s.len() < first.len() + last.len() || !s.ends_with(last) {
        return false;
    }
    let mut rest = &s[first.len()..s.len() - last.len()];
    for mid in &parts[1..parts.len() - 1] {
        match rest.find(mid) {
            Some(i) => rest = &rest[i + mid.len()..],
            None => return false,
        }
    }
    true
}

/// Outcome of one key.
#[derive(Debug, Clone, PartialEq)]
pub enum Status {
    /// Moved, within tolerance.
    Moved,
    /// Moved beyond tolerance (or a string/boolean changed).
    Drift,
    /// In the reference, not in the new summary.
    Missing,
    /// In the new summary only (reported, not a failure: refresh the reference to keep it).
    Added,
}

/// One row of the comparison table: a key whose value differs.
#[derive(Debug, Clone)]
pub struct Row {
    pub key: String,
    pub reference: Option<Leaf>,
    pub new: Option<Leaf>,
    /// |new - ref| / max(|ref|, |new|) for numbers.
    pub rel_change: Option<f64>,
    pub tolerance: Tolerance,
    pub status: Status,
}

/// The comparison of two summaries.
#[derive(Debug, Clone)]
pub struct Comparison {
    pub compared: usize,
    pub ignored: usize,
    pub rows: Vec<Row>,
}

impl Comparison {
    /// Keys that drifted or went missing.
    pub fn failures(&self) -> usize {
        self.rows.iter().filter(|r| matches!(r.status, Status::Drift | Status::Missing)).count()
    }

    /// Markdown-style table of what moved, and a one-line verdict.
    pub fn table(&self) -> String {
        let mut s = String::new();
        if !self.rows.is_empty() {
            s.push_str("| key | reference | new | rel. change | tolerance | status |\n|---|---|---|---|---|---|\n");
            for r in &self.rows {
                let show = |l: &Option<Leaf>| l.as_ref().map(|v| v.to_string()).unwrap_or_else(|| "-".into());
                let status = match r.status {
                    Status::Moved => "ok",
                    Status::Drift => "DRIFT",
                    Status::Missing => "MISSING",
                    Status::Added => "added",
                };
                s.push_str(&format!(
                    "| {} | {} | {} | {} | {} | {} |\n",
                    r.key,
                    show(&r.reference),
                    show(&r.new),
                    r.rel_change.map(|c| format!("{c:.2e}")).unwrap_or_else(|| "-".into()),
                    r.tolerance,
                    status
                ));
            }
        }
        let moved = self.rows.iter().filter(|r| r.status == Status::Moved).count();
        let added = self.rows.iter().filter(|r| r.status == Status::Added).count();
        s.push_str(&format!(
            "{} keys compared ({} ignored): {} unchanged, {} moved within tolerance, {} drifted or missing{}\n",
            self.compared,
            self.ignored,
            self.compared - moved - self.failures().min(self.compared),
            moved,
            self.failures(),
            if added > 0 { format!(", {added} new (not in the reference)") } else { String::new() }
        ));
        s
    }
}

/// Compares `new` with `reference` key by key.
pub fn compare(reference: &Value, new: &Value, tol: &Tolerances) -> Comparison {
    let (a, b) = (flatten(reference), flatten(new));
    let (mut compared, mut ignored, mut rows) = (0, 0, Vec::new());
    for (key, ra) in &a {
        let t = tol.for_key(key);
        if t == Tolerance::Ignore {
            ignored += 1;
            continue;
        }
        compared += 1;
        let Some(nb) = b.get(key) else {
            rows.push(Row {
                key: key.clone(),
                reference: Some(ra.clone()),
                new: None,
                rel_change: None,
                tolerance: t,
                status: Status::Missing,
            });
            continue;
        };
        if ra == nb {
            continue;
        }
        let (rel_change, ok) = match (ra, nb, t) {
            (Leaf::Num(x), Leaf::Num(y), Tolerance::Within { rel, abs }) => {
                let d = (x - y).abs();
                let scale = x.abs().max(y.abs());
                (Some(if scale > 0.0 { d / scale } else { 0.0 }), d <= abs.max(rel * scale))
            }
            _ => (None, false),
        };
        rows.push(Row {
            key: key.clone(),
            reference: Some(ra.clone()),
            new: Some(nb.clone()),
            rel_change,
            tolerance: t,
            status: if ok { Status::Moved } else { Status::Drift },
        });
    }
    for (key, nb) in &b {
        if !a.contains_key(key) && tol.for_key(key) != Tolerance::Ignore {
            rows.push(Row {
                key: key.clone(),
                reference: None,
                new: Some(nb.clone()),
                rel_change: None,
                tolerance: tol.for_key(key),
                status: Status::Added,
            });
        }
    }
    Comparison { compared, ignored, rows }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn tol() -> Tolerances {
        Tolerances::parse(
            r#"
default = 1e-6
[keys]
"timing.*" = "ignore"
"film.hm_*_m" = { abs = 1e-5 }
"fz" = { rel = 1e-6, abs = 1e-12 }
"#,
        )
        .unwrap()
    }

    #[test]
    fn flatten_names_nested_keys_and_array_items() {
        let f = flatten(&json!({"film": {"hc_m": 1.0}, "solver": {"path": ["a", "b"]}, "ok": true, "x": null}));
        assert_eq!(f["film.hc_m"], Leaf::Num(1.0));
        assert_eq!(f["solver.path[1]"], Leaf::Text("b".into()));
        assert_eq!(f["ok"], Leaf::Bool(true));
        assert_eq!(f["x"], Leaf::Null);
    }

    #[test]
    fn rules_pick_exact_then_longest_pattern() {
        let t = tol();
        assert_eq!(t.for_key("timing.total_s"), Tolerance::Ignore);
        assert_eq!(t.for_key("film.hm_x_m"), Tolerance::Within { rel: 0.0, abs: 1e-5 });
        assert_eq!(t.for_key("film.hc_m"), Tolerance::Within { rel: 1e-6, abs: 0.0 });
        assert!(glob("a*b*c", "axxbyyc") && !glob("a*b*c", "axxc") && glob("*_m", "film.hc_m"));
    }

    #[test]
    fn unchanged_passes_and_drift_beyond_tolerance_fails() {
        let r = json!({"film": {"hc_m": 3.8e-7, "hm_x_m": 1.0e-4}, "timing": {"total_s": 20.0}, "fz": 0.0, "reason": "CONVERGED"});
        let same = compare(&r, &r, &tol());
        assert_eq!((same.failures(), same.rows.len()), (0, 0));
        // Within tolerance: moved, reported, not a failure; timing ignored.
        let n = json!({"film": {"hc_m": 3.8e-7 * (1.0 + 5e-7), "hm_x_m": 1.05e-4}, "timing": {"total_s": 99.0}, "fz": 1e-13, "reason": "CONVERGED"});
        let c = compare(&r, &n, &tol());
        assert_eq!(c.failures(), 0, "{}", c.table());
        assert_eq!(c.rows.len(), 3);
        // Beyond: 2e-6 relative on hc, a changed string, a missing key.
        let d = json!({"film": {"hc_m": 3.8e-7 * (1.0 + 2e-6), "hm_x_m": 1.0e-4}, "fz": 0.0, "reason": "DIVERGED"});
        let c = compare(&r, &d, &tol());
        assert_eq!(c.failures(), 2, "{}", c.table());
        assert!(c.table().contains("| film.hc_m |") && c.table().contains("DRIFT"));
        let m = json!({"film": {"hc_m": 3.8e-7, "hm_x_m": 1.0e-4}, "fz": 0.0});
        assert_eq!(compare(&r, &m, &tol()).failures(), 1);
    }

    #[test]
    fn bad_tolerance_file_names_the_key() {
        let e = Tolerances::parse("[keys]\n\"film.*\" = -1\n").unwrap_err().to_string();
        assert!(e.contains("film.*"), "{e}");
        assert!(Tolerances::parse("defualt = 1e-6\n").unwrap_err().to_string().contains("defualt"));
    }

    #[test]
    fn with_rel_keeps_ignores_and_floors() {
        let t = tol().with_rel(1e-3);
        assert_eq!(t.for_key("timing.x"), Tolerance::Ignore);
        assert_eq!(t.for_key("fz"), Tolerance::Within { rel: 1e-3, abs: 1e-12 });
    }
}
