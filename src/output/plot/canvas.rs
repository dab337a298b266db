//! Canvas, text, colours: the rasteriser (lines, discs, triangles, Gouraud shading), text
//! with ab_glyph, the colour maps.
use super::*;
use crate::error::{Error, IoAction};

pub(super) type Rgb = (u8, u8, u8);
pub(super) const PALETTE: [Rgb; 10] = [
    (31, 119, 180),
    (255, 127, 14),
    (44, 160, 44),
    (214, 39, 40),
    (148, 103, 189),
    (140, 86, 75),
    (227, 119, 194),
    (127, 127, 127),
    (188, 189, 34),
    (23, 190, 207),
];
pub(super) const TITLE_SIZE: f64 = 24.0;
pub(super) const LABEL_SIZE: f64 = 19.0;
pub(super) const TICK_SIZE: f64 = 16.0;
pub(super) const TICK_LEN: i32 = 6;
/// Radius in pixels of a map's point marker (`MapOpts::markers`).
pub(super) const MARKER_RADIUS: f64 = 3.5;

/// Horizontal anchor of a text.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum HPos {
    Left,
    Center,
    Right,
}
/// Vertical anchor of a text (top or bottom of the ascent-descent box).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum VPos {
    Top,
    Center,
    Bottom,
}

/// A piece of text drawn last (on top); anchored at (x, y) in the text's own frame; `rot`
/// turns it 90 degrees counter-clockwise about the anchor (reads bottom to top).
pub(super) struct TextCmd {
    pub(super) s: String,
    pub(super) x: i32,
    pub(super) y: i32,
    pub(super) size: f64,
    pub(super) h: HPos,
    pub(super) v: VPos,
    pub(super) rot: bool,
}

pub(super) fn check_size(w: u32, h: u32) -> Result<(), Error> {
    if !(200..=10000).contains(&w) || !(150..=10000).contains(&h) {
        return Err(Error::invalid(format!("plot size {w}x{h} out of range (200..10000 x 150..10000)")));
    }
    Ok(())
}

pub(super) const BLACK: Rgb = (0, 0, 0);
pub(super) const WHITE: Rgb = (255, 255, 255);

/// RGB image with a few anti-aliased primitives; text is queued and drawn by [`Canvas::save`].
pub(super) struct Canvas {
    pub(super) w: u32,
    pub(super) h: u32,
    pub(super) buf: Vec<u8>,
    pub(super) texts: Vec<TextCmd>,
}

impl Canvas {
    pub(super) fn new(w: u32, h: u32) -> Result<Canvas, Error> {
        check_size(w, h)?;
        Ok(Canvas { w, h, buf: vec![255; (w * h * 3) as usize], texts: Vec::new() })
    }
    pub(super) fn set(&mut self, x: i32, y: i32, c: Rgb) {
        self.blend(x, y, c, 1.0);
    }
    /// Mixes colour `c` into pixel (x, y) with coverage `a` in [0, 1].
    pub(super) fn blend(&mut self, x: i32, y: i32, c: Rgb, a: f64) {
        if x >= 0 && y >= 0 && (x as u32) < self.w && (y as u32) < self.h && a > 0.0 {
            let i = 3 * (y as usize * self.w as usize + x as usize);
            let a = a.min(1.0);
            for (k, v) in [c.0, c.1, c.2].into_iter().enumerate() {
                let d = self.buf[i + k] as f64;
                self.buf[i + k] = (d + a * (v as f64 - d)).round() as u8;
            }
        }
    }
    pub(super) fn fill_rect(&mut self, l: i32, t: i32, r: i32, b: i32, c: Rgb) {
        for y in t..=b {
            for x in l..=r {
                self.set(x, y, c);
            }
        }
    }
    pub(super) fn hline(&mut self, x0: i32, x1: i32, y: i32, c: Rgb) {
        self.fill_rect(x0.min(x1), y, x0.max(x1), y, c);
    }
    pub(super) fn vline(&mut self, x: i32, y0: i32, y1: i32, c: Rgb) {
        self.fill_rect(x, y0.min(y1), x, y0.max(y1), c);
    }
    pub(super) fn rect_outline(&mut self, l: i32, t: i32, r: i32, b: i32, c: Rgb) {
        self.hline(l, r, t, c);
        self.hline(l, r, b, c);
        self.vline(l, t, b, c);
        self.vline(r, t, b, c);
    }
    /// Applies a coverage function over a pixel window (clipped to `clip` and the image):
    /// `cov(px, py)` gets the pixel centre and returns the coverage in [0, 1].
    pub(super) fn paint(&mut self, win: (f64, f64, f64, f64), clip: BoxPx, c: Rgb, cov: impl Fn(f64, f64) -> f64) {
        let x0 = (win.0.floor() as i32).max(clip.l).max(0);
        let x1 = (win.2.ceil() as i32).min(clip.r).min(self.w as i32 - 1);
        let y0 = (win.1.floor() as i32).max(clip.t).max(0);
        let y1 = (win.3.ceil() as i32).min(clip.b).min(self.h as i32 - 1);
        for y in y0..=y1 {
            for x in x0..=x1 {
                let a = cov(x as f64 + 0.5, y as f64 + 0.5);
                if a > 0.0 {
                    self.blend(x, y, c, a);
                }
            }
        }
    }
    /// Anti-aliased polyline of the given width (pixels), clipped to `clip`. The coverage of a
    /// pixel is taken from its nearest segment, so joints are not drawn twice.
    pub(super) fn stroke(&mut self, pts: &[(f64, f64)], width: f64, c: Rgb, clip: BoxPx) {
        if pts.len() < 2 {
            return;
        }
        let hw = 0.5 * width;
        let m = hw + 1.0;
        let (mut x0, mut y0, mut x1, mut y1) = (f64::INFINITY, f64::INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY);
        for p in pts {
            x0 = x0.min(p.0);
            y0 = y0.min(p.1);
            x1 = x1.max(p.0);
            y1 = y1.max(p.1);
        }
        let win = BoxPx {
            l: ((x0 - m).floor() as i32).max(clip.l).max(0),
            t: ((y0 - m).floor() as i32).max(clip.t).max(0),
            r: ((x1 + m).ceil() as i32).min(clip.r).min(self.w as i32 - 1),
            b: ((y1 + m).ceil() as i32).min(clip.b).min(self.h as i32 - 1),
        };
        if win.l > win.r || win.t > win.b {
            return;
        }
        let ww = (win.r - win.l + 1) as usize;
        let mut cov = vec![0f32; ww * (win.b - win.t + 1) as usize];
        for s in pts.windows(2) {
            let (a, b) = (s[0], s[1]);
            let (dx, dy) = (b.0 - a.0, b.1 - a.1);
            let len2 = dx * dx + dy * dy;
            let sx0 = ((a.0.min(b.0) - m).floor() as i32).max(win.l);
            let sx1 = ((a.0.max(b.0) + m).ceil() as i32).min(win.r);
            let sy0 = ((a.1.min(b.1) - m).floor() as i32).max(win.t);
            let sy1 = ((a.1.max(b.1) + m).ceil() as i32).min(win.b);
            for y in sy0..=sy1 {
                for x in sx0..=sx1 {
                    let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
                    let t = if len2 > 0.0 { (((px - a.0) * dx + (py - a.1) * dy) / len2).clamp(0.0, 1.0) } else { 0.0 };
                    let d = ((px - a.0 - t * dx).powi(2) + (py - a.1 - t * dy).powi(2)).sqrt();
                    let k = (hw + 0.5 - d).clamp(0.0, 1.0) as f32;
                    let i = (y - win.t) as usize * ww + (x - win.l) as usize;
                    cov[i] = cov[i].max(k);
                }
            }
        }
        for y in win.t..=win.b {
            for x in win.l..=win.r {
                let k = cov[(y - win.t) as usize * ww + (x - win.l) as usize];
                if k > 0.0 {
                    self.blend(x, y, c, k as f64);
                }
            }
        }
    }
    /// Anti-aliased filled disc.
    pub(super) fn disc(&mut self, cx: f64, cy: f64, r: f64, c: Rgb, clip: BoxPx) {
        self.paint((cx - r - 1.0, cy - r - 1.0, cx + r + 1.0, cy + r + 1.0), clip, c, |x, y| {
            (r + 0.5 - ((x - cx).powi(2) + (y - cy).powi(2)).sqrt()).clamp(0.0, 1.0)
        });
    }
    /// Anti-aliased filled triangle.
    pub(super) fn triangle(&mut self, p: [(f64, f64); 3], c: Rgb, clip: BoxPx) {
        let area = (p[1].0 - p[0].0) * (p[2].1 - p[0].1) - (p[2].0 - p[0].0) * (p[1].1 - p[0].1);
        if area.abs() < 1e-9 {
            return;
        }
        let sgn = area.signum();
        let xs = [p[0].0, p[1].0, p[2].0];
        let ys = [p[0].1, p[1].1, p[2].1];
        let win = (
            xs.iter().cloned().fold(f64::INFINITY, f64::min) - 1.0,
            ys.iter().cloned().fold(f64::INFINITY, f64::min) - 1.0,
            xs.iter().cloned().fold(f64::NEG_INFINITY, f64::max) + 1.0,
            ys.iter().cloned().fold(f64::NEG_INFINITY, f64::max) + 1.0,
        );
        self.paint(win, clip, c, |x, y| {
            let mut dmin = f64::INFINITY;
            for i in 0..3 {
                let (a, b) = (p[i], p[(i + 1) % 3]);
                let (ex, ey) = (b.0 - a.0, b.1 - a.1);
                let d = sgn * (ex * (y - a.1) - ey * (x - a.0)) / (ex * ex + ey * ey).sqrt();
                dmin = dmin.min(d);
            }
            (dmin + 0.5).clamp(0.0, 1.0)
        });
    }
    /// Dashed (black and white, visible on any colour) anti-aliased ellipse with centre (cx, cy)
    /// and half axes rx, ry in pixels.
    pub(super) fn dashed_ellipse(&mut self, cx: f64, cy: f64, rx: f64, ry: f64, clip: BoxPx) {
        let hw = 1.5;
        let dash = 9.0;
        let r_mean = 0.5 * (rx + ry);
        let win = (cx - rx - 3.0, cy - ry - 3.0, cx + rx + 3.0, cy + ry + 3.0);
        let x0 = (win.0.floor() as i32).max(clip.l).max(0);
        let x1 = (win.2.ceil() as i32).min(clip.r).min(self.w as i32 - 1);
        let y0 = (win.1.floor() as i32).max(clip.t).max(0);
        let y1 = (win.3.ceil() as i32).min(clip.b).min(self.h as i32 - 1);
        for y in y0..=y1 {
            for x in x0..=x1 {
                let (dx, dy) = (x as f64 + 0.5 - cx, y as f64 + 0.5 - cy);
                let q = ((dx / rx).powi(2) + (dy / ry).powi(2)).sqrt();
                if q == 0.0 {
                    continue;
                }
                let g = ((dx / (rx * rx)).powi(2) + (dy / (ry * ry)).powi(2)).sqrt() / q;
                let d = (q - 1.0) / g; // approximate distance in pixels
                let k = (hw + 0.5 - d.abs()).clamp(0.0, 1.0);
                if k > 0.0 {
                    let s = (dy / ry).atan2(dx / rx).rem_euclid(std::f64::consts::TAU) * r_mean;
                    let c = if ((s / dash) as i64) % 2 == 0 { BLACK } else { WHITE };
                    self.blend(x, y, c, k);
                }
            }
        }
    }
    pub(super) fn render_text(&mut self, font: &FontVec, t: &TextCmd) {
        let sf = font.as_scaled(PxScale::from(t.size as f32));
        let (w, h) = text_size(&t.s, t.size);
        let ax = match t.h {
            HPos::Left => 0,
            HPos::Center => w / 2,
            HPos::Right => w,
        };
        let ay = match t.v {
            VPos::Top => 0,
            VPos::Center => h / 2,
            VPos::Bottom => h,
        };
        let mut caret = 0.0f32;
        let mut prev = None;
        for c in t.s.chars() {
            let id = sf.glyph_id(c);
            if let Some(p) = prev {
                caret += sf.kern(p, id);
            }
            prev = Some(id);
            let glyph = id.with_scale_and_position(sf.scale(), ab_glyph::point(caret, sf.ascent()));
            caret += sf.h_advance(id);
            if let Some(og) = font.outline_glyph(glyph) {
                let bb = og.px_bounds();
                let mut px = Vec::new();
                og.draw(|gx, gy, a| px.push((bb.min.x as i32 + gx as i32, bb.min.y as i32 + gy as i32, a)));
                for (u, v, a) in px {
                    // (u, v): pixel in the text's own frame, top-left of the text box at (0, 0)
                    let (sx, sy) = if t.rot { (t.x + v - ay, t.y - u + ax) } else { (t.x + u - ax, t.y + v - ay) };
                    self.blend(sx, sy, BLACK, a as f64);
                }
            }
        }
    }
    /// Draws the queued text, encodes the PNG and writes it atomically.
    pub(super) fn save(mut self, path: &Path) -> Result<(), Error> {
        let font = font()?;
        for t in std::mem::take(&mut self.texts) {
            self.render_text(font, &t);
        }
        let mut png_bytes = Vec::new();
        {
            let mut enc = png::Encoder::new(&mut png_bytes, self.w, self.h);
            enc.set_color(png::ColorType::Rgb);
            enc.set_depth(png::BitDepth::Eight);
            let mut wr = enc.write_header().map_err(|e| Error::other(format!("png: {e}")))?;
            wr.write_image_data(&self.buf).map_err(|e| Error::other(format!("png: {e}")))?;
        }
        crate::output::write_atomic(path, &png_bytes).map_err(Error::io(IoAction::WritePlot, path))
    }
    /// Queues `s` anchored at (x, y); `rot` turns it 90 degrees counter-clockwise (reads bottom to top).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn text(&mut self, s: &str, x: i32, y: i32, size: f64, h: HPos, v: VPos, rot: bool) {
        if !s.is_empty() {
            self.texts.push(TextCmd { s: s.to_string(), x, y, size, h, v, rot });
        }
    }
    pub(super) fn full(&self) -> BoxPx {
        BoxPx { l: 0, t: 0, r: self.w as i32 - 1, b: self.h as i32 - 1 }
    }
}

/// Width and height (ascent - descent) of `s` in pixels at `size` (0, 0 without a font).
pub(super) fn text_size(s: &str, size: f64) -> (i32, i32) {
    let Ok(font) = font() else { return (0, 0) };
    if s.is_empty() {
        return (0, 0);
    }
    let sf = font.as_scaled(PxScale::from(size as f32));
    let mut w = 0.0f32;
    let mut prev = None;
    for c in s.chars() {
        let id = sf.glyph_id(c);
        if let Some(p) = prev {
            w += sf.kern(p, id);
        }
        w += sf.h_advance(id);
        prev = Some(id);
    }
    (w.ceil() as i32, (sf.ascent() - sf.descent()).ceil() as i32)
}

pub(super) fn lerp_table(table: &[(f64, Rgb)], t: f64) -> Rgb {
    let t = t.clamp(0.0, 1.0);
    for w in table.windows(2) {
        let ((t0, c0), (t1, c1)) = (w[0], w[1]);
        if t <= t1 {
            let s = (t - t0) / (t1 - t0);
            let l = |a: u8, b: u8| (a as f64 + s * (b as f64 - a as f64)).round() as u8;
            return (l(c0.0, c1.0), l(c0.1, c1.1), l(c0.2, c1.2));
        }
    }
    table[table.len() - 1].1
}

/// Viridis colour map (perceptually uniform), `t` in [0, 1].
pub fn viridis(t: f64) -> (u8, u8, u8) {
    pub(super) const T: [(f64, Rgb); 11] = [
        (0.0, (68, 1, 84)),
        (0.1, (72, 36, 117)),
        (0.2, (65, 68, 135)),
        (0.3, (53, 95, 141)),
        (0.4, (42, 120, 142)),
        (0.5, (33, 145, 140)),
        (0.6, (34, 168, 132)),
        (0.7, (68, 191, 112)),
        (0.8, (122, 209, 81)),
        (0.9, (189, 223, 38)),
        (1.0, (253, 231, 37)),
    ];
    lerp_table(&T, t)
}

/// Diverging blue-white-red colour map, `t` in [0, 1], white at 0.5.
pub fn blue_white_red(t: f64) -> (u8, u8, u8) {
    pub(super) const T: [(f64, Rgb); 7] = [
        (0.0, (5, 48, 97)),
        (0.17, (33, 102, 172)),
        (0.33, (103, 169, 207)),
        (0.5, (247, 247, 247)),
        (0.67, (239, 138, 98)),
        (0.83, (178, 24, 43)),
        (1.0, (103, 0, 31)),
    ];
    lerp_table(&T, t)
}
