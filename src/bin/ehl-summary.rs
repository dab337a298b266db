//! `ehl-summary`: reads ehl-petsc's summary.json files for the regression runner
//! (`ci/regress`) and the hard suite (`ci/hard`).
//!
//!   ehl-summary compare REF.json NEW.json [--tolerances FILE] [--rel TOL]
//!       prints a table of the keys that moved; exit 1 on drift (or a missing key)
//!   ehl-summary get FILE.json KEY...        prints the values of dotted keys
//!   ehl-summary hard OUTDIR CASE... [--change F]  the hard suite's table (OUTDIR/hard.md); exit 1 on a failed check
//!   ehl-summary curve DATA.csv OUT.png [--title T]  error against wall time, one line per
//!       `series` of the CSV (columns series, seconds, error_pct), log-log
//!   ehl-summary levels FILE.json            an adaptive run's levels as a Markdown table
use clap::{Parser, Subcommand};
use ehl_petsc::error::{Error, ResultExt};
use ehl_petsc::regress::{self, hard, Tolerances};
use std::path::{Path, PathBuf};

#[derive(Parser)]
#[command(name = "ehl-summary", about = "Compare and check ehl-petsc summary.json files")]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Compare NEW with the reference REF key by key; exit 1 if a key drifted or is missing
    Compare {
        reference: PathBuf,
        new: PathBuf,
        /// Per-key tolerances (TOML: default = REL, [keys] "pattern" = REL | "ignore" | { rel, abs })
        #[arg(long)]
        tolerances: Option<PathBuf>,
        /// Replace every relative tolerance by REL (ignored keys and absolute floors stay)
        #[arg(long)]
        rel: Option<f64>,
        /// Label printed in the verdict line
        #[arg(long, default_value = "")]
        label: String,
    },
    /// Print the values of dotted keys (e.g. film.hc_m)
    Get { file: PathBuf, keys: Vec<String> },
    /// The hard suite's table from OUTDIR/CASE/{default,refined}/summary.json (and .wall, .log)
    Hard {
        outdir: PathBuf,
        cases: Vec<String>,
        /// Largest relative change of hc and hm allowed between the pair (the accuracy target
        /// for a target pair; default: the mesh pair's 2 %)
        #[arg(long, default_value_t = hard::MESH_CHANGE)]
        change: f64,
    },
    /// Plot error against wall time from a CSV (columns series, seconds, error_pct), one line
    /// per series, log-log: an accuracy-time curve (docs/performance.md)
    Curve {
        data: PathBuf,
        png: PathBuf,
        #[arg(long, default_value = "relative error against wall time")]
        title: String,
    },
    /// An adaptive run's levels as a Markdown table: unknowns, Newton iterations, time,
    /// memory, films, pmax and estimates per level, then the verdict
    Levels { file: PathBuf },
}

fn read_json(p: &Path) -> Result<serde_json::Value, Error> {
    let text = std::fs::read_to_string(p).map_err(Error::reading(p))?;
    serde_json::from_str(&text).map_err(|e| Error::format(format!("{} is not valid JSON: {e}", p.display())))
}

fn run(cli: Cli) -> Result<i32, Error> {
    match cli.cmd {
        Cmd::Compare { reference, new, tolerances, rel, label } => {
            let mut tol = match &tolerances {
                Some(p) => Tolerances::parse(&std::fs::read_to_string(p).map_err(Error::reading(p))?).context(p.display().to_string())?,
                None => Tolerances::uniform(1e-6),
            };
            if let Some(r) = rel {
                tol = tol.with_rel(r);
            }
            let c = regress::compare(&read_json(&reference)?, &read_json(&new)?, &tol);
            print!("{}", c.table());
            let verdict = if c.failures() == 0 { "PASS" } else { "DRIFT" };
            println!(
                "{verdict}{}: {} against {}",
                if label.is_empty() { String::new() } else { format!(" {label}") },
                new.display(),
                reference.display()
            );
            Ok(if c.failures() == 0 { 0 } else { 1 })
        }
        Cmd::Get { file, keys } => {
            let flat = regress::flatten(&read_json(&file)?);
            for k in keys {
                match flat.get(&k) {
                    Some(regress::Leaf::Num(v)) => println!("{v:e}"),
                    Some(regress::Leaf::Text(s)) => println!("{s}"),
                    Some(v) => println!("{v}"),
                    None => return Err(Error::invalid(format!("{}: no key '{k}'", file.display()))),
                }
            }
            Ok(0)
        }
        Cmd::Hard { outdir, cases, change } => {
            let load = |case: &str, mesh: &str| -> hard::Run {
                let base = outdir.join(case).join(mesh);
                let wall_s =
                    std::fs::read_to_string(base.with_extension("wall")).ok().and_then(|t| t.trim().parse().ok()).unwrap_or(f64::NAN);
                match read_json(&base.join("summary.json")) {
                    Ok(s) => hard::Run { summary: Some(s), wall_s, error: None },
                    Err(_) => {
                        // The reason is the run's error line.
                        let log = std::fs::read_to_string(base.with_extension("log")).unwrap_or_default();
                        let rc = std::fs::read_to_string(base.with_extension("rc")).ok().and_then(|t| t.trim().parse().ok());
                        hard::Run { summary: None, wall_s, error: Some(hard::failure_reason(&log, rc)) }
                    }
                }
            };
            let mut md = String::from(hard::HEADER);
            let mut n_failed = 0;
            for case in &cases {
                let (row, failed) = hard::check_case(case, &load(case, "default"), &load(case, "refined"), change);
                md.push_str(&row);
                n_failed += usize::from(!failed.is_empty());
            }
            md.push_str(&format!("\n{} of {} cases pass every check.\n", cases.len() - n_failed, cases.len()));
            print!("{md}");
            let path = outdir.join("hard.md");
            std::fs::write(&path, &md).map_err(Error::writing(&path))?;
            Ok(if n_failed == 0 { 0 } else { 1 })
        }
        Cmd::Levels { file } => {
            print!("{}", regress::levels::levels_table(&read_json(&file)?).context(file.display().to_string())?);
            Ok(0)
        }
        Cmd::Curve { data, png, title } => {
            let series = curve_series(&data)?;
            let opts = ehl_petsc::output::plot::LineOpts { log_x: true, log_y: true, ..Default::default() };
            ehl_petsc::output::plot::line_plot(&png, &title, "wall time (s)", "relative error (%)", &series, &opts)?;
            println!("wrote {}", png.display());
            Ok(0)
        }
    }
}

/// The series of an accuracy-time CSV, in the order they first appear.
fn curve_series(path: &Path) -> Result<Vec<ehl_petsc::output::plot::Series>, Error> {
    use ehl_petsc::output::plot::{Series, Style};
    let text = std::fs::read_to_string(path).map_err(Error::reading(path))?;
    let (head, rows) =
        ehl_petsc::output::csv::parse_csv_cells(&text, &path.display().to_string()).map_err(|e| Error::format(e.to_string()))?;
    let col = |name: &str| {
        head.iter()
            .position(|h| h == name)
            .ok_or_else(|| Error::format(format!("{}: no column '{name}' (need series, seconds, error_pct)", path.display())))
    };
    let (c_s, c_t, c_e) = (col("series")?, col("seconds")?, col("error_pct")?);
    let mut series: Vec<Series> = Vec::new();
    for (i, r) in rows.iter().enumerate() {
        let num = |c: usize| {
            r[c].trim()
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite() && *v > 0.0)
                .ok_or_else(|| Error::format(format!("{} row {}: '{}' is not a positive number", path.display(), i + 2, r[c])))
        };
        let (t, e) = (num(c_t)?, num(c_e)?);
        match series.iter_mut().find(|s| s.label == r[c_s]) {
            Some(s) => {
                s.x.push(t);
                s.y.push(e);
            }
            None => series.push(Series::new(&r[c_s], vec![t], vec![e], Style::LinePoints)),
        }
    }
    Ok(series)
}

fn main() {
    match run(Cli::parse()) {
        Ok(code) => std::process::exit(code),
        Err(e) => {
            eprintln!("ehl-summary: error: {e}");
            std::process::exit(2);
        }
    }
}
