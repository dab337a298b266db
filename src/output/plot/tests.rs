//! Tests of the plots: pixels of the written PNG files.
use super::*;
use std::path::PathBuf;

fn test_dir() -> PathBuf {
    let d = Path::new(env!("CARGO_MANIFEST_DIR")).join("target").join("test-output").join("plot");
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Decodes a PNG; checks the signature and returns (width, height, RGB pixels).
fn read_png(path: &Path) -> (u32, u32, Vec<u8>) {
    let bytes = std::fs::read(path).unwrap();
    assert!(bytes.len() > 1000, "{} is too small", path.display());
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    let dec = png::Decoder::new(std::io::Cursor::new(bytes));
    let mut reader = dec.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgb);
    buf.truncate(info.buffer_size());
    (info.width, info.height, buf)
}

fn pixel(img: &(u32, u32, Vec<u8>), x: u32, y: u32) -> Rgb {
    let i = 3 * (y * img.0 + x) as usize;
    (img.2[i], img.2[i + 1], img.2[i + 2])
}

/// Triangulated square [-a, a]^2 with n x n cells, each cut into two triangles.
fn square_mesh(a: f64, n: usize, f: impl Fn(f64, f64) -> f64) -> (Vec<[[f64; 2]; 3]>, Vec<[f64; 3]>) {
    let (mut tris, mut vals) = (Vec::new(), Vec::new());
    let c = |i: usize| -a + 2.0 * a * i as f64 / n as f64;
    for i in 0..n {
        for j in 0..n {
            let p = [[c(i), c(j)], [c(i + 1), c(j)], [c(i + 1), c(j + 1)], [c(i), c(j + 1)]];
            for t in [[p[0], p[1], p[2]], [p[0], p[2], p[3]]] {
                vals.push([f(t[0][0], t[0][1]), f(t[1][0], t[1][1]), f(t[2][0], t[2][1])]);
                tris.push(t);
            }
        }
    }
    (tris, vals)
}

#[test]
fn font_loads_or_names_the_package() {
    let e = load_font("/nonexistent/DejaVuSans.ttf").err().unwrap().to_string();
    assert!(e.contains("fonts-dejavu-core"), "{e}");
    let e = load_font("/etc/hostname").err().unwrap().to_string();
    assert!(e.contains("not a valid TrueType"), "{e}");
    ensure_font().unwrap();
    let (w, h) = text_size("Pressure p [GPa]", LABEL_SIZE);
    assert!(w > 50 && h > 10, "{w}x{h}");
}

#[test]
fn hertz_pressure_map() {
    let (tris, vals) = square_mesh(3.0, 60, |x, y| (1.0 - x * x - y * y).max(0.0).sqrt());
    let path = test_dir().join("map_hertz.png");
    let opts = MapOpts { circle: Some((0.0, 0.0, 1.0)), colorbar_label: "p / p_H".to_string(), ..Default::default() };
    map_plot(&path, "Hertz pressure", "x / a", "y / a", &tris, &vals, &opts).unwrap();
    let img = read_png(&path);
    assert!(img.0 <= opts.width && img.1 <= opts.height && img.0 >= 500 && img.1 >= 300, "{}x{}", img.0, img.1);
    // find the plot box centre: the map is square (equal aspect); its centre is p = 1 (yellow)
    // and a corner region is p = 0 (dark purple). Locate by colour rather than layout.
    let yellow = (0..img.1).flat_map(|y| (0..img.0).map(move |x| (x, y))).filter(|&(x, y)| pixel(&img, x, y) == viridis(1.0)).count();
    let purple = (0..img.1).flat_map(|y| (0..img.0).map(move |x| (x, y))).filter(|&(x, y)| pixel(&img, x, y) == viridis(0.0)).count();
    assert!(yellow > 0 && purple > 10 * yellow, "yellow {yellow}, purple {purple}");
    // the title is drawn: dark pixels in the top band
    let dark = (0..40).flat_map(|y| (0..img.0).map(move |x| (x, y))).filter(|&(x, y)| pixel(&img, x, y).0 < 80).count();
    assert!(dark > 100, "{dark} dark pixels in the title band");
}

#[test]
fn a_marker_is_drawn_at_its_point_with_its_label() {
    // A uniform field: every pixel of the plot box has one colour, except what the marker
    // covers. The box's centre (the centroid of that colour without the marker) is where
    // the marker at (0, 0) must be black; its label adds dark pixels to the right of it.
    let (tris, vals) = square_mesh(1.0, 10, |_, _| 0.5);
    let dir = test_dir();
    let opts = MapOpts { range: Some((0.0, 1.0)), ..Default::default() };
    let with = MapOpts { markers: vec![([0.0, 0.0], "hm".to_string())], ..opts.clone() };
    map_plot(&dir.join("map_plain.png"), "plain", "x", "y", &tris, &vals, &opts).unwrap();
    map_plot(&dir.join("map_marker.png"), "marker", "x", "y", &tris, &vals, &with).unwrap();
    let (plain, marked) = (read_png(&dir.join("map_plain.png")), read_png(&dir.join("map_marker.png")));
    let fill: Vec<(u32, u32)> =
        (0..plain.1).flat_map(|y| (0..plain.0).map(move |x| (x, y))).filter(|&(x, y)| pixel(&plain, x, y) == viridis(0.5)).collect();
    let n = fill.len() as f64;
    let (cx, cy) = (fill.iter().map(|p| p.0 as f64).sum::<f64>() / n, fill.iter().map(|p| p.1 as f64).sum::<f64>() / n);
    let (cx, cy) = (cx.round() as u32, cy.round() as u32);
    assert_eq!(pixel(&plain, cx, cy), viridis(0.5));
    assert_eq!(pixel(&marked, cx, cy), (0, 0, 0), "the dot at the box's centre ({cx}, {cy})");
    let dark_right =
        (cy - 10..cy + 10).flat_map(|y| (cx + 8..cx + 40).map(move |x| (x, y))).filter(|&(x, y)| pixel(&marked, x, y).0 < 80).count();
    assert!(dark_right > 20, "{dark_right} dark pixels of the label right of the dot");
    // A marker outside the visible part is left out.
    let out = MapOpts { markers: vec![([5.0, 0.0], "far".to_string())], ..opts };
    map_plot(&dir.join("map_far.png"), "plain", "x", "y", &tris, &vals, &out).unwrap();
    assert!(read_png(&dir.join("map_far.png")).2 == plain.2, "a marker outside the box changed the image");
}

#[test]
fn diverging_shear_map() {
    // signed field, rectangular domain, not equal aspect
    let (tris, vals) = square_mesh(2.0, 40, |x, y| 3e6 * x * (-(x * x + y * y)).exp());
    let tris: Vec<_> = tris.iter().map(|t| t.map(|p| [p[0], 0.5 * p[1]])).collect();
    let path = test_dir().join("map_shear.png");
    let opts = MapOpts { diverging: true, circle: Some((0.0, 0.0, 0.8)), colorbar_label: "τ_xz [Pa]".to_string(), ..Default::default() };
    map_plot(&path, "Shear stress on the contact plane", "x [mm]", "y [mm]", &tris, &vals, &opts).unwrap();
    let img = read_png(&path);
    assert!(img.0 <= opts.width && img.1 <= opts.height && img.0 >= 500 && img.1 >= 300, "{}x{}", img.0, img.1);
}

#[test]
fn ehl_profile_with_secondary_axis() {
    let n = 400;
    let x: Vec<f64> = (0..n).map(|i| -3.0 + 4.5 * i as f64 / (n - 1) as f64).collect();
    let p: Vec<f64> = x
        .iter()
        .map(|&x| {
            let hz = (1.0 - x * x).max(0.0).sqrt();
            let spike = 0.6 * (-((x - 0.9) / 0.04).powi(2)).exp();
            (hz + spike) * 1.2
        })
        .collect();
    let h: Vec<f64> = x
        .iter()
        .map(|&x| {
            let base = if x.abs() < 1.0 { 0.25 } else { 0.25 + 0.3 * (x.abs() - 1.0).powf(1.5) };
            base - 0.07 * (-((x - 0.85) / 0.08).powi(2)).exp()
        })
        .collect();
    let path = test_dir().join("profile_ehl.png");
    let series = vec![
        Series::new("pressure p", x.clone(), p, Style::Line),
        Series::new("film thickness h", x.clone(), h, Style::Line).on_secondary(),
    ];
    let opts = LineOpts { y2label: "h [µm]".to_string(), legend: Legend::UpperLeft, ..Default::default() };
    line_plot(&path, "Central line profile (y = 0)", "x / a", "p [GPa]", &series, &opts).unwrap();
    let img = read_png(&path);
    assert_eq!((img.0, img.1), (1000, 700));
}

#[test]
fn loglog_convergence() {
    let dofs = [1.2e3, 9.5e3, 7.4e4, 5.9e5, 4.7e6];
    let err: Vec<f64> = dofs.iter().map(|n: &f64| 3.0 * n.powf(-2.0 / 3.0)).collect();
    let err2: Vec<f64> = dofs.iter().map(|n: &f64| 0.5 * n.powf(-1.0 / 3.0)).collect();
    let slope: Vec<f64> = dofs.iter().map(|n: &f64| 1.0 * n.powf(-2.0 / 3.0)).collect();
    let series = vec![
        Series::new("‖p − p_H‖ / p_H", dofs.to_vec(), err, Style::LinePoints),
        Series::new("‖u − u_H‖ / u_H", dofs.to_vec(), err2, Style::LinePoints),
        Series::new("slope −2/3", dofs.to_vec(), slope, Style::Line).with_color((120, 120, 120)),
    ];
    let opts = LineOpts { log_x: true, log_y: true, ..Default::default() };
    let path = test_dir().join("convergence_loglog.png");
    line_plot(&path, "Mesh convergence", "unknowns", "relative error", &series, &opts).unwrap();
    let img = read_png(&path);
    assert_eq!((img.0, img.1), (1000, 700));
    // narrow log range (less than a decade) and log-x only
    let s = vec![Series::new("", vec![200.0, 300.0, 700.0], vec![1.0, 2.0, 1.5], Style::Points)];
    let path = test_dir().join("narrow_logx.png");
    line_plot(&path, "", "n", "y", &s, &LineOpts { log_x: true, width: 600, height: 400, ..Default::default() }).unwrap();
    assert_eq!(read_png(&path).0, 600);
    let t: Vec<String> = log_ticks(200.0, 700.0).into_iter().filter_map(|t| t.label).collect();
    assert_eq!(t, ["200", "300", "400", "500", "600", "700"]);
}

#[test]
fn velocity_quiver() {
    let mut arrows = Vec::new();
    for i in 0..21 {
        for j in 0..21 {
            let (x, y) = (-2.0 + 0.2 * i as f64, -2.0 + 0.2 * j as f64);
            // rolling plus spin about the origin, in m/s
            arrows.push([x, y, 1.5 - 0.4 * y, 0.4 * x]);
        }
    }
    let path = test_dir().join("quiver_velocity.png");
    let opts = QuiverOpts { circle: Some((0.0, 0.0, 1.0)), unit: "m/s".to_string(), ..Default::default() };
    quiver_plot(&path, "Surface velocity", "x / a", "y / a", &arrows, &opts).unwrap();
    let img = read_png(&path);
    assert!(img.0 <= opts.width && img.1 <= opts.height && img.0 >= 500 && img.1 >= 300, "{}x{}", img.0, img.1);
}

#[test]
fn non_finite_and_bad_input_are_rejected() {
    let d = test_dir();
    let bad = [f64::NAN, f64::INFINITY, f64::NEG_INFINITY];
    for (k, b) in bad.iter().enumerate() {
        let s = vec![Series::new("a", vec![1.0, 2.0, 3.0], vec![1.0, *b, 2.0], Style::Line)];
        let p = d.join(format!("bad_line_{k}.png"));
        let e = line_plot(&p, "t", "x", "y", &s, &LineOpts::default()).unwrap_err().to_string();
        assert!(e.contains("finite"), "{e}");
        assert!(!p.exists());
        let tris = [[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]];
        let p = d.join(format!("bad_map_{k}.png"));
        assert!(map_plot(&p, "t", "x", "y", &tris, &[[0.0, 1.0, *b]], &MapOpts::default()).is_err());
        let tris_bad = [[[0.0, 0.0], [*b, 0.0], [0.0, 1.0]]];
        assert!(map_plot(&p, "t", "x", "y", &tris_bad, &[[0.0, 1.0, 2.0]], &MapOpts::default()).is_err());
        assert!(!p.exists());
        let p = d.join(format!("bad_quiver_{k}.png"));
        assert!(quiver_plot(&p, "t", "x", "y", &[[0.0, 0.0, *b, 1.0]], &QuiverOpts::default()).is_err());
        assert!(!p.exists());
    }
    // log axis with a non-positive value; mismatched lengths; empty input
    let s = vec![Series::new("a", vec![1.0, 2.0], vec![1.0, 0.0], Style::Line)];
    assert!(line_plot(&d.join("bad_log.png"), "", "", "", &s, &LineOpts { log_y: true, ..Default::default() }).is_err());
    let s = vec![Series::new("a", vec![1.0, 2.0], vec![1.0], Style::Line)];
    assert!(line_plot(&d.join("bad_len.png"), "", "", "", &s, &LineOpts::default()).is_err());
    assert!(line_plot(&d.join("bad_empty.png"), "", "", "", &[], &LineOpts::default()).is_err());
    assert!(map_plot(&d.join("bad_empty.png"), "", "", "", &[], &[], &MapOpts::default()).is_err());
    // constant data does not panic
    let s = vec![Series::new("c", vec![1.0, 1.0], vec![5.0, 5.0], Style::Points)];
    line_plot(&d.join("constant.png"), "constant", "x", "y", &s, &LineOpts::default()).unwrap();
    let tris = [[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]];
    let o = MapOpts { equal_aspect: false, ..Default::default() };
    map_plot(&d.join("constant_map.png"), "", "", "", &tris, &[[2.0; 3]], &o).unwrap();
}

#[test]
fn tick_labels() {
    let t: Vec<String> = linear_ticks(0.0, 1.0, 6).into_iter().filter_map(|t| t.label).collect();
    assert_eq!(t, ["0", "0.2", "0.4", "0.6", "0.8", "1.0"]);
    let t: Vec<String> = linear_ticks(0.0, 2.5e9, 6).into_iter().filter_map(|t| t.label).collect();
    assert_eq!(t[1], "0.5e9");
    let t: Vec<String> = log_ticks(1e3, 1e7).into_iter().filter_map(|t| t.label).collect();
    assert_eq!(t, ["10³", "10⁴", "10⁵", "10⁶", "10⁷"]);
    let t: Vec<String> = log_ticks(1e-9, 1e-5).into_iter().filter_map(|t| t.label).collect();
    assert_eq!(t[0], "10⁻⁹");
}
