//! Axes and ticks: linear and log scales, tick placement and labels, frame, grid.
use super::*;
use crate::error::Error;

#[derive(Clone, Debug)]
pub(super) struct Axis {
    pub(super) lo: f64,
    pub(super) hi: f64,
    pub(super) log: bool,
    /// pixel of `lo` and of `hi`
    pub(super) p0: f64,
    pub(super) p1: f64,
    /// wanted number of tick intervals (linear)
    pub(super) target: usize,
}

pub(super) struct Tick {
    pub(super) v: f64,
    pub(super) label: Option<String>,
    pub(super) major: bool,
}

impl Axis {
    pub(super) fn t(&self, v: f64) -> f64 {
        if self.log {
            v.log10()
        } else {
            v
        }
    }
    pub(super) fn px(&self, v: f64) -> f64 {
        let (a, b) = (self.t(self.lo), self.t(self.hi));
        self.p0 + (self.t(v) - a) / (b - a) * (self.p1 - self.p0)
    }
    /// pixels per data unit (linear axes)
    pub(super) fn scale(&self) -> f64 {
        (self.p1 - self.p0) / (self.hi - self.lo)
    }
    pub(super) fn ticks(&self) -> Vec<Tick> {
        if self.log && self.hi / self.lo > 3.0 {
            log_ticks(self.lo, self.hi)
        } else {
            linear_ticks(self.lo, self.hi, self.target)
        }
    }
}

/// Step 1, 2 or 5 x 10^k giving the number of intervals closest to `target`.
pub(super) fn nice_step(range: f64, target: usize) -> f64 {
    let e = 10f64.powf((range / target as f64).log10().floor());
    let mut best = (f64::INFINITY, e);
    for k in [0.1, 1.0, 10.0] {
        for m in [1.0, 2.0, 5.0] {
            let step = m * k * e;
            let d = (range / step - target as f64).abs();
            if d < best.0 {
                best = (d, step);
            }
        }
    }
    best.1
}

pub(super) fn linear_ticks(lo: f64, hi: f64, target: usize) -> Vec<Tick> {
    let step = nice_step(hi - lo, target);
    let maxabs = lo.abs().max(hi.abs());
    let mut out = Vec::new();
    let mut k = (lo / step - 1e-9).ceil();
    while k * step <= hi + 1e-9 * step {
        let v = k * step;
        let v = if v.abs() < 1e-12 * step { 0.0 } else { v };
        out.push(Tick { v, label: Some(format_linear(v, step, maxabs)), major: true });
        k += 1.0;
    }
    out
}

/// Label of a linear tick: fixed notation for moderate magnitudes, else mantissa and exponent.
pub(super) fn format_linear(v: f64, step: f64, maxabs: f64) -> String {
    if v == 0.0 {
        return "0".to_string();
    }
    let es = step.log10().floor() as i32;
    let em = maxabs.log10().floor() as i32;
    if em < 5 && es >= -4 {
        let d = (-es).max(0) as usize;
        format!("{v:.d$}")
    } else {
        let d = (em - es).max(0) as usize;
        format!("{:.d$}e{em}", v / 10f64.powi(em))
    }
}

pub(super) fn superscript(n: i32) -> String {
    pub(super) const SUP: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
    let mut s = String::new();
    if n < 0 {
        s.push('⁻');
    }
    for c in n.unsigned_abs().to_string().chars() {
        s.push(SUP[c.to_digit(10).unwrap() as usize]);
    }
    s
}

pub(super) fn format_short(v: f64) -> String {
    let a = v.abs();
    if (1e-3..1e5).contains(&a) {
        let s = format!("{v:.4}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{v:.0e}")
    }
}

pub(super) fn log_ticks(lo: f64, hi: f64) -> Vec<Tick> {
    let e0 = lo.log10().floor() as i32;
    let e1 = hi.log10().ceil() as i32;
    let inside = |v: f64| v >= lo * (1.0 - 1e-9) && v <= hi * (1.0 + 1e-9);
    let nmajor = (e0..=e1).filter(|&e| inside(10f64.powi(e))).count();
    let every = (nmajor as i32 + 7) / 8; // at most about 8 labelled decades
    let label_minor = nmajor < 3;
    let label_all_minor = nmajor == 0;
    let mut out = Vec::new();
    for e in e0..=e1 {
        let d = 10f64.powi(e);
        if inside(d) {
            let label = (e.rem_euclid(every.max(1)) == 0).then(|| format!("10{}", superscript(e)));
            out.push(Tick { v: d, label, major: true });
        }
        if every <= 1 {
            for j in 2..10 {
                let v = j as f64 * d;
                if inside(v) {
                    let label = (label_all_minor || (label_minor && (j == 2 || j == 5))).then(|| format_short(v));
                    out.push(Tick { v, label, major: false });
                }
            }
        }
    }
    out
}

pub(super) fn data_range(vals: impl Iterator<Item = f64>, log: bool, pad: f64) -> Option<(f64, f64)> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in vals {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if lo > hi {
        return None;
    }
    if log {
        let (a, b) = (lo.log10(), hi.log10());
        let (a, b) = if b - a < 1e-12 { (a - 0.5, b + 0.5) } else { (a - pad * (b - a), b + pad * (b - a)) };
        Some((10f64.powf(a), 10f64.powf(b)))
    } else {
        let span = hi - lo;
        if span <= 1e-14 * lo.abs().max(hi.abs()) || span == 0.0 {
            let d = if lo == 0.0 { 1.0 } else { 0.1 * lo.abs() };
            Some((lo - d, hi + d))
        } else {
            Some((lo - pad * span, hi + pad * span))
        }
    }
}

pub(super) fn check_range(r: (f64, f64), log: bool, what: &str) -> Result<(f64, f64), Error> {
    if !r.0.is_finite() || !r.1.is_finite() || r.0 >= r.1 || (log && r.0 <= 0.0) {
        return Err(Error::invalid(format!("invalid {what} range {:?}", r)));
    }
    Ok(r)
}

pub(super) fn max_label_width(ticks: &[Tick], size: f64) -> i32 {
    ticks.iter().filter_map(|t| t.label.as_ref()).map(|l| text_size(l, size).0).max().unwrap_or(0)
}

/// Plot box in pixels: left, top, right, bottom.
#[derive(Clone, Copy, Debug)]
pub(super) struct BoxPx {
    pub(super) l: i32,
    pub(super) t: i32,
    pub(super) r: i32,
    pub(super) b: i32,
}

/// Light grid lines at the ticks (drawn under the data).
pub(super) fn draw_grid(cv: &mut Canvas, bx: BoxPx, x: &Axis, y: &Axis) {
    for t in x.ticks() {
        let p = x.px(t.v).round() as i32;
        if p > bx.l && p < bx.r {
            cv.vline(p, bx.t, bx.b, if t.major { (220, 220, 220) } else { (240, 240, 240) });
        }
    }
    for t in y.ticks() {
        let p = y.px(t.v).round() as i32;
        if p > bx.t && p < bx.b {
            cv.hline(bx.l, bx.r, p, if t.major { (220, 220, 220) } else { (240, 240, 240) });
        }
    }
}

/// Vertical tick marks and labels on the left or right side at pixel column `x0`; returns
/// the width of the widest label.
pub(super) fn y_ticks(cv: &mut Canvas, ax: &Axis, x0: i32, right: bool, bx: BoxPx) -> i32 {
    let mut maxw = 0;
    for t in ax.ticks() {
        let p = ax.px(t.v).round() as i32;
        if p < bx.t || p > bx.b {
            continue;
        }
        let len = if t.major { TICK_LEN } else { TICK_LEN / 2 };
        if right {
            cv.hline(x0, x0 + len, p, BLACK);
        } else {
            cv.hline(x0 - len, x0, p, BLACK);
        }
        if let Some(l) = &t.label {
            let (xx, hp) = if right { (x0 + TICK_LEN + 5, HPos::Left) } else { (x0 - TICK_LEN - 5, HPos::Right) };
            cv.text(l, xx, p, TICK_SIZE, hp, VPos::Center, false);
            maxw = maxw.max(text_size(l, TICK_SIZE).0);
        }
    }
    maxw
}

/// Frame, tick marks and labels of x (bottom), y (left) and optionally y2 (right).
pub(super) fn draw_frame(cv: &mut Canvas, bx: BoxPx, x: &Axis, y: &Axis, y2: Option<&Axis>, labels: (&str, &str, &str)) {
    cv.rect_outline(bx.l, bx.t, bx.r, bx.b, BLACK);
    let mut max_h = 0;
    for t in x.ticks() {
        let p = x.px(t.v).round() as i32;
        if p < bx.l || p > bx.r {
            continue;
        }
        cv.vline(p, bx.b, bx.b + if t.major { TICK_LEN } else { TICK_LEN / 2 }, BLACK);
        if let Some(l) = &t.label {
            cv.text(l, p, bx.b + TICK_LEN + 4, TICK_SIZE, HPos::Center, VPos::Top, false);
            max_h = max_h.max(text_size(l, TICK_SIZE).1);
        }
    }
    let (cx, cy) = ((bx.l + bx.r) / 2, (bx.t + bx.b) / 2);
    cv.text(labels.0, cx, bx.b + TICK_LEN + 4 + max_h + 10, LABEL_SIZE, HPos::Center, VPos::Top, false);
    let wy = y_ticks(cv, y, bx.l, false, bx);
    cv.text(labels.1, bx.l - TICK_LEN - 5 - wy - 12, cy, LABEL_SIZE, HPos::Center, VPos::Bottom, true);
    if let Some(y2) = y2 {
        let w2 = y_ticks(cv, y2, bx.r, true, bx);
        cv.text(labels.2, bx.r + TICK_LEN + 5 + w2 + 12, cy, LABEL_SIZE, HPos::Center, VPos::Top, true);
    }
}

/// Dashed circle (cx, cy, r) in data units, clipped to the box.
pub(super) fn draw_circle(cv: &mut Canvas, x: &Axis, y: &Axis, c: (f64, f64, f64), bx: BoxPx) {
    cv.dashed_ellipse(x.px(c.0), y.px(c.1), c.2 * x.scale().abs(), c.2 * y.scale().abs(), bx);
}

pub(super) fn check_finite(vals: impl IntoIterator<Item = f64>, what: &str) -> Result<(), Error> {
    match vals.into_iter().enumerate().find(|(_, v)| !v.is_finite()) {
        Some((i, v)) => Err(Error::invalid(format!("{what}: value {i} is {v} (all plot data must be finite)"))),
        None => Ok(()),
    }
}

pub(super) fn title_band(title: &str) -> i32 {
    if title.is_empty() {
        20
    } else {
        text_size(title, TITLE_SIZE).1 + 30
    }
}
