//! The plotters side: [`Axis`] as a plotters coordinate (our ticks and labels), text sizes,
//! the title, the frame of a chart (ticks, tick labels, axis labels, grid) and the PNG file.
use super::*;
use plotters::coord::ranged1d::{KeyPointHint, KeyPointWeight, NoDefaultFormatting, Ranged, ValueFormatter};
use plotters::prelude::{
    BitMapBackend, Cartesian2d, ChartContext, Color, DrawingArea, FontDesc, FontFamily, FontStyle, RGBColor, Rectangle,
};
pub(super) use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::TextStyle;

pub(super) type Root<'a> = DrawingArea<BitMapBackend<'a>, plotters::coord::Shift>;
pub(super) type Chart<'a, 'b> = ChartContext<'a, BitMapBackend<'b>, Cartesian2d<Axis, Axis>>;

/// A plotters error as our error text.
pub(super) fn pe(e: impl std::fmt::Display) -> String {
    format!("plot: {e}")
}

/// Bold key points are the labelled (or major) ticks, light ones the rest (grid only).
impl Ranged for Axis {
    type FormatOption = NoDefaultFormatting;
    type ValueType = f64;
    fn map(&self, v: &f64, limit: (i32, i32)) -> i32 {
        let f = (self.t(*v) - self.t(self.lo)) / (self.t(self.hi) - self.t(self.lo));
        limit.0 + (f * (limit.1 - limit.0) as f64).round() as i32
    }
    fn key_points<H: KeyPointHint>(&self, hint: H) -> Vec<f64> {
        let bold = matches!(hint.weight(), KeyPointWeight::Bold);
        self.ticks().into_iter().filter(|t| (t.major || t.label.is_some()) == bold).map(|t| t.v).collect()
    }
    fn range(&self) -> std::ops::Range<f64> {
        self.lo..self.hi
    }
}

impl ValueFormatter<f64> for Axis {
    fn format_ext(&self, v: &f64) -> String {
        self.ticks().into_iter().find(|t| t.v == *v).and_then(|t| t.label).unwrap_or_default()
    }
}

pub(super) fn font(size: f64) -> FontDesc<'static> {
    FontDesc::new(FontFamily::SansSerif, size, FontStyle::Normal)
}

/// Width and height of `s` in pixels at `size` (0, 0 without a font).
pub(super) fn text_size(s: &str, size: f64) -> (i32, i32) {
    if s.is_empty() || ensure_font().is_err() {
        return (0, 0);
    }
    font(size).box_size(s).map_or((0, 0), |(w, h)| (w as i32, h as i32))
}

pub(super) fn max_label_width(ax: &Axis) -> i32 {
    ax.ticks().iter().filter_map(|t| t.label.as_ref()).map(|l| text_size(l, TICK_SIZE).0).max().unwrap_or(0)
}

/// Width of a vertical label area: axis label, tick labels, tick marks and gaps.
pub(super) fn y_area(ax: &Axis, label: &str) -> i32 {
    (if label.is_empty() { 0 } else { text_size("Xg", LABEL_SIZE).1 + 14 }) + max_label_width(ax) + 2 * TICK_LEN + 4
}

/// Height of the bottom label area.
pub(super) fn x_area(label: &str) -> i32 {
    (if label.is_empty() { 0 } else { text_size("Xg", LABEL_SIZE).1 + 12 }) + text_size("0", TICK_SIZE).1 + 2 * TICK_LEN + 6
}

/// Height of the band above the plot box.
pub(super) fn title_band(title: &str) -> i32 {
    if title.is_empty() {
        20
    } else {
        text_size(title, TITLE_SIZE).1 + 34
    }
}

pub(super) fn rgb(c: Rgb) -> RGBColor {
    RGBColor(c.0, c.1, c.2)
}

/// Draws `s` at pixel (x, y) of the root with the given anchor.
pub(super) fn text(root: &Root, s: &str, (x, y): (i32, i32), size: f64, anchor: (HPos, VPos)) -> Result<(), String> {
    if s.is_empty() {
        return Ok(());
    }
    let style = TextStyle::from(font(size)).pos(Pos::new(anchor.0, anchor.1));
    root.draw_text(s, &style, (x, y)).map_err(pe)
}

/// Title centred at the top.
pub(super) fn title_text(root: &Root, title: &str) -> Result<(), String> {
    let w = root.dim_in_pixel().0 as i32;
    text(root, title, (w / 2, 15), TITLE_SIZE, (HPos::Center, VPos::Top))
}

/// Plot box of a chart in pixels, from plotters' own mapping of the axis ends.
pub(super) fn plot_box(chart: &Chart, x: &Axis, y: &Axis) -> BoxPx {
    let (l, b) = chart.backend_coord(&(x.lo, y.lo));
    let (r, t) = chart.backend_coord(&(x.hi, y.hi));
    BoxPx { l, t, r, b }
}

/// Ticks, tick labels, axis labels, the grid (if `grid`) and a frame round the plot box;
/// sets the pixel ends of `x` and `y` and returns the plot box.
pub(super) fn draw_frame(
    root: &Root,
    chart: &mut Chart,
    x: &mut Axis,
    y: &mut Axis,
    labels: (&str, &str),
    grid: bool,
) -> Result<BoxPx, String> {
    let mut mesh = chart.configure_mesh();
    mesh.label_style(font(TICK_SIZE))
        .axis_desc_style(font(LABEL_SIZE))
        .set_all_tick_mark_size(TICK_LEN)
        .bold_line_style(rgb((220, 220, 220)))
        .light_line_style(rgb((240, 240, 240)));
    if !labels.0.is_empty() {
        mesh.x_desc(labels.0);
    }
    if !labels.1.is_empty() {
        mesh.y_desc(labels.1);
    }
    if !grid {
        mesh.disable_mesh();
    }
    mesh.draw().map_err(pe)?;
    let bx = plot_box(chart, x, y);
    (x.p0, x.p1, y.p0, y.p1) = (bx.l as f64, bx.r as f64, bx.b as f64, bx.t as f64);
    frame_rect(root, bx)?;
    Ok(bx)
}

/// Black rectangle round the plot box (pixels of the root).
pub(super) fn frame_rect(root: &Root, bx: BoxPx) -> Result<(), String> {
    root.draw(&Rectangle::new([(bx.l, bx.t), (bx.r, bx.b)], rgb(BLACK).stroke_width(1))).map_err(pe)
}
