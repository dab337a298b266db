//! Line plots: series on linear or log axes, secondary y axis, legend.
use super::*;
use plotters::prelude::{BitMapBackend, ChartBuilder, Circle, Color, EmptyElement, IntoDrawingArea, LineSeries, PathElement};
use plotters::prelude::{SeriesLabelPosition, TRANSPARENT};

/// Line/point plot of one or more series, optionally with log axes and a secondary y axis.
pub fn line_plot(path: &Path, title: &str, xlabel: &str, ylabel: &str, series: &[Series], opts: &LineOpts) -> Result<(), String> {
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
        None => data_range(series.iter().flat_map(|s| s.x.iter().copied()), opts.log_x, if markers { 0.03 } else { 0.0 }).unwrap(),
    };
    let yr_of = |sec: bool, log: bool, given: Option<(f64, f64)>, what: &str| -> Result<(f64, f64), String> {
        match given {
            Some(r) => check_range(r, log, what),
            None => Ok(data_range(series.iter().filter(|s| s.secondary == sec).flat_map(|s| s.y.iter().copied()), log, 0.05)
                .unwrap_or((if log { 1.0 } else { 0.0 }, if log { 10.0 } else { 1.0 }))),
        }
    };
    let yr = yr_of(false, opts.log_y, opts.y_range, "y")?;
    let y2r = yr_of(true, opts.log_y2, opts.y2_range, "y2")?;

    let mut x = Axis::new(xr, opts.log_x, 8);
    let mut y = Axis::new(yr, opts.log_y, 6);
    let y2 = Axis::new(y2r, opts.log_y2, 6);
    let mut cv = Canvas::new(opts.width, opts.height)?;
    let root = BitMapBackend::with_buffer(&mut cv.buf, (opts.width, opts.height)).into_drawing_area();
    title_text(&root, title)?;
    let right = if has_y2 { 15 } else { max_label_width(&x) / 2 + 20 };
    let mut chart = ChartBuilder::on(&root)
        .margin_top(title_band(title))
        .margin_left(15)
        .margin_right(right)
        .margin_bottom(15)
        .x_label_area_size(x_area(xlabel))
        .y_label_area_size(y_area(&y, ylabel))
        .right_y_label_area_size(if has_y2 { y_area(&y2, &opts.y2label) } else { 0 })
        .build_cartesian_2d(x.clone(), y.clone())
        .map_err(pe)?
        .set_secondary_coord(x.clone(), y2.clone());
    let (pw, ph) = chart.plotting_area().dim_in_pixel();
    if pw < 50 || ph < 50 {
        return Err(format!("line_plot: {}x{} pixels is too small for the labels", opts.width, opts.height));
    }
    draw_frame(&root, &mut chart, &mut x, &mut y, (xlabel, ylabel), opts.grid)?;
    if has_y2 {
        let mut axes = chart.configure_secondary_axes();
        axes.label_style(font(TICK_SIZE)).axis_desc_style(font(LABEL_SIZE)).set_all_tick_mark_size(TICK_LEN);
        if !opts.y2label.is_empty() {
            axes.y_desc(&opts.y2label);
        }
        axes.draw().map_err(pe)?;
    }
    for (i, s) in series.iter().enumerate() {
        let c = rgb(s.color.unwrap_or(PALETTE[i % PALETTE.len()]));
        let pts: Vec<(f64, f64)> = s.x.iter().copied().zip(s.y.iter().copied()).collect();
        let line = matches!(s.style, Style::Line | Style::LinePoints);
        let dots = matches!(s.style, Style::Points | Style::LinePoints);
        let ls = if line { c.stroke_width(2) } else { TRANSPARENT.stroke_width(0) };
        let ds = if dots { c.filled() } else { TRANSPARENT.filled() };
        let elems = pts.iter().map(|&p| Circle::new(p, 4, ds));
        let anno = match (s.secondary, line) {
            (false, true) => chart.draw_series(LineSeries::new(pts.clone(), ls)),
            (true, true) => chart.draw_secondary_series(LineSeries::new(pts.clone(), ls)),
            (false, false) => chart.draw_series(elems.clone()),
            (true, false) => chart.draw_secondary_series(elems.clone()),
        }
        .map_err(pe)?;
        if !s.label.is_empty() {
            let label = if s.secondary { format!("{} (right axis)", s.label) } else { s.label.clone() };
            anno.label(label)
                .legend(move |(lx, ly)| EmptyElement::at((lx, ly)) + PathElement::new([(0, 0), (34, 0)], ls) + Circle::new((17, 0), 4, ds));
        }
        if line && dots {
            if s.secondary { chart.draw_secondary_series(elems) } else { chart.draw_series(elems) }.map_err(pe)?;
        }
    }
    let pos = match opts.legend {
        Legend::None => None,
        Legend::UpperRight => Some(SeriesLabelPosition::UpperRight),
        Legend::UpperLeft => Some(SeriesLabelPosition::UpperLeft),
        Legend::LowerRight => Some(SeriesLabelPosition::LowerRight),
        Legend::LowerLeft => Some(SeriesLabelPosition::LowerLeft),
    };
    if let Some(pos) = pos.filter(|_| series.iter().any(|s| !s.label.is_empty())) {
        chart
            .configure_series_labels()
            .position(pos)
            .margin(10)
            .legend_area_size(44)
            .label_font(font(TICK_SIZE))
            .background_style(rgb(WHITE))
            .border_style(rgb((160, 160, 160)))
            .draw()
            .map_err(pe)?;
    }
    root.present().map_err(pe)?;
    drop(chart);
    drop(root);
    cv.save(path)
}
