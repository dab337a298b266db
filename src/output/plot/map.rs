//! Colour maps of a scalar field on a triangle mesh, with colour bar.
use super::*;
use plotters::prelude::{BitMapBackend, ChartBuilder, IntoDrawingArea};

/// Plot box for a 2-D field: fills the available space, or the largest box with equal scales;
/// then the canvas (w, h) loses the unused band, keeping at least `min_w` of width.
pub(super) fn fit_box(avail: BoxPx, xr: (f64, f64), yr: (f64, f64), equal: bool, w: i32, h: i32, min_w: i32) -> (BoxPx, i32, i32) {
    if !equal {
        return (avail, w, h);
    }
    let (aw, ah) = ((avail.r - avail.l) as f64, (avail.b - avail.t) as f64);
    let s = (aw / (xr.1 - xr.0)).min(ah / (yr.1 - yr.0));
    let (bw, bh) = ((s * (xr.1 - xr.0)).round() as i32, (s * (yr.1 - yr.0)).round() as i32);
    let (slack_w, slack_h) = (avail.r - avail.l - bw, avail.b - avail.t - bh);
    let new_w = (w - slack_w).max(min_w.min(w));
    let l = avail.l + (new_w - (w - slack_w)) / 2;
    (BoxPx { l, t: avail.t, r: l + bw, b: avail.t + bh }, new_w, h - slack_h)
}

/// Filled colour map of a scalar field given per triangle vertex, linear on each triangle.
pub fn map_plot(
    path: &Path,
    title: &str,
    xlabel: &str,
    ylabel: &str,
    tris: &[[[f64; 2]; 3]],
    values: &[[f64; 3]],
    opts: &MapOpts,
) -> Result<(), String> {
    ensure_font()?;
    check_size(opts.width, opts.height)?;
    if tris.is_empty() {
        return Err("map_plot: no triangles".to_string());
    }
    if tris.len() != values.len() {
        return Err(format!("map_plot: {} triangles but {} value triples", tris.len(), values.len()));
    }
    check_finite(tris.iter().flatten().flatten().copied(), "map_plot: coordinates")?;
    check_finite(values.iter().flatten().copied(), "map_plot: values")?;
    if let Some(c) = opts.circle {
        check_finite([c.0, c.1, c.2], "map_plot: circle")?;
    }
    let xr = match opts.x_range {
        Some(r) => check_range(r, false, "x")?,
        None => data_range(tris.iter().flatten().map(|p| p[0]), false, 0.0).unwrap(),
    };
    let yr = match opts.y_range {
        Some(r) => check_range(r, false, "y")?,
        None => data_range(tris.iter().flatten().map(|p| p[1]), false, 0.0).unwrap(),
    };
    let (vlo, vhi) = match opts.range {
        Some(r) => check_range(r, false, "colour")?,
        None => {
            let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
            for v in values.iter().flatten() {
                lo = lo.min(*v);
                hi = hi.max(*v);
            }
            if opts.diverging {
                let m = lo.abs().max(hi.abs());
                (lo, hi) = (-m, m);
            }
            if hi - lo <= 1e-300 || hi - lo <= 1e-12 * lo.abs().max(hi.abs()) {
                let d = if lo == 0.0 { 1.0 } else { 0.1 * lo.abs() };
                (lo - d, hi + d)
            } else {
                (lo, hi)
            }
        }
    };
    let cmap: fn(f64) -> Rgb = if opts.diverging { blue_white_red } else { viridis };

    let (mut x, mut y) = (Axis::new(xr, false, 6), Axis::new(yr, false, 6));
    let cbax = Axis::new((vlo, vhi), false, 8);
    let (cb_gap, cb_w, cb_area) = (25, 24, y_area(&cbax, &opts.colorbar_label));
    let (left, bottom) = (y_area(&y, ylabel), x_area(xlabel));
    let (w, h) = (opts.width as i32, opts.height as i32);
    let avail = BoxPx { l: 15 + left, t: title_band(title), r: w - 15 - cb_area - cb_w - cb_gap, b: h - 15 - bottom };
    if avail.r - avail.l < 50 || avail.b - avail.t < 50 {
        return Err(format!("map_plot: {w}x{h} pixels is too small for the labels"));
    }
    let min_w = text_size(title, TITLE_SIZE).0 + 40;
    let (bx, w, h) = fit_box(avail, xr, yr, opts.equal_aspect, w, h, min_w);
    let mut cv = Canvas::new(w as u32, h as u32)?;
    let cb = BoxPx { l: bx.r + cb_gap, t: bx.t, r: bx.r + cb_gap + cb_w, b: bx.b };
    check_finite(opts.edges.iter().flatten().flatten().copied(), "map_plot: edges")?;
    let bx = {
        let root = BitMapBackend::with_buffer(&mut cv.buf, (w as u32, h as u32)).into_drawing_area();
        title_text(&root, title)?;
        let mut chart = ChartBuilder::on(&root)
            .margin_top(bx.t)
            .margin_left(bx.l - left)
            .margin_right(w - bx.r)
            .margin_bottom(h - bx.b - bottom)
            .x_label_area_size(bottom)
            .y_label_area_size(left)
            .build_cartesian_2d(x.clone(), y.clone())
            .map_err(pe)?;
        let bx = draw_frame(&root, &mut chart, &mut x, &mut y, (xlabel, ylabel), false)?;
        // colour bar: plotters draws its axis, we fill the gradient below
        let (cbx, cby) = (Axis::new((0.0, 1.0), false, 1), cbax);
        let mut bar = ChartBuilder::on(&root)
            .margin_top(cb.t)
            .margin_left(cb.l)
            .margin_right(w - cb.r - cb_area)
            .margin_bottom(h - cb.b)
            .right_y_label_area_size(cb_area)
            .build_cartesian_2d(cbx.clone(), cby.clone())
            .map_err(pe)?;
        let mut mesh = bar.configure_mesh();
        mesh.disable_mesh()
            .disable_x_axis()
            .label_style(font(TICK_SIZE))
            .axis_desc_style(font(LABEL_SIZE))
            .set_all_tick_mark_size(TICK_LEN);
        if !opts.colorbar_label.is_empty() {
            mesh.y_desc(&opts.colorbar_label);
        }
        mesh.draw().map_err(pe)?;
        frame_rect(&root, cb)?;
        root.present().map_err(pe)?;
        bx
    };
    let inner = |b: BoxPx| BoxPx { l: b.l + 1, t: b.t + 1, r: b.r - 1, b: b.b - 1 };

    // raster the triangles: pixel centres inside the box, barycentric interpolation
    let ib = inner(bx);
    let vnorm = |v: f64| (v - vlo) / (vhi - vlo);
    for (tri, val) in tris.iter().zip(values) {
        let p: Vec<(f64, f64)> = tri.iter().map(|q| (x.px(q[0]), y.px(q[1]))).collect();
        let det = (p[1].0 - p[0].0) * (p[2].1 - p[0].1) - (p[2].0 - p[0].0) * (p[1].1 - p[0].1);
        if det.abs() < 1e-12 {
            continue;
        }
        let xmin = p.iter().map(|q| q.0).fold(f64::INFINITY, f64::min).floor().max(ib.l as f64) as i32;
        let xmax = p.iter().map(|q| q.0).fold(f64::NEG_INFINITY, f64::max).ceil().min(ib.r as f64) as i32;
        let ymin = p.iter().map(|q| q.1).fold(f64::INFINITY, f64::min).floor().max(ib.t as f64) as i32;
        let ymax = p.iter().map(|q| q.1).fold(f64::NEG_INFINITY, f64::max).ceil().min(ib.b as f64) as i32;
        let eps = 1e-9;
        for py in ymin..=ymax {
            for px in xmin..=xmax {
                let (cx, cy) = (px as f64 + 0.5, py as f64 + 0.5);
                let l1 = ((cx - p[0].0) * (p[2].1 - p[0].1) - (p[2].0 - p[0].0) * (cy - p[0].1)) / det;
                let l2 = ((p[1].0 - p[0].0) * (cy - p[0].1) - (cx - p[0].0) * (p[1].1 - p[0].1)) / det;
                let l0 = 1.0 - l1 - l2;
                if l0 >= -eps && l1 >= -eps && l2 >= -eps {
                    let v = l0 * val[0] + l1 * val[1] + l2 * val[2];
                    cv.set(px, py, cmap(vnorm(v)));
                }
            }
        }
    }
    for e in &opts.edges {
        cv.stroke(&[(x.px(e[0][0]), y.px(e[0][1])), (x.px(e[1][0]), y.px(e[1][1]))], 0.6, (30, 30, 30), ib);
    }
    if let Some(c) = opts.circle {
        draw_circle(&mut cv, &x, &y, c, ib);
    }
    let ic = inner(cb);
    for py in ic.t..=ic.b {
        let t = (cb.b as f64 - (py as f64 + 0.5)) / (cb.b - cb.t) as f64;
        cv.fill_rect(ic.l, py, ic.r, py, cmap(t));
    }
    cv.save(path)
}
