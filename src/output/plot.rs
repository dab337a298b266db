//! PNG plots: line plots (linear or log axes, legend, optional secondary y axis), filled colour
//! maps of a scalar field on a triangle mesh (with colour bar), and quiver (arrow) plots.
//!
//! Pure Rust, no system libraries: a small anti-aliased rasteriser of our own (lines, discs,
//! triangles, dashed circles, Gouraud-shaded mesh triangles) draws into an RGB buffer, `ab_glyph`
//! renders the text, and the `png` crate encodes the image. Files are written atomically
//! ([`super::write_atomic`]).
//!
//! Text is rendered from the TrueType file [`FONT_PATH`] (Debian package `fonts-dejavu-core`),
//! read at run time; the option `-ehl_plot_font FILE` ([`set_font_file`]) names another. If the
//! font cannot be read every plot function fails with an error naming the package.
//!
//! All input must be finite (and positive on a log axis); otherwise the functions return `Err`.
use ab_glyph::{Font, FontVec, PxScale, ScaleFont};
use std::path::Path;
use std::sync::OnceLock;

/// The TrueType font used for all text in plots.
pub const FONT_PATH: &str = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";

static FONT: OnceLock<Result<FontVec, String>> = OnceLock::new();
static FONT_FILE: OnceLock<String> = OnceLock::new();

/// Uses the TrueType font `path` instead of [`FONT_PATH`] (before the first plot; later
/// calls have no effect).
pub fn set_font_file(path: &str) {
    let _ = FONT_FILE.set(path.to_string());
}

fn load_font(path: &str) -> Result<FontVec, String> {
    let bytes = std::fs::read(path).map_err(|e| {
        format!(
            "plot font '{path}' cannot be read ({e}): install the Debian package fonts-dejavu-core \
             (apt-get install fonts-dejavu-core) or give -ehl_plot_font FILE, a TrueType font file"
        )
    })?;
    FontVec::try_from_vec(bytes).map_err(|_| format!("plot font '{path}' is not a valid TrueType font"))
}

fn font() -> Result<&'static FontVec, String> {
    FONT.get_or_init(|| load_font(FONT_FILE.get().map_or(FONT_PATH, |f| f.as_str())))
        .as_ref()
        .map_err(|e| e.clone())
}

/// Loads the plot font once (from [`set_font_file`] or [`FONT_PATH`]); every plot function calls it
/// first, so a missing font is an error before any drawing.
pub fn ensure_font() -> Result<(), String> {
    font().map(|_| ())
}

// ---------------------------------------------------------------------------------------------
// Public API
// ---------------------------------------------------------------------------------------------

/// How a series is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Style {
    #[default]
    Line,
    Points,
    LinePoints,
}

/// One curve of a line plot.
#[derive(Clone, Debug, Default)]
pub struct Series {
    pub label: String,
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    pub style: Style,
    /// Plot against the secondary (right) y axis.
    pub secondary: bool,
    /// Colour; `None` takes the next colour of a 10-colour palette.
    pub color: Option<(u8, u8, u8)>,
}

impl Series {
    pub fn new(label: &str, x: Vec<f64>, y: Vec<f64>, style: Style) -> Series {
        Series { label: label.to_string(), x, y, style, secondary: false, color: None }
    }
    /// Moves the series to the secondary (right) y axis.
    pub fn on_secondary(mut self) -> Series {
        self.secondary = true;
        self
    }
    pub fn with_color(mut self, rgb: (u8, u8, u8)) -> Series {
        self.color = Some(rgb);
        self
    }
}

/// Where the legend goes (inside the plot box).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Legend {
    None,
    #[default]
    UpperRight,
    UpperLeft,
    LowerRight,
    LowerLeft,
}

/// Options of [`line_plot`].
#[derive(Clone, Debug)]
pub struct LineOpts {
    pub width: u32,
    pub height: u32,
    pub log_x: bool,
    pub log_y: bool,
    /// Log scale of the secondary y axis.
    pub log_y2: bool,
    /// Label of the secondary (right) y axis; the axis is drawn when a series is `secondary`.
    pub y2label: String,
    pub x_range: Option<(f64, f64)>,
    pub y_range: Option<(f64, f64)>,
    pub y2_range: Option<(f64, f64)>,
    pub legend: Legend,
    pub grid: bool,
}

impl Default for LineOpts {
    fn default() -> Self {
        LineOpts {
            width: 1000,
            height: 700,
            log_x: false,
            log_y: false,
            log_y2: false,
            y2label: String::new(),
            x_range: None,
            y_range: None,
            y2_range: None,
            legend: Legend::UpperRight,
            grid: true,
        }
    }
}

/// Options of [`map_plot`].
#[derive(Clone, Debug)]
pub struct MapOpts {
    /// Image size in pixels; with `equal_aspect` the unused band is cut off, so the image
    /// may be narrower or lower.
    pub width: u32,
    pub height: u32,
    /// Dashed circle `(cx, cy, r)` in data units (e.g. the Hertz contact circle).
    pub circle: Option<(f64, f64, f64)>,
    /// Blue-white-red colour map with limits symmetric about zero (signed fields); otherwise viridis.
    pub diverging: bool,
    /// Same length scale on both axes.
    pub equal_aspect: bool,
    /// Label of the colour bar (name and unit of the field).
    pub colorbar_label: String,
    /// Colour limits; default the data range (symmetric `±max|v|` when `diverging`).
    pub range: Option<(f64, f64)>,
    /// Visible part of the plane; default the bounding box of the triangles.
    pub x_range: Option<(f64, f64)>,
    pub y_range: Option<(f64, f64)>,
}

impl Default for MapOpts {
    fn default() -> Self {
        MapOpts {
            width: 900,
            height: 760,
            circle: None,
            diverging: false,
            equal_aspect: true,
            colorbar_label: String::new(),
            range: None,
            x_range: None,
            y_range: None,
        }
    }
}

/// Options of [`quiver_plot`].
#[derive(Clone, Debug)]
pub struct QuiverOpts {
    /// Image size in pixels (cut down as for [`MapOpts`] with `equal_aspect`).
    pub width: u32,
    pub height: u32,
    pub circle: Option<(f64, f64, f64)>,
    pub equal_aspect: bool,
    /// Arrow length in x-axis data units per unit of (u, v); default: the longest arrow is about
    /// the mean spacing of the arrow positions.
    pub scale: Option<f64>,
    /// Unit of (u, v), printed beside the reference arrow (e.g. "m/s").
    pub unit: String,
    /// Length of the reference arrow in units of (u, v); default a round number near the largest |(u, v)|.
    pub reference: Option<f64>,
    pub x_range: Option<(f64, f64)>,
    pub y_range: Option<(f64, f64)>,
}

impl Default for QuiverOpts {
    fn default() -> Self {
        QuiverOpts {
            width: 900,
            height: 800,
            circle: None,
            equal_aspect: true,
            scale: None,
            unit: String::new(),
            reference: None,
            x_range: None,
            y_range: None,
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Canvas, text, colours
// ---------------------------------------------------------------------------------------------

type Rgb = (u8, u8, u8);
const PALETTE: [Rgb; 10] = [
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
const TITLE_SIZE: f64 = 24.0;
const LABEL_SIZE: f64 = 19.0;
const TICK_SIZE: f64 = 16.0;
const TICK_LEN: i32 = 6;

/// Horizontal anchor of a text.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum HPos {
    Left,
    Center,
    Right,
}
/// Vertical anchor of a text (top or bottom of the ascent-descent box).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum VPos {
    Top,
    Center,
    Bottom,
}

/// A piece of text drawn last (on top); anchored at (x, y) in the text's own frame; `rot`
/// turns it 90 degrees counter-clockwise about the anchor (reads bottom to top).
struct TextCmd {
    s: String,
    x: i32,
    y: i32,
    size: f64,
    h: HPos,
    v: VPos,
    rot: bool,
}

fn check_size(w: u32, h: u32) -> Result<(), String> {
    if !(200..=10000).contains(&w) || !(150..=10000).contains(&h) {
        return Err(format!("plot size {w}x{h} out of range (200..10000 x 150..10000)"));
    }
    Ok(())
}

const BLACK: Rgb = (0, 0, 0);
const WHITE: Rgb = (255, 255, 255);

/// RGB image with a few anti-aliased primitives; text is queued and drawn by [`Canvas::save`].
struct Canvas {
    w: u32,
    h: u32,
    buf: Vec<u8>,
    texts: Vec<TextCmd>,
}

impl Canvas {
    fn new(w: u32, h: u32) -> Result<Canvas, String> {
        check_size(w, h)?;
        Ok(Canvas { w, h, buf: vec![255; (w * h * 3) as usize], texts: Vec::new() })
    }
    fn set(&mut self, x: i32, y: i32, c: Rgb) {
        self.blend(x, y, c, 1.0);
    }
    /// Mixes colour `c` into pixel (x, y) with coverage `a` in [0, 1].
    fn blend(&mut self, x: i32, y: i32, c: Rgb, a: f64) {
        if x >= 0 && y >= 0 && (x as u32) < self.w && (y as u32) < self.h && a > 0.0 {
            let i = 3 * (y as usize * self.w as usize + x as usize);
            let a = a.min(1.0);
            for (k, v) in [c.0, c.1, c.2].into_iter().enumerate() {
                let d = self.buf[i + k] as f64;
                self.buf[i + k] = (d + a * (v as f64 - d)).round() as u8;
            }
        }
    }
    fn fill_rect(&mut self, l: i32, t: i32, r: i32, b: i32, c: Rgb) {
        for y in t..=b {
            for x in l..=r {
                self.set(x, y, c);
            }
        }
    }
    fn hline(&mut self, x0: i32, x1: i32, y: i32, c: Rgb) {
        self.fill_rect(x0.min(x1), y, x0.max(x1), y, c);
    }
    fn vline(&mut self, x: i32, y0: i32, y1: i32, c: Rgb) {
        self.fill_rect(x, y0.min(y1), x, y0.max(y1), c);
    }
    fn rect_outline(&mut self, l: i32, t: i32, r: i32, b: i32, c: Rgb) {
        self.hline(l, r, t, c);
        self.hline(l, r, b, c);
        self.vline(l, t, b, c);
        self.vline(r, t, b, c);
    }
    /// Applies a coverage function over a pixel window (clipped to `clip` and the image):
    /// `cov(px, py)` gets the pixel centre and returns the coverage in [0, 1].
    fn paint(&mut self, win: (f64, f64, f64, f64), clip: BoxPx, c: Rgb, cov: impl Fn(f64, f64) -> f64) {
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
    fn stroke(&mut self, pts: &[(f64, f64)], width: f64, c: Rgb, clip: BoxPx) {
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
    fn disc(&mut self, cx: f64, cy: f64, r: f64, c: Rgb, clip: BoxPx) {
        self.paint((cx - r - 1.0, cy - r - 1.0, cx + r + 1.0, cy + r + 1.0), clip, c, |x, y| {
            (r + 0.5 - ((x - cx).powi(2) + (y - cy).powi(2)).sqrt()).clamp(0.0, 1.0)
        });
    }
    /// Anti-aliased filled triangle.
    fn triangle(&mut self, p: [(f64, f64); 3], c: Rgb, clip: BoxPx) {
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
    fn dashed_ellipse(&mut self, cx: f64, cy: f64, rx: f64, ry: f64, clip: BoxPx) {
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
    fn render_text(&mut self, font: &FontVec, t: &TextCmd) {
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
    fn save(mut self, path: &Path) -> Result<(), String> {
        let font = font()?;
        for t in std::mem::take(&mut self.texts) {
            self.render_text(font, &t);
        }
        let mut png_bytes = Vec::new();
        {
            let mut enc = png::Encoder::new(&mut png_bytes, self.w, self.h);
            enc.set_color(png::ColorType::Rgb);
            enc.set_depth(png::BitDepth::Eight);
            let mut wr = enc.write_header().map_err(|e| format!("png: {e}"))?;
            wr.write_image_data(&self.buf).map_err(|e| format!("png: {e}"))?;
        }
        super::write_atomic(path, &png_bytes).map_err(|e| format!("cannot write plot '{}': {e}", path.display()))
    }
    /// Queues `s` anchored at (x, y); `rot` turns it 90 degrees counter-clockwise (reads bottom to top).
    #[allow(clippy::too_many_arguments)]
    fn text(&mut self, s: &str, x: i32, y: i32, size: f64, h: HPos, v: VPos, rot: bool) {
        if !s.is_empty() {
            self.texts.push(TextCmd { s: s.to_string(), x, y, size, h, v, rot });
        }
    }
    fn full(&self) -> BoxPx {
        BoxPx { l: 0, t: 0, r: self.w as i32 - 1, b: self.h as i32 - 1 }
    }
}

/// Width and height (ascent - descent) of `s` in pixels at `size` (0, 0 without a font).
fn text_size(s: &str, size: f64) -> (i32, i32) {
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

fn lerp_table(table: &[(f64, Rgb)], t: f64) -> Rgb {
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
    const T: [(f64, Rgb); 11] = [
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
    const T: [(f64, Rgb); 7] = [
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

// ---------------------------------------------------------------------------------------------
// Axes and ticks
// ---------------------------------------------------------------------------------------------

#[derive(Clone, Debug)]
struct Axis {
    lo: f64,
    hi: f64,
    log: bool,
    /// pixel of `lo` and of `hi`
    p0: f64,
    p1: f64,
    /// wanted number of tick intervals (linear)
    target: usize,
}

struct Tick {
    v: f64,
    label: Option<String>,
    major: bool,
}

impl Axis {
    fn t(&self, v: f64) -> f64 {
        if self.log {
            v.log10()
        } else {
            v
        }
    }
    fn px(&self, v: f64) -> f64 {
        let (a, b) = (self.t(self.lo), self.t(self.hi));
        self.p0 + (self.t(v) - a) / (b - a) * (self.p1 - self.p0)
    }
    /// pixels per data unit (linear axes)
    fn scale(&self) -> f64 {
        (self.p1 - self.p0) / (self.hi - self.lo)
    }
    fn ticks(&self) -> Vec<Tick> {
        if self.log && self.hi / self.lo > 3.0 {
            log_ticks(self.lo, self.hi)
        } else {
            linear_ticks(self.lo, self.hi, self.target)
        }
    }
}

/// Step 1, 2 or 5 x 10^k giving the number of intervals closest to `target`.
fn nice_step(range: f64, target: usize) -> f64 {
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

fn linear_ticks(lo: f64, hi: f64, target: usize) -> Vec<Tick> {
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
fn format_linear(v: f64, step: f64, maxabs: f64) -> String {
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

fn superscript(n: i32) -> String {
    const SUP: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
    let mut s = String::new();
    if n < 0 {
        s.push('⁻');
    }
    for c in n.unsigned_abs().to_string().chars() {
        s.push(SUP[c.to_digit(10).unwrap() as usize]);
    }
    s
}

fn format_short(v: f64) -> String {
    let a = v.abs();
    if (1e-3..1e5).contains(&a) {
        let s = format!("{v:.4}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{v:.0e}")
    }
}

fn log_ticks(lo: f64, hi: f64) -> Vec<Tick> {
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

fn data_range(vals: impl Iterator<Item = f64>, log: bool, pad: f64) -> Option<(f64, f64)> {
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

fn check_range(r: (f64, f64), log: bool, what: &str) -> Result<(f64, f64), String> {
    if !r.0.is_finite() || !r.1.is_finite() || r.0 >= r.1 || (log && r.0 <= 0.0) {
        return Err(format!("invalid {what} range {:?}", r));
    }
    Ok(r)
}

fn max_label_width(ticks: &[Tick], size: f64) -> i32 {
    ticks.iter().filter_map(|t| t.label.as_ref()).map(|l| text_size(l, size).0).max().unwrap_or(0)
}

/// Plot box in pixels: left, top, right, bottom.
#[derive(Clone, Copy, Debug)]
struct BoxPx {
    l: i32,
    t: i32,
    r: i32,
    b: i32,
}

/// Light grid lines at the ticks (drawn under the data).
fn draw_grid(cv: &mut Canvas, bx: BoxPx, x: &Axis, y: &Axis) {
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
fn y_ticks(cv: &mut Canvas, ax: &Axis, x0: i32, right: bool, bx: BoxPx) -> i32 {
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
fn draw_frame(cv: &mut Canvas, bx: BoxPx, x: &Axis, y: &Axis, y2: Option<&Axis>, labels: (&str, &str, &str)) {
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
fn draw_circle(cv: &mut Canvas, x: &Axis, y: &Axis, c: (f64, f64, f64), bx: BoxPx) {
    cv.dashed_ellipse(x.px(c.0), y.px(c.1), c.2 * x.scale().abs(), c.2 * y.scale().abs(), bx);
}

fn check_finite(vals: impl IntoIterator<Item = f64>, what: &str) -> Result<(), String> {
    match vals.into_iter().enumerate().find(|(_, v)| !v.is_finite()) {
        Some((i, v)) => Err(format!("{what}: value {i} is {v} (all plot data must be finite)")),
        None => Ok(()),
    }
}

fn title_band(title: &str) -> i32 {
    if title.is_empty() {
        20
    } else {
        text_size(title, TITLE_SIZE).1 + 30
    }
}

// ---------------------------------------------------------------------------------------------
// Line plot
// ---------------------------------------------------------------------------------------------

/// Line/point plot of one or more series, optionally with log axes and a secondary y axis.
pub fn line_plot(
    path: &Path,
    title: &str,
    xlabel: &str,
    ylabel: &str,
    series: &[Series],
    opts: &LineOpts,
) -> Result<(), String> {
    ensure_font()?;
    check_size(opts.width, opts.height)?;
    if series.is_empty() || series.iter().all(|s| s.x.is_empty()) {
        return Err("line_plot: no data".to_string());
    }
    for s in series {
        if s.x.len() != s.y.len() {
            return Err(format!("line_plot: series '{}' has {} x and {} y values", s.label, s.x.len(), s.y.len()));
        }
        check_finite(s.x.iter().copied(), &format!("line_plot: series '{}' x", s.label))?;
        check_finite(s.y.iter().copied(), &format!("line_plot: series '{}' y", s.label))?;
        let logy = if s.secondary { opts.log_y2 } else { opts.log_y };
        if opts.log_x && s.x.iter().any(|&v| v <= 0.0) {
            return Err(format!("line_plot: series '{}' has x <= 0 on a log axis", s.label));
        }
        if logy && s.y.iter().any(|&v| v <= 0.0) {
            return Err(format!("line_plot: series '{}' has y <= 0 on a log axis", s.label));
        }
    }
    let has_y2 = series.iter().any(|s| s.secondary);
    let markers = series.iter().any(|s| s.style != Style::Line);
    let xr = match opts.x_range {
        Some(r) => check_range(r, opts.log_x, "x")?,
        None => data_range(series.iter().flat_map(|s| s.x.iter().copied()), opts.log_x, if markers { 0.03 } else { 0.0 })
            .unwrap(),
    };
    let yr_of = |sec: bool, log: bool, given: Option<(f64, f64)>, what: &str| -> Result<(f64, f64), String> {
        match given {
            Some(r) => check_range(r, log, what),
            None => Ok(data_range(
                series.iter().filter(|s| s.secondary == sec).flat_map(|s| s.y.iter().copied()),
                log,
                0.05,
            )
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
        return Err(format!("line_plot: {w}x{h} pixels is too small for the labels"));
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

fn draw_legend(cv: &mut Canvas, bx: BoxPx, pos: Legend, entries: &[(String, Rgb, Style)]) {
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

// ---------------------------------------------------------------------------------------------
// Maps
// ---------------------------------------------------------------------------------------------

/// Plot box for a 2-D field: fills the available space, or the largest box with equal scales;
/// then the canvas (w, h) loses the unused band, keeping at least `min_w` of width.
fn fit_box(avail: BoxPx, xr: (f64, f64), yr: (f64, f64), equal: bool, w: i32, h: i32, min_w: i32) -> (BoxPx, i32, i32) {
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
        return Err(format!("map_plot: {w}x{h} pixels is too small for the labels"));
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
    if let Some(c) = opts.circle {
        draw_circle(&mut cv, &x, &y, c, bx);
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

// ---------------------------------------------------------------------------------------------
// Quiver
// ---------------------------------------------------------------------------------------------

fn draw_arrow(cv: &mut Canvas, tail: (f64, f64), tip: (f64, f64), c: Rgb, width: f64, clip: BoxPx) {
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
pub fn quiver_plot(
    path: &Path,
    title: &str,
    xlabel: &str,
    ylabel: &str,
    arrows: &[[f64; 4]],
    opts: &QuiverOpts,
) -> Result<(), String> {
    ensure_font()?;
    check_size(opts.width, opts.height)?;
    if arrows.is_empty() {
        return Err("quiver_plot: no arrows".to_string());
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
        Some(s) => return Err(format!("quiver_plot: invalid scale {s}")),
        None if vmax > 0.0 => 0.9 * spacing / vmax,
        None => 1.0,
    };
    let reference = match opts.reference {
        Some(r) if r.is_finite() && r > 0.0 => r,
        Some(r) => return Err(format!("quiver_plot: invalid reference length {r}")),
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
        return Err(format!("quiver_plot: {w}x{h} pixels is too small for the labels"));
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

// ---------------------------------------------------------------------------------------------
// Tests
// ---------------------------------------------------------------------------------------------

#[cfg(test)]
mod tests {
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
        let e = load_font("/nonexistent/DejaVuSans.ttf").err().unwrap();
        assert!(e.contains("fonts-dejavu-core"), "{e}");
        let e = load_font("/etc/hostname").err().unwrap();
        assert!(e.contains("not a valid TrueType"), "{e}");
        ensure_font().unwrap();
        let (w, h) = text_size("Pressure p [GPa]", LABEL_SIZE);
        assert!(w > 50 && h > 10, "{w}x{h}");
    }

    #[test]
    fn hertz_pressure_map() {
        let (tris, vals) = square_mesh(3.0, 60, |x, y| (1.0 - x * x - y * y).max(0.0).sqrt());
        let path = test_dir().join("map_hertz.png");
        let opts = MapOpts {
            circle: Some((0.0, 0.0, 1.0)),
            colorbar_label: "p / p_H".to_string(),
            ..Default::default()
        };
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
    fn diverging_shear_map() {
        // signed field, rectangular domain, not equal aspect
        let (tris, vals) = square_mesh(2.0, 40, |x, y| 3e6 * x * (-(x * x + y * y)).exp());
        let tris: Vec<_> = tris.iter().map(|t| t.map(|p| [p[0], 0.5 * p[1]])).collect();
        let path = test_dir().join("map_shear.png");
        let opts = MapOpts {
            diverging: true,
            circle: Some((0.0, 0.0, 0.8)),
            colorbar_label: "τ_xz [Pa]".to_string(),
            ..Default::default()
        };
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
        line_plot(&path, "", "n", "y", &s, &LineOpts { log_x: true, width: 600, height: 400, ..Default::default() })
            .unwrap();
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
            let e = line_plot(&p, "t", "x", "y", &s, &LineOpts::default()).unwrap_err();
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
}
