//! Line plots: series on linear or log axes, secondary y axis, legend.
use super::*;
use crate::error::Error;

/// Line/point plot of one or more series, optionally with log axes and a secondary y axis.
pub fn line_plot(path: &Path, title: &str, xlabel: &str, ylabel: &str, series: &[Series], opts: &LineOpts) -> Result<(), Error> {
    ensure_font()?;
    check_size(opts.width, opts.height)?;
    if series.is_empty() || series.iter().all(|s| s.x.is_empty()) {
        return Err(Error::invalid("line_plot: no data"));
    }
    for s in series {
        if s.x.len() != s.y.len() {
            return Err(Error::invalid(format!("line_plot: series '{}' has {} x and {} y values", s.label, s.x.len(), s.y.len())));
        }
        check_finite(s.x.iter().copied(), &format!("line_plot: series '{}' x", s.label))?;
        check_finite(s.y.iter().copied(), &format!("line_plot: series '{}' y", s.label))?;
        let logy = if s.secondary { opts.log_y2 } else { opts.log_y };
        if opts.log_x && s.x.iter().any(|&v| v <= 0.0) {
            return Err(Error::invalid(format!("line_plot: series '{}' has x <= 0 on a log axis", s.label)));
        }
        if logy && s.y.iter().any(|&v| v <= 0.0) {
            return Err(Error::invalid(format!("line_plot: series '{}' has y <= 0 on a log axis", s.label)));
        }
    }
    let has_y2 = series.iter().any(|s| s.secondary);
    let markers = series.iter().any(|s| s.style != Style::Line);
    let xr = match opts.x_range {
        Some(r) => check_range(r, opts.log_x, "x")?,
        None => data_range(series.iter().flat_map(|s| s.x.iter().copied()), opts.log_x, if markers { 0.03 } else { 0.0 }).unwrap(),
    };
    let yr_of = |sec: bool, log: bool, given: Option<(f64, f64)>, what: &str| -> Result<(f64, f64), Error> {
        match given {
            Some(r) => check_range(r, log, what),
            None => Ok(data_range(series.iter().filter(|s| s.secondary == sec).flat_map(|s| s.y.iter().copied()), log, 0.05)
                .unwrap_or((if log { 1.0 } else { 0.0 }, if log { 10.0 } else { 1.0 }))),
        }
    };
    let yr = yr_of(false, opts.log_y, opts.y_range, "y")?;
    let y2r = yr_of(true, opts.log_y2, opts.y2_range, "y2")?;

    let (w, h) = (opts.width as i32, opts.height as i32);
    let mut x = Axis { lo: xr.0, hi: xr.1, log: opts.log_x, p0: 0.0, p1: 1.0, target: 8 };
    let mut y = Axis { lo: yr.0, hi: yr.1, log: opts.log_y, p0: 1.0, p1: 0.0, target: 6 };
    let mut y2 = Axis { lo: y2r.0, hi: y2r.1, log: opts.log_y2, p0: 1.0, p1: 0.0, target: 6 };
    let label_h = text_size("Xg", LABEL_SIZE).1;
    let tick_h = text_size("0", TICK_SIZE).1;
    let left = 15 + if ylabel.is_empty() { 0 } else { label_h + 12 } + max_label_width(&y.ticks(), TICK_SIZE) + TICK_LEN + 5;
    let right = if has_y2 {
        15 + if opts.y2label.is_empty() { 0 } else { label_h + 12 } + max_label_width(&y2.ticks(), TICK_SIZE) + TICK_LEN + 5
    } else {
        max_label_width(&x.ticks(), TICK_SIZE) / 2 + 20
    };
    let top = title_band(title);
    let bottom = TICK_LEN + 4 + tick_h + if xlabel.is_empty() { 0 } else { 10 + label_h } + 15;
    let bx = BoxPx { l: left, t: top, r: w - right, b: h - bottom };
    if bx.r - bx.l < 50 || bx.b - bx.t < 50 {
        return Err(Error::invalid(format!("line_plot: {w}x{h} pixels is too small for the labels")));
    }
    x.p0 = bx.l as f64;
    x.p1 = bx.r as f64;
    for a in [&mut y, &mut y2] {
        a.p0 = bx.b as f64;
        a.p1 = bx.t as f64;
    }

    let mut cv = Canvas::new(opts.width, opts.height)?;
    cv.text(title, w / 2, 15, TITLE_SIZE, HPos::Center, VPos::Top, false);
    if opts.grid {
        draw_grid(&mut cv, bx, &x, &y);
    }
    let inner = BoxPx { l: bx.l + 1, t: bx.t + 1, r: bx.r - 1, b: bx.b - 1 };
    let mut entries = Vec::new();
    for (i, s) in series.iter().enumerate() {
        let c = s.color.unwrap_or(PALETTE[i % PALETTE.len()]);
        let ya = if s.secondary { &y2 } else { &y };
        let pts: Vec<(f64, f64)> = s.x.iter().zip(&s.y).map(|(&a, &b)| (x.px(a), ya.px(b))).collect();
        if matches!(s.style, Style::Line | Style::LinePoints) {
            cv.stroke(&pts, 2.2, c, inner);
        }
        if matches!(s.style, Style::Points | Style::LinePoints) {
            for p in &pts {
                cv.disc(p.0, p.1, 4.0, c, inner);
            }
        }
        if !s.label.is_empty() {
            let label = if s.secondary && has_y2 { format!("{} (right axis)", s.label) } else { s.label.clone() };
            entries.push((label, c, s.style));
        }
    }
    draw_frame(&mut cv, bx, &x, &y, has_y2.then_some(&y2), (xlabel, ylabel, &opts.y2label));
    draw_legend(&mut cv, bx, opts.legend, &entries);
    cv.save(path)
}

pub(super) fn draw_legend(cv: &mut Canvas, bx: BoxPx, pos: Legend, entries: &[(String, Rgb, Style)]) {
    if pos == Legend::None || entries.is_empty() {
        return;
    }
    let row = text_size("Xg", TICK_SIZE).1 + 8;
    let sample = 34;
    let lw = entries.iter().map(|e| text_size(&e.0, TICK_SIZE).0).max().unwrap_or(0);
    let (bw, bh) = (10 + sample + 8 + lw + 12, 8 + row * entries.len() as i32 + 4);
    let (x0, y0) = match pos {
        Legend::UpperRight => (bx.r - 10 - bw, bx.t + 10),
        Legend::UpperLeft => (bx.l + 10, bx.t + 10),
        Legend::LowerRight => (bx.r - 10 - bw, bx.b - 10 - bh),
        Legend::LowerLeft | Legend::None => (bx.l + 10, bx.b - 10 - bh),
    };
    cv.fill_rect(x0, y0, x0 + bw, y0 + bh, WHITE);
    cv.rect_outline(x0, y0, x0 + bw, y0 + bh, (160, 160, 160));
    let full = cv.full();
    for (i, (label, c, style)) in entries.iter().enumerate() {
        let cy = y0 + 6 + row * i as i32 + row / 2;
        let (sx0, sx1) = (x0 + 10, x0 + 10 + sample);
        if matches!(style, Style::Line | Style::LinePoints) {
            cv.stroke(&[(sx0 as f64, cy as f64 + 0.5), (sx1 as f64, cy as f64 + 0.5)], 2.2, *c, full);
        }
        if matches!(style, Style::Points | Style::LinePoints) {
            cv.disc((sx0 + sx1) as f64 / 2.0, cy as f64 + 0.5, 4.0, *c, full);
        }
        cv.text(label, sx1 + 8, cy, TICK_SIZE, HPos::Left, VPos::Center, false);
    }
}
