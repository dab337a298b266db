//! The hard suite's checks (`ci/hard`): each case is solved twice and both runs must
//! converge with no NaN, nodal p >= -1e-3 p_H (after the cavitation penalty), h > 0
//! everywhere and a load error below 1e-6. The pair is, by default, the scene at an
//! accuracy target and at a quarter of it: both must reach their targets, and hc, hm may
//! move less than the target between them (the error of the run at the target, measured
//! against a run four times more accurate); so may fx and fz where they are targets, relative
//! to the friction coefficient's magnitude sqrt(fx^2 + fz^2), the scale of their estimates
//! (fz vanishes without spin). A mesh pair (`ci/hard -m plain`) may move hc and hm by less
//! than 2 %.

use serde_json::Value;

/// Most negative nodal pressure allowed, in units of p_H.
pub const PMIN_OVER_PH: f64 = -1e-3;
/// Largest load-balance error allowed.
pub const LOAD_ERROR: f64 = 1e-6;
/// Largest change of hc and hm between the two meshes (relative to the refined mesh).
pub const MESH_CHANGE: f64 = 0.02;

/// One run of a case: its summary (None if it failed), wall time and failure message.
#[derive(Debug, Clone, Default)]
pub struct Run {
    pub summary: Option<Value>,
    pub wall_s: f64,
    pub error: Option<String>,
}

fn num(s: &Value, path: &str) -> Option<f64> {
    let mut v = s;
    for p in path.split('.') {
        v = v.get(p)?;
    }
    v.as_f64()
}

/// Numbers the checks and the table need from one converged run.
#[derive(Debug, Clone, Copy)]
struct Key {
    hc: f64,
    hm: f64,
    pmin_ph: f64,
    load_error: f64,
    its: f64,
    steps: usize,
    /// fx and fz where the run estimated them as targets (`accuracy.estimated_error.fx`).
    friction: Option<[f64; 2]>,
}

fn key_numbers(s: &Value) -> Option<Key> {
    let ph = num(s, "hertz.ph_pa")?;
    Some(Key {
        hc: num(s, "film.hc_m")?,
        hm: num(s, "film.hm_m")?,
        pmin_ph: num(s, "pressure.pmin_nodes_pa")? / ph,
        load_error: num(s, "pressure.load_error_rel")?,
        its: num(s, "solver.newton_iterations")?,
        steps: s.pointer("/solver/path").and_then(|p| p.as_array()).map(|a| a.len().saturating_sub(1)).unwrap_or(0),
        friction: num(s, "accuracy.estimated_error.fx").and_then(|_| Some([num(s, "friction.fx")?, num(s, "friction.fz")?])),
    })
}

/// Result values that are null (NaN or infinite when written; values that may be absent
/// excepted: [`crate::output::summary::null_paths`]).
fn nan_keys(s: &Value) -> Vec<String> {
    crate::output::summary::null_paths(s)
        .into_iter()
        .filter(|k| ["film.", "pressure.", "friction.", "solver."].iter().any(|p| k.starts_with(p)))
        .collect()
}

/// Exit code of `timeout` when it stopped the run (`ci/hard -T`).
pub const TIMEOUT_RC: i32 = 124;

/// Why a run left no summary: the run's error line (`ehl-petsc: error: ...`) if its log has
/// one; else what its exit code `rc` says (124: `ci/hard -T` stopped it; the ranks may be
/// killed inside a factorisation before they print anything).
pub fn failure_reason(log: &str, rc: Option<i32>) -> String {
    if let Some(l) = log.lines().find(|l| l.starts_with("ehl-petsc: error")) {
        return l.trim_start_matches("ehl-petsc: error: ").to_string();
    }
    match rc {
        Some(TIMEOUT_RC) => "stopped by the time limit (ci/hard -T)".into(),
        Some(0) => "exit code 0 but no summary.json".into(),
        Some(c) => format!("no summary.json and no error line (exit code {c})"),
        None => "no summary.json and no error line".into(),
    }
}

/// The first clause of a failure message (the path of continuation steps is in the log).
fn short_reason(e: &str) -> String {
    let first =
        e.split("; path:").next().unwrap_or(e).split("; steps:").next().unwrap_or(e).split("; last domain error").next().unwrap_or(e);
    // Room for the reason behind a failure, e.g. the film closing next to a spin pole.
    const ROOM: usize = 260;
    if first.chars().count() > ROOM {
        format!("{}...", first.chars().take(ROOM).collect::<String>())
    } else {
        first.to_string()
    }
}

/// The checks of one case; `change` is the largest relative change of hc and hm allowed
/// between the pair ([`MESH_CHANGE`] for a mesh pair, the target for a target pair). Returns
/// the table row (Markdown) and the failed checks.
pub fn check_case(name: &str, default: &Run, refined: &Run, change: f64) -> (String, Vec<String>) {
    let mut failed = Vec::new();
    let mut keys = Vec::new();
    for (label, run) in [("default", default), ("refined", refined)] {
        match (&run.summary, &run.error) {
            (Some(s), None) if s.get("converged").and_then(|c| c.as_bool()) == Some(true) => {
                if let Some(acc) = s.get("accuracy").filter(|a| a.get("reached").and_then(|r| r.as_bool()) == Some(false)) {
                    let why = acc.get("not_reached_because").and_then(|w| w.as_str()).unwrap_or("no reason given");
                    failed.push(format!("{label}: target not reached ({why})"));
                }
                let nans = nan_keys(s);
                if !nans.is_empty() {
                    failed.push(format!("{label}: NaN in {}", nans.join(", ")));
                }
                match key_numbers(s) {
                    Some(k) => {
                        if k.pmin_ph < PMIN_OVER_PH {
                            failed.push(format!("{label}: nodal p_min = {:.2e} p_H < {PMIN_OVER_PH:.0e} p_H", k.pmin_ph));
                        }
                        if k.hm <= 0.0 {
                            failed.push(format!("{label}: h_min = {:.3e} m <= 0", k.hm));
                        }
                        if !(k.load_error < LOAD_ERROR) {
                            failed.push(format!("{label}: load error {:.1e} >= {LOAD_ERROR:.0e}", k.load_error));
                        }
                        keys.push(Some(k));
                    }
                    None => {
                        failed.push(format!("{label}: summary lacks film/pressure/solver numbers"));
                        keys.push(None);
                    }
                }
            }
            (_, Some(e)) => {
                failed.push(format!("{label}: did not converge ({})", short_reason(e)));
                keys.push(None);
            }
            _ => {
                failed.push(format!("{label}: no converged summary"));
                keys.push(None);
            }
        }
    }
    let (dhc, dhm, fmoves) = match (keys[0], keys[1]) {
        (Some(d), Some(r)) => {
            let (dhc, dhm) = ((d.hc - r.hc) / r.hc, (d.hm - r.hm) / r.hm);
            if !(dhc.abs() < change) {
                failed.push(format!("hc moves {:+.2} % between the pair", 100.0 * dhc));
            }
            if !(dhm.abs() < change) {
                failed.push(format!("hm moves {:+.2} % between the pair", 100.0 * dhm));
            }
            (Some(dhc), Some(dhm), friction_moves(d.friction, r.friction))
        }
        _ => (None, None, None),
    };
    if let Some(moves) = fmoves {
        for (name, v) in ["fx", "fz"].iter().zip(moves) {
            if !(v.abs() < change) {
                failed.push(format!("{name} moves {:+.2} % of the friction coefficient between the pair", 100.0 * v));
            }
        }
    }
    let m = default.summary.as_ref().or(refined.summary.as_ref()).and_then(|s| num(s, "moes.M"));
    let pair = |f: &dyn Fn(&Key) -> String| {
        format!("{} / {}", keys[0].as_ref().map(f).unwrap_or("-".into()), keys[1].as_ref().map(f).unwrap_or("-".into()))
    };
    let pct = |v: Option<f64>| v.map(|v| format!("{:+.2} %", 100.0 * v)).unwrap_or("-".into());
    let worst = |f: &dyn Fn(&Key) -> f64, min: bool| {
        let v: Vec<f64> = keys.iter().flatten().map(f).collect();
        if v.is_empty() {
            "-".to_string()
        } else if min {
            format!("{:.1e}", v.iter().cloned().fold(f64::INFINITY, f64::min))
        } else {
            format!("{:.1e}", v.iter().cloned().fold(0.0, f64::max))
        }
    };
    let row = format!(
        "| {name} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.0} / {:.0} | {} |\n",
        m.map(|m| format!("{m:.0}")).unwrap_or("-".into()),
        keys.iter().map(|k| if k.is_some() { "yes" } else { "NO" }).collect::<Vec<_>>().join(" / "),
        pair(&|k| format!("{:.0}", k.its)),
        pair(&|k| k.steps.to_string()),
        pair(&|k| format!("{:.4}", k.hc * 1e6)),
        pair(&|k| format!("{:.4}", k.hm * 1e6)),
        pct(dhc),
        pct(dhm),
        fmoves.map(|[x, z]| format!("{}, {}", pct(Some(x)), pct(Some(z)))).unwrap_or("-".into()),
        worst(&|k| k.pmin_ph, true),
        worst(&|k| k.load_error, false),
        default.wall_s,
        refined.wall_s,
        if failed.is_empty() { "pass".to_string() } else { format!("FAIL: {}", failed.join("; ")) }
    );
    (row, failed)
}

/// How far fx and fz move from the refined run `r` to the default one `d`, relative to the
/// refined run's friction coefficient sqrt(fx^2 + fz^2): where both runs estimated them as
/// targets ([`Key::friction`]), else None (a mesh pair, or no friction).
fn friction_moves(d: Option<[f64; 2]>, r: Option<[f64; 2]>) -> Option<[f64; 2]> {
    let (d, r) = (d?, r?);
    let scale = r[0].hypot(r[1]);
    (scale > 0.0).then(|| [(d[0] - r[0]) / scale, (d[1] - r[1]) / scale])
}

/// Header of the hard suite's table.
pub const HEADER: &str = "| case | M | converged (default / refined) | Newton its | continuation steps | hc (um) | hm (um) | hc change | hm change | fx, fz change (of the friction coefficient) | min nodal p / p_H | max load error | wall (s) | verdict |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn run(hc: f64, hm: f64, pmin: f64) -> Run {
        Run {
            summary: Some(json!({
                "converged": true, "hertz": {"ph_pa": 1e9}, "moes": {"M": 100.0},
                "film": {"hc_m": hc, "hm_m": hm},
                "pressure": {"pmin_nodes_pa": pmin, "load_error_rel": 1e-12},
                "solver": {"newton_iterations": 12, "path": ["Newton", "continuation"]}
            })),
            wall_s: 10.0,
            error: None,
        }
    }

    #[test]
    fn a_good_pair_passes() {
        let (row, failed) = check_case("ok", &run(3.0e-7, 1.0e-7, -1e5), &run(3.01e-7, 1.01e-7, -2e5), MESH_CHANGE);
        assert!(failed.is_empty(), "{failed:?}");
        assert!(row.contains("| ok | 100 |") && row.ends_with("| pass |\n"), "{row}");
    }

    #[test]
    fn each_check_can_fail() {
        // hm moves 5 %, nodal p below -1e-3 p_H.
        let (_, f) = check_case("bad", &run(3.0e-7, 1.05e-7, -2e6), &run(3.0e-7, 1.0e-7, 0.0), MESH_CHANGE);
        assert_eq!(f.len(), 2, "{f:?}");
        assert!(f.iter().any(|m| m.contains("hm moves +5.00 %")) && f.iter().any(|m| m.contains("p_min")));
        // A failed refined run.
        let failed_run = Run { summary: None, wall_s: 3.0, error: Some("DIVERGED_LINE_SEARCH".into()) };
        let (row, f) = check_case("div", &run(3.0e-7, 1.0e-7, 0.0), &failed_run, MESH_CHANGE);
        assert!(f[0].contains("refined: did not converge (DIVERGED_LINE_SEARCH)") && row.contains("FAIL"), "{row}");
        // NaN written as null.
        let mut r = run(3.0e-7, 1.0e-7, 0.0);
        r.summary.as_mut().unwrap()["pressure"]["pmax_pa"] = serde_json::Value::Null;
        let (_, f) = check_case("nan", &r, &run(3.0e-7, 1.0e-7, 0.0), MESH_CHANGE);
        assert!(f.iter().any(|m| m.contains("NaN in pressure.pmax_pa")), "{f:?}");
        // A value that may be absent is no NaN: the film formulas outside the setting they
        // were fitted in (the Nijenbanning film of a Roelands scene).
        let mut r = run(3.0e-7, 1.0e-7, 0.0);
        let s = r.summary.as_mut().unwrap();
        s["film"]["hc_nijenbanning_m"] = serde_json::Value::Null;
        s["film"]["hm_hamrock_dowson_m"] = serde_json::Value::Null;
        let (_, f) = check_case("absent", &r, &run(3.0e-7, 1.0e-7, 0.0), MESH_CHANGE);
        assert!(f.is_empty(), "{f:?}");
    }

    #[test]
    fn a_target_pair_checks_the_targets_and_the_change_against_the_target() {
        // 1 % target: a 1.5 % move between the target and the quarter-target run fails it,
        // though it would pass the 2 % of a mesh pair.
        let (_, f) = check_case("t", &run(3.0e-7, 1.015e-7, 0.0), &run(3.0e-7, 1.0e-7, 0.0), 0.01);
        assert_eq!(f, ["hm moves +1.50 % between the pair"]);
        let mut short = run(3.0e-7, 1.0e-7, 0.0);
        short.summary.as_mut().unwrap()["accuracy"] = json!({"reached": false, "not_reached_because": "the time budget"});
        let (row, f) = check_case("t", &run(3.0e-7, 1.0e-7, 0.0), &short, 0.01);
        assert_eq!(f, ["refined: target not reached (the time budget)"], "{row}");
    }

    #[test]
    fn a_target_pair_checks_fx_and_fz_against_the_friction_coefficient() {
        let with_friction = |fx: f64, fz: f64| {
            let mut r = run(3.0e-7, 1.0e-7, 0.0);
            let s = r.summary.as_mut().unwrap();
            s["friction"] = json!({"fx": fx, "fz": fz});
            s["accuracy"] = json!({"reached": true, "estimated_error": {"hc": 0.001, "hm": 0.001, "fx": 0.001, "fz": 0.001}});
            r
        };
        // fz is small next to fx: its move is measured against sqrt(fx^2 + fz^2) = 4.12e-3,
        // so a move of 3e-5 (3 % of fz itself) is 0.73 % of the coefficient and passes at 1 %.
        let (row, f) = check_case("spin", &with_friction(4.0e-3, -1.03e-3), &with_friction(4.0e-3, -1.0e-3), 0.01);
        assert!(f.is_empty(), "{f:?}");
        assert!(row.contains("| +0.00 %, -0.73 % |"), "{row}");
        let (_, f) = check_case("spin", &with_friction(4.0e-3 * 1.02, -3.0e-3), &with_friction(4.0e-3, -3.0e-3), 0.01);
        assert_eq!(f, ["fx moves +1.60 % of the friction coefficient between the pair"]);
        // Without friction among the estimated values (a mesh pair's runs) it is not checked.
        let mut plain = with_friction(4.0e-3 * 1.5, 0.0);
        plain.summary.as_mut().unwrap().as_object_mut().unwrap().remove("accuracy");
        let (_, f) = check_case("mesh", &plain, &with_friction(4.0e-3, 0.0), MESH_CHANGE);
        assert!(f.is_empty(), "{f:?}");
    }

    #[test]
    fn a_run_without_summary_says_why() {
        let log = "[ 1.0 s] mesh: ...\nehl-petsc: error: Newton did not converge: DIVERGED_MAX_IT\n";
        assert_eq!(failure_reason(log, Some(1)), "Newton did not converge: DIVERGED_MAX_IT");
        assert_eq!(failure_reason("[ 1.0 s] mesh\n", Some(TIMEOUT_RC)), "stopped by the time limit (ci/hard -T)");
        assert!(failure_reason("", Some(137)).contains("exit code 137"));
        assert_eq!(failure_reason("", None), "no summary.json and no error line");
    }
}
