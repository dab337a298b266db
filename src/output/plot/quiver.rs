//! Quiver (arrow) plots of a vector field.
use super::*;
use crate::error::Error;

pub(super) fn draw_arrow(cv: &mut Canvas, tail: (f64, f64), tip: (f64, f64), c: Rgb, width: f64, clip: BoxPx) {
    let (dx, dy) = (tip.0 - tail.0, tip.1 - tail.1);
    let len = (dx * dx + dy * dy).sqrt();
    if len < 1.0 {
        return;
    }
    let (ux, uy) = (dx / len, dy / len);
    let head = (0.35 * len).clamp(3.0, 11.0);
    let half = 0.45 * head;
    let base = (tip.0 - head * ux, tip.1 - head * uy);
    cv.stroke(&[tail, (base.0 + 0.5 * ux, base.1 + 0.5 * uy)], width, c, clip);
    cv.triangle([tip, (base.0 - half * uy, base.1 + half * ux), (base.0 + half * uy, base.1 - half * ux)], c, clip);
}

/// Arrow plot of a vector field: each entry is `[x, y, u, v]`; arrows are centred on (x, y).
/// A reference arrow with its length in `opts.unit` is drawn under the plot.
pub fn quiver_plot(path: &Path, title: &str, xlabel: &str, ylabel: &str, arrows: &[[f64; 4]], opts: &QuiverOpts) -> Result<(), Error> {
    ensure_font()?;
    check_size(opts.width, opts.height)?;
    if arrows.is_empty() {
        return Err(Error::invalid("quiver_plot: no arrows"));
    }
    check_finite(arrows.iter().flatten().copied(), "quiver_plot: arrows")?;
    if let Some(c) = opts.circle {
        check_finite([c.0, c.1, c.2], "quiver_plot: circle")?;
    }
    let xr0 = data_range(arrows.iter().map(|a| a[0]), false, 0.0).unwrap();
    let yr0 = data_range(arrows.iter().map(|a| a[1]), false, 0.0).unwrap();
    let spacing = (((xr0.1 - xr0.0) * (yr0.1 - yr0.0)) / arrows.len() as f64).sqrt();
    let spacing = if spacing > 0.0 { spacing } else { 0.05 * (xr0.1 - xr0.0).max(yr0.1 - yr0.0) };
    let xr = match opts.x_range {
        Some(r) => check_range(r, false, "x")?,
        None => (xr0.0 - 0.6 * spacing, xr0.1 + 0.6 * spacing),
    };
    let yr = match opts.y_range {
        Some(r) => check_range(r, false, "y")?,
        None => (yr0.0 - 0.6 * spacing, yr0.1 + 0.6 * spacing),
    };
    let vmax = arrows.iter().map(|a| a[2].hypot(a[3])).fold(0.0, f64::max);
    let scale = match opts.scale {
        Some(s) if s.is_finite() && s > 0.0 => s,
        Some(s) => return Err(Error::invalid(format!("quiver_plot: invalid scale {s}"))),
        None if vmax > 0.0 => 0.9 * spacing / vmax,
        None => 1.0,
    };
    let reference = match opts.reference {
        Some(r) if r.is_finite() && r > 0.0 => r,
        Some(r) => return Err(Error::invalid(format!("quiver_plot: invalid reference length {r}"))),
        None if vmax > 0.0 => {
            let e = 10f64.powf(vmax.log10().floor());
            let m = vmax / e;
            (if m >= 5.0 {
                5.0
            } else if m >= 2.0 {
                2.0
            } else {
                1.0
            }) * e
        }
        None => 1.0,
    };

    let (w, h) = (opts.width as i32, opts.height as i32);
    let mut x = Axis { lo: xr.0, hi: xr.1, log: false, p0: 0.0, p1: 1.0, target: 6 };
    let mut y = Axis { lo: yr.0, hi: yr.1, log: false, p0: 1.0, p1: 0.0, target: 6 };
    let label_h = text_size("Xg", LABEL_SIZE).1;
    let tick_h = text_size("0", TICK_SIZE).1;
    let left = 15 + if ylabel.is_empty() { 0 } else { label_h + 12 } + max_label_width(&y.ticks(), TICK_SIZE) + TICK_LEN + 5;
    let right = max_label_width(&x.ticks(), TICK_SIZE) / 2 + 25;
    let top = title_band(title);
    let ref_row = tick_h + 20;
    let bottom = TICK_LEN + 4 + tick_h + if xlabel.is_empty() { 0 } else { 10 + label_h } + 15 + ref_row;
    let avail = BoxPx { l: left, t: top, r: w - right, b: h - bottom };
    if avail.r - avail.l < 50 || avail.b - avail.t < 50 {
        return Err(Error::invalid(format!("quiver_plot: {w}x{h} pixels is too small for the labels")));
    }
    let min_w = text_size(title, TITLE_SIZE).0 + 40;
    let (bx, w, h) = fit_box(avail, xr, yr, opts.equal_aspect, w, h, min_w);
    let mut cv = Canvas::new(w as u32, h as u32)?;
    x.p0 = bx.l as f64;
    x.p1 = bx.r as f64;
    y.p0 = bx.b as f64;
    y.p1 = bx.t as f64;
    let (sx, sy) = (x.scale(), y.scale()); // pixels per data unit (sy < 0)
    let color = (20, 40, 120);
    let width = if arrows.len() > 400 { 1.2 } else { 1.8 };

    if let Some(c) = opts.circle {
        draw_circle(&mut cv, &x, &y, c, bx);
    }
    for a in arrows {
        let (cx, cy) = (x.px(a[0]), y.px(a[1]));
        let (dx, dy) = (0.5 * scale * a[2] * sx, 0.5 * scale * a[3] * sy);
        draw_arrow(&mut cv, (cx - dx, cy - dy), (cx + dx, cy + dy), color, width, bx);
    }
    cv.text(title, w / 2, 15, TITLE_SIZE, HPos::Center, VPos::Top, false);
    draw_frame(&mut cv, bx, &x, &y, None, (xlabel, ylabel, ""));
    // reference arrow, bottom right under the plot
    let len = scale * reference * sx;
    let yy = (h - 15 - ref_row / 2) as f64 + 0.5;
    let x1 = bx.r as f64;
    let full = cv.full();
    draw_arrow(&mut cv, (x1 - len, yy), (x1, yy), color, 1.8, full);
    let label = format!("{} {}", format_short(reference), opts.unit);
    cv.text(label.trim(), (x1 - len).round() as i32 - 10, yy as i32, TICK_SIZE, HPos::Right, VPos::Center, false);
    cv.save(path)
}
