//! Prints the numbers behind each finding of the paper (docs/paper.md, findings 1-6)
//! from the outputs of the paper scenes, and whether the model reproduces it:
//!
//!   paper-findings [--fig4-6 DIR] [--fig7-8 DIR] [--case1 DIR] [--case2 DIR] [--extra DIR]...
//!
//! Defaults: out/fig4-6, out/fig7-8, out/case1, out/case2. `--extra` adds single-point
//! output folders to a table of hc, hm, fx, fz (the R_D study). A finding the model does
//! not reproduce is printed as DIFFERS with its numbers (the model is not bent to fit);
//! the exit code is non-zero only when an output is missing.
use ehl_petsc::output::summary::Summary;
use ehl_petsc::Error;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

type Res<T> = Result<T, Error>;

fn read(path: &Path) -> Res<String> {
    std::fs::read_to_string(path).map_err(Error::reading(path))
}

/// A CSV file as rows of named columns (numbers where they parse).
fn csv(path: &Path) -> Res<Vec<HashMap<String, String>>> {
    let (head, rows) =
        ehl_petsc::output::csv::parse_csv_cells(&read(path)?, &path.display().to_string()).map_err(|e| Error::format(e.to_string()))?;
    Ok(rows.into_iter().map(|r| head.iter().cloned().zip(r).collect()).collect())
}

fn f(row: &HashMap<String, String>, key: &str) -> f64 {
    row.get(key).and_then(|v| v.parse().ok()).unwrap_or(f64::NAN)
}

fn summary(dir: &Path) -> Res<Summary> {
    Summary::read(dir)
}

/// Friction coefficients (fx, fz) of a run, NaN without a friction model.
fn friction(s: &Summary) -> (f64, f64) {
    s.friction.as_ref().map_or((f64::NAN, f64::NAN), |f| (f.fx, f.fz))
}

/// Linear interpolation of column `yc` at `xv` of column `xc` (rows sorted by xc).
fn interp(rows: &[HashMap<String, String>], xc: &str, yc: &str, xv: f64) -> f64 {
    for w in rows.windows(2) {
        let (x0, x1) = (f(&w[0], xc), f(&w[1], xc));
        if (x0 - xv) * (x1 - xv) <= 0.0 && x1 != x0 {
            let t = (xv - x0) / (x1 - x0);
            return f(&w[0], yc) * (1.0 - t) + f(&w[1], yc) * t;
        }
    }
    f64::NAN
}

fn verdict(ok: bool) -> &'static str {
    if ok {
        "HOLDS"
    } else {
        "DIFFERS"
    }
}

struct Sweep {
    dir: PathBuf,
    rows: Vec<HashMap<String, String>>,
}

impl Sweep {
    fn load(dir: &Path) -> Res<Sweep> {
        Ok(Sweep { dir: dir.to_path_buf(), rows: csv(&dir.join("sweep.csv"))? })
    }
    /// The row (and its 1-based point number) at (Ue, lambda, SRR).
    fn at(&self, ue: f64, lambda: f64, srr: f64) -> Option<(usize, &HashMap<String, String>)> {
        self.rows
            .iter()
            .enumerate()
            .find(|(_, r)| {
                f(r, "ue_m_s") == ue
                    && f(r, "tilt_angle_deg") == lambda
                    && (f(r, "slide_to_roll") - srr).abs() < 1e-12
                    && r.get("status").map(String::as_str) == Some("converged")
            })
            .map(|(i, r)| (i + 1, r))
    }
    fn get(&self, ue: f64, lambda: f64, srr: f64, key: &str) -> f64 {
        self.at(ue, lambda, srr).map(|(_, r)| f(r, key)).unwrap_or(f64::NAN)
    }
    fn point_dir(&self, ue: f64, lambda: f64, srr: f64) -> Option<PathBuf> {
        self.at(ue, lambda, srr).map(|(i, _)| self.dir.join(format!("point_{i:03}")))
    }
    fn values(&self, key: &str) -> Vec<f64> {
        let mut v: Vec<f64> = self.rows.iter().map(|r| f(r, key)).filter(|x| x.is_finite()).collect();
        v.sort_by(|a, b| a.total_cmp(b));
        v.dedup();
        v
    }
}

const LAMBDAS: [f64; 6] = [90.0, 7.0, 4.0, 2.0, 1.0, 0.5];

fn figs_4_6(dir: &Path) -> Res<()> {
    let s = Sweep::load(dir)?;
    println!("## Findings 1-3 (Figs. 4-6), {}\n", dir.display());
    println!("| Ue (m/s) | lambda (deg) | hc (um) | hm (um) | hc/hc90 | hm/hm90 | pmax/pmax90 |");
    println!("|---|---|---|---|---|---|---|");
    let ues = s.values("ue_m_s");
    for &ue in &ues {
        let (hc90, hm90, p90) = (s.get(ue, 90.0, 0.0, "hc_m"), s.get(ue, 90.0, 0.0, "hm_m"), s.get(ue, 90.0, 0.0, "pmax_pa"));
        for l in LAMBDAS {
            let (hc, hm, p) = (s.get(ue, l, 0.0, "hc_m"), s.get(ue, l, 0.0, "hm_m"), s.get(ue, l, 0.0, "pmax_pa"));
            println!("| {ue} | {l} | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} |", hc * 1e6, hm * 1e6, hc / hc90, hm / hm90, p / p90);
        }
    }
    println!();
    let ratio = |ue: f64, l: f64, k: &str| s.get(ue, l, 0.0, k) / s.get(ue, 90.0, 0.0, k);
    // 1a: hc unchanged for lambda > 2, hm unchanged for lambda > 4 (within 1 %).
    let dev_hc = ues.iter().flat_map(|&u| [7.0, 4.0].map(|l| (ratio(u, l, "hc_m") - 1.0).abs())).fold(0.0, f64::max);
    let dev_hm = ues.iter().map(|&u| (ratio(u, 7.0, "hm_m") - 1.0).abs()).fold(0.0, f64::max);
    println!(
        "1a. hc unchanged for lambda in {{4, 7}} deg: max |hc/hc90 - 1| = {:.2} % (< 1 %): {}",
        100.0 * dev_hc,
        verdict(dev_hc < 0.01)
    );
    println!("1b. hm unchanged at lambda = 7 deg: max |hm/hm90 - 1| = {:.2} % (< 1 %): {}", 100.0 * dev_hm, verdict(dev_hm < 0.01));
    let hc7 = ues.iter().map(|&u| (ratio(u, 7.0, "hc_m") - 1.0).abs()).fold(0.0, f64::max);
    println!("    issue check |hc(7)/hc(90) - 1| < 1 %: {:.2} %: {}", 100.0 * hc7, verdict(hc7 < 0.01));
    for &u in &ues {
        let (rc, rm) = (ratio(u, 0.5, "hc_m"), ratio(u, 0.5, "hm_m"));
        println!("1c. Ue = {u}: hm(0.5)/hm(90) = {rm:.4} < hc(0.5)/hc(90) = {rc:.4} < 1: {}", verdict(rm < rc && rc < 1.0));
    }
    for l in [2.0, 1.0, 0.5] {
        let r: Vec<f64> = ues.iter().map(|&u| ratio(u, l, "hm_m")).collect();
        let spread = r.iter().cloned().fold(f64::NEG_INFINITY, f64::max) - r.iter().cloned().fold(f64::INFINITY, f64::min);
        println!("1d. hm(lambda)/hm(90) at lambda = {l} over Ue = {ues:?}: {:?}, spread {spread:.4} (almost independent of Ue: spread < 0.05): {}", r.iter().map(|x| (x * 1e4).round() / 1e4).collect::<Vec<_>>(), verdict(spread < 0.05));
    }
    // 2: the profile on x = 0.
    println!();
    let a = summary(&s.point_dir(ues[0], 90.0, 0.0).ok_or_else(|| Error::invalid("no lambda = 90 point"))?)?.hertz.a_m;
    let mut asym = Vec::new();
    for &u in &ues {
        let prof = |l: f64| -> Res<Vec<HashMap<String, String>>> {
            csv(&s.point_dir(u, l, 0.0).ok_or_else(|| Error::invalid(format!("no point Ue {u} lambda {l}")))?.join("profile_x0.csv"))
        };
        let p90 = prof(90.0)?;
        let hc90 = s.get(u, 90.0, 0.0, "hc_m");
        let p7 = prof(7.0)?;
        let dmax =
            p90.iter().zip(&p7).filter(|(r, _)| f(r, "z_m").abs() <= a).map(|(r, q)| (f(r, "h_m") - f(q, "h_m")).abs()).fold(0.0, f64::max)
                / hc90;
        println!("2a. Ue = {u}: profiles on x = 0 at lambda = 90 and 7 deg differ by at most {:.2} % of hc over |z| <= a (almost the same: < 2 %): {}", 100.0 * dmax, verdict(dmax < 0.02));
        for l in [2.0, 1.0, 0.5] {
            let p = prof(l)?;
            let (hm_, hp_) = (interp(&p, "z_m", "h_m", -a), interp(&p, "z_m", "h_m", a));
            // Inside the contact, where the film is flat: z = -0.8a and +0.8a.
            let (hm8, hp8) = (interp(&p, "z_m", "h_m", -0.8 * a), interp(&p, "z_m", "h_m", 0.8 * a));
            let rel = (hp8 - hm8) / s.get(u, l, 0.0, "hc_m");
            if l == 0.5 {
                asym.push((u, hp_ - hm_, rel));
            }
            println!(
                "2b. Ue = {u}, lambda = {l}: h(0, -a) = {:.4} um < h(0, +a) = {:.4} um: {};  (h(+0.8a) - h(-0.8a))/hc = {:.3}",
                hm_ * 1e6,
                hp_ * 1e6,
                verdict(hm_ < hp_),
                rel
            );
        }
        // 3: pressure not significantly changed by spin.
        let p05 = prof(0.5)?;
        let ph = summary(&s.point_dir(u, 90.0, 0.0).unwrap())?.hertz.ph_pa;
        let dp = p90.iter().zip(&p05).map(|(r, q)| (f(r, "p_pa") - f(q, "p_pa")).abs()).fold(0.0, f64::max) / ph;
        println!(
            "3.  Ue = {u}: max |p(0.5 deg) - p(90 deg)| on x = 0 = {:.3} p_H, pmax ratio {:.4} (not significantly changed: < 0.1 p_H): {}",
            dp,
            s.get(u, 0.5, 0.0, "pmax_pa") / s.get(u, 90.0, 0.0, "pmax_pa"),
            verdict(dp < 0.1)
        );
    }
    if asym.len() >= 2 {
        let (lo, hi) = (asym[0], asym[asym.len() - 1]);
        println!(
            "2c. asymmetry at lambda = 0.5 deg grows with Ue: h(0, +a) - h(0, -a) = {:.4} um at Ue = {} vs {:.4} um at Ue = {}: {}; relative to hc (at +-0.8a): {:.3} vs {:.3}",
            hi.1 * 1e6, hi.0, lo.1 * 1e6, lo.0, verdict(hi.1 > lo.1), hi.2, lo.2
        );
    }
    println!();
    Ok(())
}

fn figs_7_8(dir: &Path) -> Res<()> {
    let s = Sweep::load(dir)?;
    let ue = s.values("ue_m_s")[0];
    let srrs = s.values("slide_to_roll");
    println!("## Findings 4-5 (Figs. 7-8), {}, Ue = {ue} m/s\n", dir.display());
    print!("| SRR (%) |");
    for l in LAMBDAS {
        print!(" fx, {l} deg | fz, {l} deg |");
    }
    println!();
    println!("|---|{}", "---|---|".repeat(LAMBDAS.len()));
    for &r in &srrs {
        print!("| {} |", r * 100.0);
        for l in LAMBDAS {
            print!(" {:.4} | {:.2e} |", s.get(ue, l, r, "fx"), s.get(ue, l, r, "fz"));
        }
        println!();
    }
    println!();
    let fx = |l: f64, r: f64| s.get(ue, l, r, "fx");
    println!(
        "4a. SRR = 5 %: fx(2 deg) = {:.4} < fx(90 deg) = {:.4}: {}",
        fx(2.0, 0.05),
        fx(90.0, 0.05),
        verdict(fx(2.0, 0.05) < fx(90.0, 0.05))
    );
    let slopes: Vec<f64> = LAMBDAS.iter().map(|&l| (fx(l, 0.01) - fx(l, -0.01)) / 0.02).collect();
    let decreasing = slopes.windows(2).all(|w| w[1] <= w[0] * 1.001);
    println!(
        "4b. slope dfx/dSRR at SRR = 0 for lambda = {:?}: {:?}; smaller lambda, smaller slope: {}",
        LAMBDAS,
        slopes.iter().map(|x| (x * 1e3).round() / 1e3).collect::<Vec<_>>(),
        verdict(decreasing)
    );
    // "Friction falls roughly in proportion" for SRR <= 10 % and lambda <= 7 deg: read as
    // fx proportional to lambda, i.e. fx(lambda) / fx(lambda') = lambda / lambda'.
    let pairs = [(4.0, 7.0), (2.0, 4.0), (1.0, 2.0), (0.5, 1.0)];
    let mut worst: f64 = 0.0;
    for &sr in &[0.02, 0.05, 0.1] {
        let r: Vec<String> = pairs
            .iter()
            .map(|&(l1, l2)| {
                let q = fx(l1, sr) / fx(l2, sr);
                worst = worst.max((q / (l1 / l2) - 1.0).abs());
                format!("fx({l1})/fx({l2}) = {q:.3} (lambda ratio {:.3})", l1 / l2)
            })
            .collect();
        println!("4c. SRR = {} %: {}", sr * 100.0, r.join(", "));
    }
    println!(
        "4c. fx proportional to lambda for lambda <= 7 deg, SRR <= 10 %: worst deviation of the ratios {:.0} % (roughly: < 20 %): {}",
        100.0 * worst,
        verdict(worst < 0.2)
    );
    let max_fx = s.rows.iter().map(|r| f(r, "fx").abs()).filter(|x| x.is_finite()).fold(0.0, f64::max);
    let max_fz = s.rows.iter().map(|r| f(r, "fz").abs()).filter(|x| x.is_finite()).fold(0.0, f64::max);
    println!(
        "5a. max |fz| / max |fx| = {:.2e} / {:.2e} = {:.1e} (about two orders: in [3e-3, 3e-2]): {}",
        max_fz,
        max_fx,
        max_fz / max_fx,
        verdict((3e-3..3e-2).contains(&(max_fz / max_fx)))
    );
    for l in LAMBDAS {
        let (mut best, mut at) = (0.0f64, f64::NAN);
        for &r in &srrs {
            let v = s.get(ue, l, r, "fz").abs();
            if v > best {
                best = v;
                at = r;
            }
        }
        // Width: the SRR range where |fz| >= max/2.
        let above: Vec<f64> = srrs.iter().copied().filter(|&r| s.get(ue, l, r, "fz").abs() >= 0.5 * best).collect();
        let width = above.last().unwrap_or(&f64::NAN) - above.first().unwrap_or(&f64::NAN);
        println!(
            "5b. lambda = {l}: max |fz| = {best:.3e} at SRR = {} %, half-height width {} % of SRR",
            at * 100.0,
            (width * 1e4).round() / 1e2
        );
    }
    println!();
    Ok(())
}

fn cases(c1: &Path, c2: &Path) -> Res<()> {
    println!("## Finding 6 (Figs. 9-11), {} and {}\n", c1.display(), c2.display());
    let stats = |dir: &Path| -> Res<(f64, f64, f64, f64, f64)> {
        let rows = csv(&dir.join("shear_profile.csv"))?;
        let a = summary(dir)?.hertz.a_m;
        let inside: Vec<&HashMap<String, String>> = rows.iter().filter(|r| f(r, "x_m").abs() <= a).collect();
        let tx: Vec<f64> = inside.iter().map(|r| f(r, "tau_yx_pa")).collect();
        let tz: Vec<f64> = inside.iter().map(|r| f(r, "tau_yz_pa")).collect();
        let p: Vec<f64> = inside.iter().map(|r| f(r, "p_pa")).collect();
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
        let (mx, mp) = (mean(&tx), mean(&p));
        let cov: f64 = tx.iter().zip(&p).map(|(a, b)| (a - mx) * (b - mp)).sum();
        let corr = cov / (tx.iter().map(|a| (a - mx).powi(2)).sum::<f64>().sqrt() * p.iter().map(|b| (b - mp).powi(2)).sum::<f64>().sqrt());
        let max = |v: &[f64]| v.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        let min = |v: &[f64]| v.iter().cloned().fold(f64::INFINITY, f64::min);
        Ok((min(&tx), max(&tx), tz.iter().map(|x| x.abs()).fold(0.0, f64::max), corr, min(&tz).abs().min(max(&tz).abs())))
    };
    let (a1, b1, z1, c1r, _) = stats(c1)?;
    let (_, _, z2, _, zz2) = stats(c2)?;
    // The sign zones of tau_yx in Case 2 lie on either side of a line across the rolling
    // direction: look along the transverse centre line x = 0, inside the contact.
    let transverse = |dir: &Path| -> Res<(f64, f64)> {
        let rows = csv(&dir.join("profile_x0.csv"))?;
        let a = summary(dir)?.hertz.a_m;
        let t: Vec<f64> = rows.iter().filter(|r| f(r, "z_m").abs() <= a).map(|r| f(r, "tau_yx_pa")).collect();
        Ok((t.iter().cloned().fold(f64::INFINITY, f64::min), t.iter().cloned().fold(f64::NEG_INFINITY, f64::max)))
    };
    let (a2, b2) = transverse(c2)?;
    let (a1x, b1x) = transverse(c1)?;
    println!("6a. Case 1 (lambda = 90): tau_yx on the line in [{:.2}, {:.2}] MPa, correlation with p = {c1r:.3} (follows the pressure: > 0.8): {}", a1 * 1e-6, b1 * 1e-6, verdict(c1r > 0.8));
    let split = a2 < -0.1 * b2.abs().max(a2.abs()) && b2 > 0.1 * b2.abs().max(a2.abs());
    println!(
        "6b. Case 2 (lambda = 2): tau_yx on x = 0, |z| <= a in [{:.2}, {:.2}] MPa (zones of opposite sign: {}); Case 1: [{:.2}, {:.2}] MPa",
        a2 * 1e-6,
        b2 * 1e-6,
        verdict(split),
        a1x * 1e-6,
        b1x * 1e-6
    );
    println!(
        "6c. max |tau_yz| on the line: Case 1 {:.2} MPa vs Case 2 {:.2} MPa (near zero in Case 1, strong in Case 2): {}",
        z1 * 1e-6,
        z2 * 1e-6,
        verdict(z1 < 0.3 * z2)
    );
    println!("6d. Case 2 tau_yz has both signs on the line, the weaker zone reaching {:.2} MPa", zz2 * 1e-6);
    for (name, d) in [("Case 1", c1), ("Case 2", c2)] {
        let s = summary(d)?;
        println!(
            "    {name}: hc {:.4} um, hm {:.4} um, fx {:.4}, fz {:.3e}",
            s.film.hc_m * 1e6,
            s.film.hm_m * 1e6,
            friction(&s).0,
            friction(&s).1
        );
    }
    println!();
    Ok(())
}

fn extra(dirs: &[PathBuf]) -> Res<()> {
    println!("## Single runs\n\n| folder | R_D (m) | lambda (deg) | SRR | hc (um) | hm (um) | fx | fz | Newton its | wall (s) |\n|---|---|---|---|---|---|---|---|---|---|");
    for d in dirs {
        let s = summary(d)?;
        println!(
            "| {} | {} | {} | {} | {:.4} | {:.4} | {:.4} | {:.3e} | {} | {:.0} |",
            d.display(),
            s.scene.geometry.disc_track_radius,
            s.operating.tilt_angle_deg,
            s.operating.slide_to_roll,
            s.film.hc_m * 1e6,
            s.film.hm_m * 1e6,
            friction(&s).0,
            friction(&s).1,
            s.solver.newton_iterations,
            s.timing.total_s
        );
    }
    println!();
    Ok(())
}

fn main() {
    let mut dirs: HashMap<&str, PathBuf> =
        [("fig4-6", "out/fig4-6"), ("fig7-8", "out/fig7-8"), ("case1", "out/case1"), ("case2", "out/case2")]
            .into_iter()
            .map(|(k, v)| (k, PathBuf::from(v)))
            .collect();
    let mut extras = Vec::new();
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut i = 0;
    while i < args.len() {
        let key = args[i].trim_start_matches("--");
        let Some(val) = args.get(i + 1) else {
            eprintln!("paper-findings: {} needs a folder", args[i]);
            std::process::exit(2);
        };
        match key {
            "fig4-6" | "fig7-8" | "case1" | "case2" => {
                let k: &str = ["fig4-6", "fig7-8", "case1", "case2"].into_iter().find(|k| *k == key).unwrap();
                dirs.insert(k, PathBuf::from(val));
            }
            "extra" => extras.push(PathBuf::from(val)),
            _ => {
                eprintln!("paper-findings: unknown option {} (known: --fig4-6, --fig7-8, --case1, --case2, --extra)", args[i]);
                std::process::exit(2);
            }
        }
        i += 2;
    }
    let mut missing = 0;
    let mut report = |r: Res<()>| {
        if let Err(e) = r {
            eprintln!("paper-findings: {e}");
            missing += 1;
        }
    };
    report(figs_4_6(&dirs["fig4-6"]));
    report(figs_7_8(&dirs["fig7-8"]));
    report(cases(&dirs["case1"], &dirs["case2"]));
    if !extras.is_empty() {
        report(extra(&extras));
    }
    std::process::exit(if missing > 0 { 1 } else { 0 });
}
