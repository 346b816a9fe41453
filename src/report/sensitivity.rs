//! The sensitivities section: per QoI a tornado chart of its Spearman correlations, the Sobol
//! first and total indices under `saltelli` (both from `statistics.parquet`, with their
//! intervals), and a scatter against its top driver (two instances columns, subsampled alike).

use super::data::{self, label, RunInfo, StatRow};
use super::plots::{font, legend_style, mesh_style, padded, plot_err, BLUE, ORANGE, SIZE};
use super::{file_stem, ReportError, HEADLINE};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

/// The sensitivity plots of one QoI.
#[derive(Debug, Default)]
pub(crate) struct SensitivitySection {
    pub qoi: String,
    pub spearman: Option<String>,
    pub sobol: Option<String>,
    /// Scatter file and the input it is drawn against.
    pub scatter: Option<(String, String)>,
}

/// The QoIs with sensitivity rows that vary: the headline ones first, then the others.
pub(crate) fn sensitivity_qois(stats: &[StatRow], varying: &[String]) -> Vec<String> {
    let mut qs: Vec<String> = Vec::new();
    for r in stats.iter().filter(|r| r.input.is_some()) {
        if varying.contains(&r.quantity) && !qs.contains(&r.quantity) {
            qs.push(r.quantity.clone());
        }
    }
    qs.sort_by_key(|q| {
        HEADLINE
            .iter()
            .position(|h| h == q)
            .unwrap_or(HEADLINE.len())
    });
    qs
}

/// Points of a scatter, at most this many (an even stride through the instances).
const SCATTER_POINTS: usize = 4000;

/// The tornado charts and the scatter against the top driver of one QoI.
pub(crate) fn sensitivity(
    info: &RunInfo,
    stats: &[StatRow],
    q: &str,
    at: &Path,
) -> Result<SensitivitySection, ReportError> {
    let stem = file_stem(q);
    let mut section = SensitivitySection {
        qoi: q.to_string(),
        ..Default::default()
    };
    let rows_of = |statistic: &str| -> Vec<&StatRow> {
        stats
            .iter()
            .filter(|r| r.quantity == q && r.statistic == statistic && r.input.is_some())
            .collect()
    };
    let mut rho = rows_of("spearman");
    rho.sort_by(|a, b| b.value.abs().total_cmp(&a.value.abs()));
    if !rho.is_empty() {
        let names: Vec<String> = rho.iter().filter_map(|r| r.input.clone()).collect();
        let file = format!("spearman_{stem}.svg");
        let series = [BarSeries {
            label: String::new(),
            colour: BLUE,
            values: rho.iter().map(|r| (r.value, r.ci_low, r.ci_high)).collect(),
        }];
        tornado(
            &at.join(&file),
            &format!("{q}: rank correlation with each input (n = {})", rho[0].n),
            &format!(
                "Spearman ρ (1); whiskers: {:.0} % interval",
                rho[0].confidence * 100.0
            ),
            &names,
            &series,
            -1.05..1.05,
        )?;
        section.spearman = Some(file);
        let top = &names[0];
        let (x, y) = (
            data::strided_column(info, top, SCATTER_POINTS)?,
            data::strided_column(info, q, SCATTER_POINTS)?,
        );
        let pairs: Vec<(f64, f64)> = x
            .into_iter()
            .zip(y)
            .filter(|(a, b)| a.is_finite() && b.is_finite())
            .collect();
        if pairs.len() >= 2 {
            let file = format!("scatter_{stem}.svg");
            let note = format!(
                "{} instances, Spearman ρ = {:+.2}",
                pairs.len(),
                rho[0].value
            );
            scatter(&at.join(&file), top, q, &pairs, &note, rho[0].value >= 0.0)?;
            section.scatter = Some((file, top.clone()));
        }
    }
    let (first, total) = (rows_of("sobol_first"), rows_of("sobol_total"));
    if !first.is_empty() {
        let mut names: Vec<String> = first.iter().filter_map(|r| r.input.clone()).collect();
        let total_of = |name: &str| {
            total
                .iter()
                .find(|r| r.input.as_deref() == Some(name))
                .map_or((f64::NAN, f64::NAN, f64::NAN), |r| {
                    (r.value, r.ci_low, r.ci_high)
                })
        };
        names.sort_by(|a, b| total_of(b).0.total_cmp(&total_of(a).0));
        let first_of = |name: &str| {
            first
                .iter()
                .find(|r| r.input.as_deref() == Some(name))
                .map_or((f64::NAN, f64::NAN, f64::NAN), |r| {
                    (r.value, r.ci_low, r.ci_high)
                })
        };
        let series = [
            BarSeries {
                label: "first order S_i".into(),
                colour: BLUE,
                values: names.iter().map(|n| first_of(n)).collect(),
            },
            BarSeries {
                label: "total S_Ti".into(),
                colour: ORANGE,
                values: names.iter().map(|n| total_of(n)).collect(),
            },
        ];
        let all = series.iter().flat_map(|s| s.values.iter());
        let lo = all
            .clone()
            .map(|v| v.1.min(v.0))
            .filter(|v| v.is_finite())
            .fold(0.0, f64::min);
        let hi = all
            .map(|v| v.2.max(v.0))
            .filter(|v| v.is_finite())
            .fold(1.0, f64::max);
        let file = format!("sobol_{stem}.svg");
        tornado(
            &at.join(&file),
            &format!(
                "{q}: Sobol indices, bootstrap intervals (n = {} groups)",
                first[0].n
            ),
            "Sobol index (1)",
            &names,
            &series,
            (lo - 0.05)..(hi + 0.05),
        )?;
        section.sobol = Some(file);
    }
    Ok(section)
}

/// One set of bars of a tornado chart: an estimate per row with its interval.
pub struct BarSeries {
    pub label: String,
    pub colour: RGBColor,
    /// (value, ci_low, ci_high) per row; NaN bounds draw no whisker.
    pub values: Vec<(f64, f64, f64)>,
}

/// Horizontal bars per input (rows top to bottom), each series side by side, with whiskers for
/// the intervals and a zero line.
pub fn tornado(
    path: &Path,
    title: &str,
    x_desc: &str,
    rows: &[String],
    series: &[BarSeries],
    x_range: std::ops::Range<f64>,
) -> Result<(), ReportError> {
    let e = plot_err(path);
    let k = rows.len().max(1);
    let height = 150 + 26 * k as u32 * series.len().max(1) as u32 + 10 * k as u32;
    let longest = rows.iter().map(|r| r.chars().count()).max().unwrap_or(4);
    let left = (longest as f64 * 8.2 + 24.0).max(80.0) as u32;
    let root =
        SVGBackend::new(path, (SIZE.0 + left.saturating_sub(80), height)).into_drawing_area();
    root.fill(&WHITE).map_err(&e)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, font(17.0))
        .margin(14)
        .x_label_area_size(58)
        .y_label_area_size(left)
        .build_cartesian_2d(x_range.clone(), -0.5..(k as f64 - 0.5))
        .map_err(&e)?;
    mesh_style(&mut chart.configure_mesh())
        .x_desc(x_desc)
        .x_labels(9)
        .y_labels(0)
        .disable_y_mesh()
        .draw()
        .map_err(&e)?;
    let s = series.len().max(1) as f64;
    let band = 0.8 / s;
    for (j, ser) in series.iter().enumerate() {
        let c = ser.colour;
        let centre = |i: usize| (k - 1 - i) as f64 + 0.4 - band * (j as f64 + 0.5);
        chart
            .draw_series(ser.values.iter().enumerate().map(|(i, &(v, _, _))| {
                let y = centre(i);
                Rectangle::new([(0.0, y - 0.4 * band), (v, y + 0.4 * band)], c.filled())
            }))
            .map_err(&e)?
            .label(ser.label.clone())
            .legend(move |(x, y)| Rectangle::new([(x, y - 6), (x + 22, y + 6)], c.filled()));
        for (i, &(_, lo, hi)) in ser.values.iter().enumerate() {
            if !(lo.is_finite() && hi.is_finite()) {
                continue;
            }
            let y = centre(i);
            let cap = 0.25 * band;
            let whisker = BLACK.stroke_width(2);
            chart
                .draw_series([
                    PathElement::new(vec![(lo, y), (hi, y)], whisker),
                    PathElement::new(vec![(lo, y - cap), (lo, y + cap)], whisker),
                    PathElement::new(vec![(hi, y - cap), (hi, y + cap)], whisker),
                ])
                .map_err(&e)?;
        }
    }
    chart
        .draw_series(std::iter::once(PathElement::new(
            vec![(0.0, -0.5), (0.0, k as f64 - 0.5)],
            BLACK.stroke_width(1),
        )))
        .map_err(&e)?;
    // Row names beside the plotting area, right-aligned against it.
    let x_left = x_range.start;
    for (i, name) in rows.iter().enumerate() {
        let (px, py) = chart.backend_coord(&(x_left, (k - 1 - i) as f64));
        root.draw(&Text::new(
            name.clone(),
            (px - 10, py),
            font(14.0).pos(Pos::new(HPos::Right, VPos::Center)),
        ))
        .map_err(&e)?;
    }
    if series.len() < 2 {
        root.present().map_err(&e)?;
        return Ok(());
    }
    legend_style(&mut chart.configure_series_labels())
        .position(SeriesLabelPosition::LowerRight)
        .draw()
        .map_err(&e)?;
    root.present().map_err(&e)?;
    Ok(())
}

/// A scatter of one QoI against one input, pairs with a null left out.
pub fn scatter(
    path: &Path,
    x_col: &str,
    y_col: &str,
    pairs: &[(f64, f64)],
    note: &str,
    rising: bool,
) -> Result<(), ReportError> {
    let e = plot_err(path);
    let root: DrawingArea<SVGBackend, Shift> = SVGBackend::new(path, SIZE).into_drawing_area();
    root.fill(&WHITE).map_err(&e)?;
    let bounds = |f: fn(&(f64, f64)) -> f64| {
        pairs
            .iter()
            .map(f)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(v), b.max(v))
            })
    };
    let (x0, x1) = bounds(|p| p.0);
    let (y0, y1) = bounds(|p| p.1);
    let mut chart = ChartBuilder::on(&root)
        .caption(format!("{y_col} against {x_col}"), font(17.0))
        .margin(14)
        .x_label_area_size(58)
        .y_label_area_size(84)
        .build_cartesian_2d(padded(x0, x1), padded(y0, y1))
        .map_err(&e)?;
    mesh_style(&mut chart.configure_mesh())
        .x_desc(label(x_col))
        .y_desc(label(y_col))
        .x_labels(7)
        .y_labels(7)
        .draw()
        .map_err(&e)?;
    chart
        .draw_series(
            pairs
                .iter()
                .map(|&(x, y)| Circle::new((x, y), 3, BLUE.mix(0.55).filled())),
        )
        .map_err(&e)?
        .label(note)
        .legend(|(x, y)| Circle::new((x + 10, y), 4, BLUE.filled()));
    legend_style(&mut chart.configure_series_labels())
        // The corner the points leave empty: upper left when the QoI rises with the input.
        .position(if rising {
            SeriesLabelPosition::UpperLeft
        } else {
            SeriesLabelPosition::UpperRight
        })
        .draw()
        .map_err(&e)?;
    root.present().map_err(&e)?;
    Ok(())
}
