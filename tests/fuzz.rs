//! Fuzzing the scene validation (issue 27): scenes made by randomly mutating the shipped
//! ones (values, keys, types, sections, bytes) go through `ehl-petsc --check`, which must
//! end with exit 0 (valid) or 2 (refused, one message), never panic, never hang.
//!
//! `fuzz_scenes_in_ci` runs a few hundred; `fuzz_scenes_10000` (ignored; run it with
//! `cargo test --release --test fuzz -- --ignored --nocapture`) runs 10,000 and prints the
//! counts given in docs/robustness.md.
mod common;
use common::*;
use std::process::Command;
use std::time::Instant;

/// xorshift64*: a small deterministic generator (the same seed gives the same scenes).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545F4914F6CDD1D)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
    fn pick<'a, T>(&mut self, v: &'a [T]) -> &'a T {
        &v[self.below(v.len())]
    }
}

/// Replacement values: extremes, non-finite numbers, wrong types.
const VALUES: &[&str] = &[
    "0",
    "-0.0",
    "-1",
    "1",
    "2",
    "1e308",
    "-1e308",
    "1e-320",
    "5e-324",
    "nan",
    "inf",
    "-inf",
    "9223372036854775807",
    "-9223372036854775808",
    "1e6",
    "1e-6",
    "0.5",
    "90",
    "1e9",
    "\"text\"",
    "\"\"",
    "true",
    "false",
    "[]",
    "[1.0, 2.0]",
    "[\"a\"]",
    "{}",
    "{ x = 1 }",
    "1979-05-27",
    "\"roelands\"",
    "\"none\"",
    "\"spin\"",
    "[0.0, 1e308]",
];

/// Key names to insert or rename to (known ones elsewhere, misspellings, junk).
const KEYS: &[&str] = &[
    "load",
    "lod",
    "young_modulus",
    "viscosity",
    "contact_size",
    "cube_size",
    "x_min",
    "accept",
    "tilt_angle",
    "sweep",
    "checks",
    "name",
    "dir",
    "a.b",
    "\"quoted key\"",
    "ü",
];

/// Section headers to insert.
const SECTIONS: &[&str] = &[
    "[sweep]",
    "[checks]",
    "[mesh]",
    "[reynolds]",
    "[operating]",
    "[materials.ball]",
    "[nonsense]",
    "[[array]]",
    "[effects]",
    "[lubricant]",
];

/// Where the numbers, keys and values of `text` are: (line index, byte start, byte end) of
/// each value after an `=`.
fn value_spans(lines: &[String]) -> Vec<(usize, usize)> {
    lines.iter().enumerate().filter_map(|(i, l)| l.find('=').filter(|_| !l.trim_start().starts_with('#')).map(|p| (i, p + 1))).collect()
}

/// One mutation of the scene text.
fn mutate(text: &str, rng: &mut Rng) -> String {
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    match rng.below(12) {
        // Replace a value.
        0..=3 => {
            let spans = value_spans(&lines);
            if let Some(&(i, p)) = spans.get(rng.below(spans.len())) {
                lines[i] = format!("{}= {}", &lines[i][..p - 1], rng.pick(VALUES));
            }
        }
        // Scale a number by 10^k.
        4 => {
            let spans = value_spans(&lines);
            if let Some(&(i, p)) = spans.get(rng.below(spans.len())) {
                if let Ok(v) = lines[i][p..].trim().parse::<f64>() {
                    let k = rng.below(80) as i32 - 40;
                    lines[i] = format!("{}= {:e}", &lines[i][..p - 1], v * 10f64.powi(k));
                }
            }
        }
        // Rename a key.
        5 => {
            let spans = value_spans(&lines);
            if let Some(&(i, p)) = spans.get(rng.below(spans.len())) {
                lines[i] = format!("{} ={}", rng.pick(KEYS), &lines[i][p..]);
            }
        }
        // Delete, duplicate or move a line.
        6 => {
            if !lines.is_empty() {
                let i = rng.below(lines.len());
                match rng.below(3) {
                    0 => {
                        lines.remove(i);
                    }
                    1 => {
                        let l = lines[i].clone();
                        lines.insert(i, l);
                    }
                    _ => {
                        let l = lines.remove(i);
                        let j = rng.below(lines.len() + 1);
                        lines.insert(j, l);
                    }
                }
            }
        }
        // Insert a section header or a key.
        7 => {
            let j = rng.below(lines.len() + 1);
            let l = if rng.below(2) == 0 { rng.pick(SECTIONS).to_string() } else { format!("{} = {}", rng.pick(KEYS), rng.pick(VALUES)) };
            lines.insert(j, l);
        }
        // A sweep or an accept list of odd content.
        8 => {
            let l = match rng.below(4) {
                0 => format!(
                    "[sweep]\nentrainment_speed = [{}]",
                    (0..rng.below(50)).map(|_| rng.pick(VALUES).to_string()).collect::<Vec<_>>().join(", ")
                ),
                1 => format!("[sweep]\ntilt_angle = [{}]\nslide_to_roll = [{}]", rng.pick(VALUES), rng.pick(VALUES)),
                2 => format!("[checks]\naccept = [\"{}\"]", rng.pick(&["memory", "spin", "moes_m", "bogus", "a_over_r"])),
                _ => format!("[checks]\naccept = {}", rng.pick(VALUES)),
            };
            lines.push(l);
        }
        // Bytes: flip, insert, truncate.
        _ => {
            let mut b = lines.join("\n").into_bytes();
            match rng.below(3) {
                0 if !b.is_empty() => {
                    let i = rng.below(b.len());
                    b[i] ^= 1 << rng.below(8);
                }
                1 => {
                    let i = rng.below(b.len() + 1);
                    let junk: Vec<u8> = (0..1 + rng.below(8)).map(|_| rng.next() as u8).collect();
                    b.splice(i..i, junk);
                }
                _ => b.truncate(rng.below(b.len() + 1)),
            }
            return String::from_utf8_lossy(&b).into_owned();
        }
    }
    lines.join("\n")
}

fn shipped_scenes() -> Vec<String> {
    let mut out = Vec::new();
    let mut dirs = vec![repo().join("cases")];
    while let Some(d) = dirs.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                dirs.push(p);
            } else if p.extension().is_some_and(|x| x == "toml") {
                out.push(std::fs::read_to_string(&p).unwrap());
            }
        }
    }
    out.sort();
    out
}

/// Runs `n` mutated scenes through `--check`; panics on any exit other than 0 or 2, a
/// panic, a hang (20 s) or an error printed more than once. Prints the counts.
fn fuzz(n: usize, seed: u64) {
    let bases = shipped_scenes();
    let dir = scratch(&format!("fuzz-{n}"));
    let path = dir.join("scene.toml");
    let mut rng = Rng(seed);
    let (mut valid, mut refused, mut slowest) = (0usize, 0usize, 0f64);
    let mut failures = Vec::new();
    let t0 = Instant::now();
    for k in 0..n {
        let mut text = rng.pick(&bases).clone();
        for _ in 0..1 + rng.below(3) {
            text = mutate(&text, &mut rng);
        }
        std::fs::write(&path, &text).unwrap();
        let t = Instant::now();
        let out = Command::new("timeout")
            .args(["-k", "2", "20"])
            .arg(binary())
            .arg("--check")
            .arg(&path)
            .arg("--output")
            .arg(dir.join("out"))
            .env("OPENBLAS_NUM_THREADS", "1")
            .output()
            .unwrap();
        slowest = slowest.max(t.elapsed().as_secs_f64());
        let all = text_of(&out);
        let errors = String::from_utf8_lossy(&out.stderr).lines().filter(|l| l.starts_with("ehl-petsc: error")).count();
        let ok = match out.status.code() {
            Some(0) => {
                valid += 1;
                errors == 0
            }
            Some(2) => {
                refused += 1;
                errors == 1
            }
            _ => false,
        };
        if !ok || all.contains("panicked") || dir.join("out").exists() {
            let keep = dir.join(format!("failure-{k}.toml"));
            std::fs::write(&keep, &text).unwrap();
            failures.push(format!(
                "scene {k} ({}): exit {:?}, {errors} error lines\n{}",
                keep.display(),
                out.status.code(),
                all.lines().take(5).collect::<Vec<_>>().join("\n")
            ));
        }
    }
    eprintln!(
        "fuzz: {n} mutated scenes through --check in {:.0} s: {valid} valid (exit 0), {refused} refused (exit 2), {} other; slowest run {slowest:.2} s",
        t0.elapsed().as_secs_f64(),
        failures.len()
    );
    assert!(failures.is_empty(), "{} of {n} fuzzed scenes failed:\n{}", failures.len(), failures.join("\n\n"));
}

fn text_of(out: &std::process::Output) -> String {
    text(out)
}

#[test]
fn fuzz_scenes_in_ci() {
    fuzz(100, 0x5eed_2027);
}

#[test]
#[ignore]
fn fuzz_scenes_10000() {
    fuzz(10_000, 0x0ddba11);
}
