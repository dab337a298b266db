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
use crate::error::Error;
use ab_glyph::{Font, FontVec, PxScale, ScaleFont};
use std::path::Path;
use std::sync::OnceLock;

/// The TrueType font used for all text in plots.
pub const FONT_PATH: &str = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";

static FONT: OnceLock<Result<FontVec, Error>> = OnceLock::new();
static FONT_FILE: OnceLock<String> = OnceLock::new();

/// Uses the TrueType font `path` instead of [`FONT_PATH`] (before the first plot; later
/// calls have no effect).
pub fn set_font_file(path: &str) {
    let _ = FONT_FILE.set(path.to_string());
}

fn load_font(path: &str) -> Result<FontVec, Error> {
    let bytes = std::fs::read(path).map_err(|e| {
        Error::invalid(format!(
            "plot font '{path}' cannot be read ({e}): install the Debian package fonts-dejavu-core \
             (apt-get install fonts-dejavu-core) or give -ehl_plot_font FILE, a TrueType font file"
        ))
    })?;
    FontVec::try_from_vec(bytes).map_err(|_| Error::invalid(format!("plot font '{path}' is not a valid TrueType font")))
}

fn font() -> Result<&'static FontVec, Error> {
    FONT.get_or_init(|| load_font(FONT_FILE.get().map_or(FONT_PATH, |f| f.as_str()))).as_ref().map_err(|e| Error::invalid(e.to_string()))
}

/// Loads the plot font once (from [`set_font_file`] or [`FONT_PATH`]); every plot function calls it
/// first, so a missing font is an error before any drawing.
pub fn ensure_font() -> Result<(), Error> {
    font().map(|_| ())
}

mod axes;
mod canvas;
mod line;
mod map;
mod quiver;
#[cfg(test)]
mod tests;

use axes::*;
use canvas::*;
pub use canvas::{blue_white_red, viridis};
pub use line::line_plot;
pub use map::map_plot;
use map::*;
pub use quiver::quiver_plot;

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
    /// Line segments drawn over the colours in data units (e.g. the edges of a mesh).
    pub edges: Vec<[[f64; 2]; 2]>,
    /// Labelled points drawn over the colours in data units (e.g. where hm lies): a black
    /// dot in a white ring, its label beside it; points outside the visible part are left out.
    pub markers: Vec<([f64; 2], String)>,
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
            edges: Vec::new(),
            markers: Vec::new(),
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
