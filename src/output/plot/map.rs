//! Colour maps of a scalar field on a triangle mesh, with colour bar.
use super::*;
use crate::error::Error;

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
) -> Result<(), Error> {
    ensure_font()?;
    check_size(opts.width, opts.height)?;
    if tris.is_empty() {
        return Err(Error::invalid("map_plot: no triangles"));
    }
    if tris.len() != values.len() {
        return Err(Error::invalid(format!("map_plot: {} triangles but {} value triples", tris.len(), values.len())));
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

    let (w, h) = (opts.width as i32, opts.height as i32);
    let mut x = Axis { lo: xr.0, hi: xr.1, log: false, p0: 0.0, p1: 1.0, target: 6 };
    let mut y = Axis { lo: yr.0, hi: yr.1, log: false, p0: 1.0, p1: 0.0, target: 6 };
    let cb_ticks = linear_ticks(vlo, vhi, 8);
    let label_h = text_size("Xg", LABEL_SIZE).1;
    let tick_h = text_size("0", TICK_SIZE).1;
    let (cb_gap, cb_w) = (25, 24);
    let left = 15 + if ylabel.is_empty() { 0 } else { label_h + 12 } + max_label_width(&y.ticks(), TICK_SIZE) + TICK_LEN + 5;
    let right = 15
        + if opts.colorbar_label.is_empty() { 0 } else { label_h + 12 }
        + max_label_width(&cb_ticks, TICK_SIZE)
        + TICK_LEN
        + 5
        + cb_w
        + cb_gap;
    let top = title_band(title);
    let bottom = TICK_LEN + 4 + tick_h + if xlabel.is_empty() { 0 } else { 10 + label_h } + 15;
    let avail = BoxPx { l: left, t: top, r: w - right, b: h - bottom };
    if avail.r - avail.l < 50 || avail.b - avail.t < 50 {
        return Err(Error::invalid(format!("map_plot: {w}x{h} pixels is too small for the labels")));
    }
    let min_w = text_size(title, TITLE_SIZE).0 + 40;
    let (bx, w, h) = fit_box(avail, xr, yr, opts.equal_aspect, w, h, min_w);
    let mut cv = Canvas::new(w as u32, h as u32)?;
    x.p0 = bx.l as f64;
    x.p1 = bx.r as f64;
    y.p0 = bx.b as f64;
    y.p1 = bx.t as f64;

    // raster the triangles: pixel centres inside the box, barycentric interpolation
    let vnorm = |v: f64| (v - vlo) / (vhi - vlo);
    for (tri, val) in tris.iter().zip(values) {
        let p: Vec<(f64, f64)> = tri.iter().map(|q| (x.px(q[0]), y.px(q[1]))).collect();
        let det = (p[1].0 - p[0].0) * (p[2].1 - p[0].1) - (p[2].0 - p[0].0) * (p[1].1 - p[0].1);
        if det.abs() < 1e-12 {
            continue;
        }
        let xmin = p.iter().map(|q| q.0).fold(f64::INFINITY, f64::min).floor().max(bx.l as f64) as i32;
        let xmax = p.iter().map(|q| q.0).fold(f64::NEG_INFINITY, f64::max).ceil().min(bx.r as f64 - 1.0) as i32;
        let ymin = p.iter().map(|q| q.1).fold(f64::INFINITY, f64::min).floor().max(bx.t as f64) as i32;
        let ymax = p.iter().map(|q| q.1).fold(f64::NEG_INFINITY, f64::max).ceil().min(bx.b as f64 - 1.0) as i32;
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
    check_finite(opts.edges.iter().flatten().flatten().copied(), "map_plot: edges")?;
    for e in &opts.edges {
        cv.stroke(&[(x.px(e[0][0]), y.px(e[0][1])), (x.px(e[1][0]), y.px(e[1][1]))], 0.6, (30, 30, 30), bx);
    }
    if let Some(c) = opts.circle {
        draw_circle(&mut cv, &x, &y, c, bx);
    }
    check_finite(opts.markers.iter().flat_map(|(p, _)| *p), "map_plot: markers")?;
    for (p, label) in &opts.markers {
        let (px, py) = (x.px(p[0]), y.px(p[1]));
        if px < bx.l as f64 || px > bx.r as f64 || py < bx.t as f64 || py > bx.b as f64 {
            continue;
        }
        cv.disc(px, py, MARKER_RADIUS + 1.5, WHITE, bx);
        cv.disc(px, py, MARKER_RADIUS, BLACK, bx);
        // The label on a white band beside the dot (right of it, or left near the box's
        // right edge), so that it reads on any colour.
        let (tw, th) = text_size(label, TICK_SIZE);
        let gap = MARKER_RADIUS as i32 + 5;
        let right = px.round() as i32 + gap;
        let lx = if right + tw + 2 <= bx.r { right } else { px.round() as i32 - gap - tw };
        let ly = py.round() as i32;
        cv.fill_rect(lx - 2, ly - th / 2 - 1, lx + tw + 2, ly + th / 2 + 1, WHITE);
        cv.text(label, lx, ly, TICK_SIZE, HPos::Left, VPos::Center, false);
    }
    // colour bar
    let cb = BoxPx { l: bx.r + cb_gap, t: bx.t, r: bx.r + cb_gap + cb_w, b: bx.b };
    for py in cb.t..cb.b {
        let t = (cb.b as f64 - (py as f64 + 0.5)) / (cb.b - cb.t) as f64;
        for px in cb.l..cb.r {
            cv.set(px, py, cmap(t));
        }
    }
    cv.rect_outline(cb.l, cb.t, cb.r, cb.b, BLACK);
    let cbax = Axis { lo: vlo, hi: vhi, log: false, p0: cb.b as f64, p1: cb.t as f64, target: 8 };
    let maxw = y_ticks(&mut cv, &cbax, cb.r, true, cb);

    cv.text(title, w / 2, 15, TITLE_SIZE, HPos::Center, VPos::Top, false);
    draw_frame(&mut cv, bx, &x, &y, None, (xlabel, ylabel, ""));
    let cbl = cb.r + TICK_LEN + 5 + maxw + 12;
    cv.text(&opts.colorbar_label, cbl, (cb.t + cb.b) / 2, LABEL_SIZE, HPos::Center, VPos::Top, true);
    cv.save(path)
}
