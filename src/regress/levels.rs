//! An adaptive run's levels as a Markdown table (`ehl-summary levels`): what each level
//! solved, what it cost and what it gave, from summary.json's `accuracy` object.
use crate::error::Error;
use serde_json::Value;

/// The table of `summary`'s `accuracy.levels`, then the run's verdict, its estimated
/// errors and pmax's last change. An error when the summary has no levels (a run on one
/// mesh).
pub fn levels_table(summary: &Value) -> Result<String, Error> {
    let acc = &summary["accuracy"];
    let levels = acc["levels"].as_array().filter(|l| !l.is_empty()).ok_or_else(|| {
        Error::invalid("the summary has no accuracy.levels: it is not from an adaptive run (a scene with accuracy.target)")
    })?;
    let num = |v: &Value, k: &str| v[k].as_f64();
    let fmt = |v: Option<f64>, f: &dyn Fn(f64) -> String| v.map_or("".to_string(), f);
    let mut t = String::from(
        "| level | smallest (a) | unknowns | Newton its | seconds (failed) | peak/rank (MB) | hc (um) | hm (um) | pmax (GPa) | estimate hc, hm (fx, fz) | note |\n\
         |---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for l in levels {
        let unknowns = num(l, "elastic_unknowns").zip(num(l, "pressure_unknowns")).map(|(e, p)| e + p + 1.0);
        let failed = num(l, "failed_attempts_seconds").filter(|&s| s > 0.0);
        let seconds = fmt(num(l, "seconds"), &|s| match failed {
            Some(f) => format!("{s:.1} ({f:.1})"),
            None => format!("{s:.1}"),
        });
        let mut note = Vec::new();
        if let Some(j) = l["complementarity_on_the_mesh_of_level"].as_u64() {
            note.push(format!("level {j}'s mesh as complementarity"));
        }
        if let (Some(share), Some(by)) = (num(l, "budget_share"), l["cut_by"].as_str()) {
            note.push(format!("cut to {:.0} % of its marking by {by}", 100.0 * share));
        }
        t.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
            l["level"],
            fmt(num(l, "smallest_size_a"), &|v| format!("{v:.4}")),
            fmt(unknowns, &|v| format!("{v:.0}")),
            l["newton_iterations"],
            seconds,
            fmt(num(l, "peak_memory_per_rank_mb"), &|v| format!("{v:.0}")),
            fmt(num(l, "hc_m"), &|v| format!("{:.6}", v * 1e6)),
            fmt(num(l, "hm_m"), &|v| format!("{:.6}", v * 1e6)),
            fmt(num(l, "pmax_pa"), &|v| format!("{:.4}", v * 1e-9)),
            estimates(&l["estimated_error"]),
            note.join("; "),
        ));
    }
    let verdict = match acc["reached"].as_bool() {
        Some(true) => "reached".to_string(),
        // The reason as the run logged it, less its own "accuracy: target T not reached: ".
        _ => {
            let why = acc["not_reached_because"].as_str().unwrap_or("no reason given");
            format!("not reached: {}", why.split_once("not reached: ").map_or(why, |(_, r)| r))
        }
    };
    t.push_str(&format!("\ntarget {}: {verdict}; estimated error {}", acc["target"], estimates(&acc["estimated_error"])));
    if let Some(c) = acc["pmax_last_change"]["relative"].as_f64() {
        t.push_str(&format!("; pmax (not a target) moved by {:+.2} % over the last level", 100.0 * c));
    }
    t.push('\n');
    Ok(t)
}

/// "hc %, hm % (fx %, fz %)" of an `estimated_error` object; empty without one.
fn estimates(e: &Value) -> String {
    let pct = |k: &str| e[k].as_f64().map(|v| format!("{:.2} %", 100.0 * v));
    let Some((hc, hm)) = pct("hc").zip(pct("hm")) else { return String::new() };
    let friction: Vec<String> = ["fx", "fz"].iter().filter_map(|k| pct(k)).collect();
    if friction.is_empty() {
        format!("{hc}, {hm}")
    } else {
        format!("{hc}, {hm} ({})", friction.join(", "))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn the_levels_of_an_adaptive_run_read_as_a_table() {
        let s = json!({ "accuracy": {
            "target": 0.01, "reached": true,
            "estimated_error": { "hc": 0.002, "hm": 0.0081 },
            "pmax_last_change": { "relative": 0.0034 },
            "levels": [
                { "level": 0, "smallest_size_a": 0.25, "elastic_unknowns": 34000, "pressure_unknowns": 1691,
                  "newton_iterations": 14, "seconds": 2.4, "failed_attempts_seconds": 0.0, "peak_memory_per_rank_mb": 300.0,
                  "hc_m": 3.8e-7, "hm_m": 1.45e-7, "pmax_pa": 8.5e8 },
                { "level": 1, "smallest_size_a": 0.125, "elastic_unknowns": 40000, "pressure_unknowns": 3105,
                  "newton_iterations": 9, "seconds": 6.0, "failed_attempts_seconds": 1.5, "peak_memory_per_rank_mb": 420.0,
                  "hc_m": 3.6365e-7, "hm_m": 1.3798e-7, "pmax_pa": 8.47e8,
                  "estimated_error": { "hc": 0.002, "hm": 0.0081, "fx": 0.001, "fz": 0.0074 },
                  "budget_share": 0.94, "cut_by": "-ehl_memory_per_rank", "complementarity_on_the_mesh_of_level": 0 }
            ] } });
        let t = levels_table(&s).unwrap();
        let lines: Vec<&str> = t.lines().collect();
        assert_eq!(lines[2], "| 0 | 0.2500 | 35692 | 14 | 2.4 | 300 | 0.380000 | 0.145000 | 0.8500 |  |  |");
        assert_eq!(
            lines[3],
            "| 1 | 0.1250 | 43106 | 9 | 6.0 (1.5) | 420 | 0.363650 | 0.137980 | 0.8470 | 0.20 %, 0.81 % (0.10 %, 0.74 %) | level 0's mesh as complementarity; cut to 94 % of its marking by -ehl_memory_per_rank |"
        );
        assert_eq!(
            lines[5],
            "target 0.01: reached; estimated error 0.20 %, 0.81 %; pmax (not a target) moved by +0.34 % over the last level"
        );
        let mut short = s.clone();
        short["accuracy"]["reached"] = json!(false);
        short["accuracy"]["not_reached_because"] = json!("accuracy: target 0.01 not reached: level 2 would have 912478 unknowns");
        let t = levels_table(&short).unwrap();
        assert!(t.contains("\ntarget 0.01: not reached: level 2 would have 912478 unknowns; estimated error"), "{t}");
        let e = levels_table(&json!({ "film": {} })).unwrap_err().to_string();
        assert!(e.contains("not from an adaptive run"), "{e}");
    }
}
