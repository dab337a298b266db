//! Plain CSV tables of numbers (profiles, convergence histories), written atomically.
//!
//! Every value is written as the shortest text that parses back to the same `f64`
//! (Rust's `Display`, or `{:e}` for very large or very small magnitudes), so a table read back
//! with [`read_csv`] is bit-for-bit the table written. Non-finite values are written as `NaN`,
//! `inf` and `-inf`, which [`read_csv`] (and numpy, pandas) read back.
use std::io;
use std::path::Path;

/// Formats one value: shortest round-trip text, plain for 1e-4 <= |v| < 1e15, otherwise with an exponent.
pub fn format_value(v: f64) -> String {
    let a = v.abs();
    if v == 0.0 || !v.is_finite() || (1e-4..1e15).contains(&a) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

fn quote_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// Writes a header line and one line per row. Every row must have `header.len()` values.
pub fn write_csv(path: &Path, header: &[&str], rows: &[Vec<f64>]) -> io::Result<()> {
    if header.is_empty() {
        return Err(io::Error::new(io::ErrorKind::InvalidInput, "csv: empty header"));
    }
    let mut out = String::with_capacity(32 * (rows.len() + 1) * header.len());
    out.push_str(&header.iter().map(|h| quote_field(h)).collect::<Vec<_>>().join(","));
    out.push('\n');
    for (i, row) in rows.iter().enumerate() {
        if row.len() != header.len() {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!("csv '{}': row {i} has {} values, header has {}", path.display(), row.len(), header.len()),
            ));
        }
        for (j, v) in row.iter().enumerate() {
            if j > 0 {
                out.push(',');
            }
            out.push_str(&format_value(*v));
        }
        out.push('\n');
    }
    super::write_atomic(path, out.as_bytes())
}

/// Writes columns of equal length (e.g. `x`, `p`, `h` of a profile) as a table.
pub fn write_csv_columns(path: &Path, header: &[&str], columns: &[&[f64]]) -> io::Result<()> {
    if columns.len() != header.len() {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("csv '{}': {} columns for {} header names", path.display(), columns.len(), header.len()),
        ));
    }
    let n = columns.first().map_or(0, |c| c.len());
    if let Some((k, c)) = columns.iter().enumerate().find(|(_, c)| c.len() != n) {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("csv '{}': column '{}' has {} values, the first has {n}", path.display(), header[k], c.len()),
        ));
    }
    let rows: Vec<Vec<f64>> = (0..n).map(|i| columns.iter().map(|c| c[i]).collect()).collect();
    write_csv(path, header, &rows)
}

fn split_line(line: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut cur = String::new();
    let mut in_quotes = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, in_quotes) {
            ('"', true) if chars.peek() == Some(&'"') => {
                cur.push('"');
                chars.next();
            }
            ('"', _) => in_quotes = !in_quotes,
            (',', false) => out.push(std::mem::take(&mut cur)),
            _ => cur.push(c),
        }
    }
    out.push(cur);
    out
}

/// Reads a table written by [`write_csv`]: header names and numeric rows.
pub fn read_csv(path: &Path) -> io::Result<(Vec<String>, Vec<Vec<f64>>)> {
    parse_csv(&std::fs::read_to_string(path)?, &path.display().to_string())
}

/// A table's text (`name` for messages) as header names and rows of cells; blank lines are
/// skipped, quoted cells keep their commas.
pub fn parse_csv_cells(text: &str, name: &str) -> io::Result<(Vec<String>, Vec<Vec<String>>)> {
    let mut lines = text.lines().filter(|l| !l.trim().is_empty());
    let header = split_line(lines.next().ok_or_else(|| io::Error::new(io::ErrorKind::InvalidData, format!("csv '{name}': empty file")))?);
    Ok((header, lines.map(split_line).collect()))
}

/// A table's text (`name` for messages) as header names and numeric rows, each with as
/// many values as the header; errors name the data line (1: the first after the header).
pub fn parse_csv(text: &str, name: &str) -> io::Result<(Vec<String>, Vec<Vec<f64>>)> {
    let (header, cells) = parse_csv_cells(text, name)?;
    let mut rows = Vec::with_capacity(cells.len());
    for (i, cells) in cells.iter().enumerate() {
        let row = cells
            .iter()
            .map(|s| s.trim().parse::<f64>())
            .collect::<Result<Vec<f64>, _>>()
            .map_err(|e| io::Error::new(io::ErrorKind::InvalidData, format!("csv '{name}': data line {}: {e}", i + 1)))?;
        if row.len() != header.len() {
            return Err(io::Error::new(
                io::ErrorKind::InvalidData,
                format!("csv '{name}': data line {} has {} values, header has {}", i + 1, row.len(), header.len()),
            ));
        }
        rows.push(row);
    }
    Ok((header, rows))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn test_dir() -> std::path::PathBuf {
        let d = Path::new(env!("CARGO_MANIFEST_DIR")).join("target").join("test-output").join("csv");
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn csv_round_trip_is_exact() {
        let path = test_dir().join("table.csv");
        let header = ["x [m]", "p, Pa", "h \"film\""];
        let rows = vec![
            vec![0.0, 1.0 / 3.0, -2.5e-9],
            vec![1e300, 6.02214076e23, f64::MIN_POSITIVE],
            vec![f64::NAN, f64::INFINITY, f64::NEG_INFINITY],
            vec![-0.1, 123456.789, 1e-5],
        ];
        write_csv(&path, &header, &rows).unwrap();
        let (h, r) = read_csv(&path).unwrap();
        assert_eq!(h, header.iter().map(|s| s.to_string()).collect::<Vec<_>>());
        assert_eq!(r.len(), rows.len());
        for (a, b) in r.iter().zip(&rows) {
            for (x, y) in a.iter().zip(b) {
                assert!(x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan()), "{x} vs {y}");
            }
        }
        // no temporary file left behind
        let leftovers: Vec<_> = std::fs::read_dir(test_dir())
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().starts_with(".table.csv.tmp-"))
            .collect();
        assert!(leftovers.is_empty());
    }

    #[test]
    fn csv_columns_and_bad_rows() {
        let path = test_dir().join("cols.csv");
        write_csv_columns(&path, &["a", "b"], &[&[1.0, 2.0], &[3.0, 4.0]]).unwrap();
        let (_, r) = read_csv(&path).unwrap();
        assert_eq!(r, vec![vec![1.0, 3.0], vec![2.0, 4.0]]);
        assert!(write_csv_columns(&path, &["a", "b"], &[&[1.0, 2.0], &[3.0]]).is_err());
        assert!(write_csv(&test_dir().join("bad.csv"), &["a", "b"], &[vec![1.0]]).is_err());
        assert!(!test_dir().join("bad.csv").exists());
    }
}
