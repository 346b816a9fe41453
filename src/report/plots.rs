//! The report's distribution and sensitivity plots, drawn with plotters into SVG files: a
//! histogram, the exceedance curve with its band, a tornado chart and a scatter. Text stays
//! text (`<text>` elements), so a browser renders it sharp and a test can read every label.
//!
//! Colours are the Okabe–Ito palette (distinguishable with every common colour-vision
//! deficiency); sizes are chosen for 100 % zoom: 14 px tick labels, 16 px axis titles.

use super::data::{label, ExceedancePoint, Histogram};
use super::ReportError;
use plotters::chart::{MeshStyle, SeriesLabelStyle};
use plotters::coord::{CoordTranslate, Shift};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

/// Okabe & Ito (2008) colours.
pub const BLUE: RGBColor = RGBColor(0, 114, 178);
pub const ORANGE: RGBColor = RGBColor(230, 159, 0);
pub const SKY: RGBColor = RGBColor(86, 180, 233);
pub const GREEN: RGBColor = RGBColor(0, 158, 115);
pub const VERMILLION: RGBColor = RGBColor(213, 94, 0);
pub const PURPLE: RGBColor = RGBColor(204, 121, 167);
pub const GREY: RGBColor = RGBColor(110, 110, 110);
/// The sky blue of the confidence bands, lightened (the plots stay opaque for any viewer).
pub const BAND: RGBColor = RGBColor(179, 218, 242);

/// Colours of successive threshold lines.
pub const MARKER_COLOURS: [RGBColor; 4] = [VERMILLION, PURPLE, GREEN, ORANGE];

/// [`fmt_tick`] as a tick-label formatter (a function item: it lives as long as any chart).
fn tick(v: &f64) -> String {
    fmt_tick(*v)
}

/// The report's axes: ticks written by [`fmt_tick`], 14 px labels and 16 px axis names, faint
/// major grid lines only. A chart sets its own descriptions and label counts after it.
pub fn mesh_style<'m, 'a, 'b, X, Y, DB>(
    m: &'m mut MeshStyle<'a, 'b, X, Y, DB>,
) -> &'m mut MeshStyle<'a, 'b, X, Y, DB>
where
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
    DB: DrawingBackend,
{
    m.x_label_formatter(&tick)
        .y_label_formatter(&tick)
        .label_style(font(14.0))
        .axis_desc_style(font(16.0))
        .light_line_style(TRANSPARENT)
        .bold_line_style(BLACK.mix(0.08))
}

/// The report's in-chart legend box: translucent white over a grey border, 13 px text.
pub fn legend_style<'l, 'a, 'b, DB, CT>(
    l: &'l mut SeriesLabelStyle<'a, 'b, DB, CT>,
) -> &'l mut SeriesLabelStyle<'a, 'b, DB, CT>
where
    DB: DrawingBackend + 'a,
    CT: CoordTranslate,
{
    l.background_style(WHITE.mix(0.9))
        .border_style(BLACK.mix(0.4))
        .label_font(font(13.0))
}

/// A text style of `px` CSS pixels (plotters' SVG backend writes `font-size` as size / 1.24).
pub fn font(px: f64) -> TextStyle<'static> {
    ("sans-serif", px * 1.24).into_font().color(&BLACK)
}

/// A vertical line drawn across a plot: a threshold and what it means.
#[derive(Clone, Debug)]
pub struct Marker {
    pub x: f64,
    pub label: String,
    pub colour: RGBColor,
}

/// Maps a plotters error to the report's error, naming the file.
pub fn plot_err<E: std::fmt::Display>(path: &Path) -> impl Fn(E) -> ReportError + '_ {
    move |e| ReportError::Plot {
        path: path.to_path_buf(),
        message: e.to_string(),
    }
}

/// A tick label: at most four significant digits, plain between 1e-3 and 1e7, else
/// scientific (`1.25e7`).
pub fn fmt_tick(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 || !v.is_finite() {
        return if v.is_finite() {
            "0".into()
        } else {
            v.to_string()
        };
    }
    if !(1e-3..1e7).contains(&a) {
        let s = format!("{v:.3e}");
        let (m, e) = s.split_once('e').unwrap_or((&s, "0"));
        let m = m.trim_end_matches('0').trim_end_matches('.');
        return format!("{m}e{e}");
    }
    let decimals = (3 - a.log10().floor() as i32).clamp(0, 8) as usize;
    let s = format!("{v:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// `lo..hi` padded by 3 % of the span (or of the magnitude for a zero span).
pub fn padded(lo: f64, hi: f64) -> std::ops::Range<f64> {
    let span = hi - lo;
    // A flat series gets a visible band around it (±1 around zero), not a 1e-9 one.
    let pad = if span > 0.0 {
        0.03 * span
    } else if lo == 0.0 {
        1.0
    } else {
        lo.abs() * 0.05
    };
    (lo - pad)..(hi + pad)
}

/// The x range of a distribution plot: the data's, widened to take in each marker that lies
/// within three data spans of it (a farther one would squash the data into a sliver; the
/// report's table still gives its probability).
pub fn x_span(lo: f64, hi: f64, markers: &[Marker]) -> (std::ops::Range<f64>, Vec<Marker>) {
    let span = (hi - lo).max(lo.abs() * 1e-6).max(1e-12);
    let shown: Vec<Marker> = markers
        .iter()
        .filter(|m| m.x >= lo - 3.0 * span && m.x <= hi + 3.0 * span)
        .cloned()
        .collect();
    let lo2 = shown.iter().map(|m| m.x).fold(lo, f64::min);
    let hi2 = shown.iter().map(|m| m.x).fold(hi, f64::max);
    (padded(lo2, hi2), shown)
}

/// Width and height of the distribution plots, px.
pub const SIZE: (u32, u32) = (600, 400);

/// Histogram of one QoI with its threshold markers.
pub fn histogram(
    path: &Path,
    column: &str,
    h: &Histogram,
    n: usize,
    markers: &[Marker],
) -> Result<(), ReportError> {
    let e = plot_err(path);
    let hi = h.lo + h.width * h.counts.len() as f64;
    let (xr, shown) = x_span(h.lo, hi, markers);
    let keys = marker_keys(&shown);
    let legend_h = if keys.is_empty() {
        0
    } else {
        10 + KEY_ROW * keys.len() as u32
    };
    let canvas = SVGBackend::new(path, (SIZE.0, SIZE.1 + legend_h)).into_drawing_area();
    canvas.fill(&WHITE).map_err(&e)?;
    let (root, below) = canvas.split_vertically(SIZE.1);
    let top = h.counts.iter().copied().max().unwrap_or(1) as f64 * 1.15;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            format!("{column}: histogram of {n} valid instances"),
            font(17.0),
        )
        .margin(14)
        .x_label_area_size(58)
        .y_label_area_size(78)
        .build_cartesian_2d(xr, 0.0..top)
        .map_err(&e)?;
    mesh_style(&mut chart.configure_mesh())
        .x_desc(label(column))
        .y_desc("instances per bin (1)")
        .x_labels(7)
        .y_labels(6)
        .draw()
        .map_err(&e)?;
    chart
        .draw_series(h.counts.iter().enumerate().map(|(i, &c)| {
            let a = h.lo + i as f64 * h.width;
            Rectangle::new([(a, 0.0), (a + h.width, c as f64)], SKY.filled())
        }))
        .map_err(&e)?;
    chart
        .draw_series(h.counts.iter().enumerate().map(|(i, &c)| {
            let a = h.lo + i as f64 * h.width;
            Rectangle::new([(a, 0.0), (a + h.width, c as f64)], BLUE.stroke_width(1))
        }))
        .map_err(&e)?;
    draw_markers(&mut chart, &shown, 0.0, top, &e)?;
    draw_keys(&below, (90, 12), &keys, &e)?;
    canvas.present().map_err(&e)?;
    Ok(())
}

type Chart<'a, 'b> = ChartContext<
    'a,
    SVGBackend<'b>,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

/// Vertical marker lines from `y0` to `y1`.
fn draw_markers<'a, 'b: 'a, F>(
    chart: &mut Chart<'a, 'b>,
    markers: &[Marker],
    y0: f64,
    y1: f64,
    e: &F,
) -> Result<(), ReportError>
where
    F: Fn(DrawingAreaErrorKind<std::io::Error>) -> ReportError,
{
    for m in markers {
        chart
            .draw_series(LineSeries::new(
                vec![(m.x, y0), (m.x, y1)],
                m.colour.stroke_width(3),
            ))
            .map_err(e)?;
    }
    Ok(())
}

/// One legend entry: a swatch (a filled block or a line) and its text.
pub struct Key {
    pub text: String,
    pub colour: RGBColor,
    pub block: bool,
}

/// Height of one legend row, px.
pub const KEY_ROW: u32 = 22;

/// Draw legend rows from (x, y) down in `area`'s pixel coordinates: outside the data, so
/// a legend never hides a curve.
pub fn draw_keys<F>(
    area: &DrawingArea<SVGBackend, Shift>,
    (x, y): (i32, i32),
    keys: &[Key],
    e: &F,
) -> Result<(), ReportError>
where
    F: Fn(DrawingAreaErrorKind<std::io::Error>) -> ReportError,
{
    for (j, k) in keys.iter().enumerate() {
        let y = y + KEY_ROW as i32 * j as i32;
        if k.block {
            area.draw(&Rectangle::new(
                [(x, y - 6), (x + 22, y + 6)],
                k.colour.filled(),
            ))
            .map_err(e)?;
        } else {
            area.draw(&PathElement::new(
                vec![(x, y), (x + 22, y)],
                k.colour.stroke_width(3),
            ))
            .map_err(e)?;
        }
        area.draw(&Text::new(
            k.text.clone(),
            (x + 28, y),
            font(13.0).pos(Pos::new(HPos::Left, VPos::Center)),
        ))
        .map_err(e)?;
    }
    Ok(())
}

/// Legend entries of threshold markers.
fn marker_keys(markers: &[Marker]) -> Vec<Key> {
    markers
        .iter()
        .map(|m| Key {
            text: m.label.clone(),
            colour: m.colour,
            block: false,
        })
        .collect()
}

/// The empirical exceedance curve P(X ≥ x) — for a margin (`lower`) the non-exceedance
/// P(X ≤ x) — on a log axis with its pointwise band.
pub fn exceedance(
    path: &Path,
    column: &str,
    points: &[ExceedancePoint],
    level: f64,
    markers: &[Marker],
    lower: bool,
) -> Result<(), ReportError> {
    let e = plot_err(path);
    // The most extreme value is reached by one instance in n.
    let n = (1.0 / points.iter().map(|p| p.p).fold(1.0, f64::min).max(1e-300)).round();
    let (what, beyond, sign) = if lower {
        ("non-exceedance", "at or below", "≤")
    } else {
        ("exceedance", "at or above", "≥")
    };
    let (lo, hi) = (points[0].x, points[points.len() - 1].x);
    let (xr, shown) = x_span(lo, hi, markers);
    let pct = format!("{:.0} %", level * 100.0);
    let mut keys = vec![
        Key {
            text: format!("fraction of instances {beyond} x"),
            colour: BLUE,
            block: false,
        },
        Key {
            text: format!("{pct} pointwise Clopper–Pearson band"),
            colour: BAND,
            block: true,
        },
    ];
    keys.extend(marker_keys(&shown));
    let legend_h = 10 + KEY_ROW * keys.len() as u32;
    let canvas = SVGBackend::new(path, (SIZE.0, SIZE.1 + legend_h)).into_drawing_area();
    canvas.fill(&WHITE).map_err(&e)?;
    let (root, below) = canvas.split_vertically(SIZE.1);
    // The smallest plotted probability is 1/n; the decade below (and a little more, so that
    // its tick is labelled) leaves room for the band.
    let ymin = 0.8 * 10f64.powf((0.5 / n.max(1.0)).log10().floor());
    let mut chart = ChartBuilder::on(&root)
        .caption(format!("{column}: {what}, n = {n}"), font(17.0))
        .margin(14)
        .x_label_area_size(58)
        .y_label_area_size(78)
        .build_cartesian_2d(xr, (ymin..1.0).log_scale())
        .map_err(&e)?;
    mesh_style(&mut chart.configure_mesh())
        .x_desc(label(column))
        .y_desc(format!("P(X {sign} x), {what} (1)"))
        .x_labels(7)
        .draw()
        .map_err(&e)?;
    // Step functions: P(X ≥ x) takes the next point's value right after a point,
    // P(X ≤ x) keeps a point's value up to the next.
    let step = |f: &dyn Fn(&ExceedancePoint) -> f64| {
        let mut v = vec![(points[0].x, f(&points[0]).max(ymin))];
        for w in points.windows(2) {
            let held = if lower { &w[0] } else { &w[1] };
            v.push((w[0].x, f(held).max(ymin)));
            v.push((w[1].x, f(held).max(ymin)));
            v.push((w[1].x, f(&w[1]).max(ymin)));
        }
        v
    };
    let upper = step(&|p| p.hi);
    let mut band = step(&|p| p.lo);
    band.reverse();
    let mut polygon = upper;
    polygon.extend(band);
    chart
        .draw_series(std::iter::once(Polygon::new(polygon, BAND.filled())))
        .map_err(&e)?;
    chart
        .draw_series(LineSeries::new(step(&|p| p.p), BLUE.stroke_width(2)))
        .map_err(&e)?;
    for m in &shown {
        chart
            .draw_series(LineSeries::new(
                vec![(m.x, ymin), (m.x, 1.0)],
                m.colour.stroke_width(3),
            ))
            .map_err(&e)?;
    }
    draw_keys(&below, (90, 12), &keys, &e)?;
    canvas.present().map_err(&e)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tick_labels_are_short() {
        assert_eq!(fmt_tick(125000.0), "125000");
        assert_eq!(fmt_tick(0.1567), "0.1567");
        assert_eq!(fmt_tick(0.5), "0.5");
        assert_eq!(fmt_tick(2.5e7), "2.5e7");
        assert_eq!(fmt_tick(1e-5), "1e-5");
        assert_eq!(fmt_tick(0.0), "0");
        assert_eq!(fmt_tick(-12.5), "-12.5");
    }
}
