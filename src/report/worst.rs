//! Worst cases: the instances with the worst values of each headline QoI, integrated again by the
//! run's exact replay (`simulate --run DIR --instance I`), drawn as stacked time histories —
//! pressure against MEOP and the relief crack, the four temperatures, fill level, slosh angle and
//! cavitation margin — with phase boundaries, relief-valve openings and the outcome events
//! (cavitation onset and end, tank dry, pressurant exhausted, bulk merged) marked.

use super::data::{label, unit_of, RunInfo};
use super::plots::{
    draw_keys, fmt_tick, font, mesh_style, padded, plot_err, Key, BLUE, GREEN, GREY, ORANGE,
    PURPLE, VERMILLION,
};
use super::ReportError;
use crate::montecarlo::histories::worst_is_smallest;
use crate::montecarlo::plan::Plan;
use crate::montecarlo::{replay, table};
use crate::simulate::History;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

/// The QoIs whose worst instances are re-simulated ([`WORST_PER_QOI`] each).
pub const HEADLINE: [&str; 4] = [
    "peak_pressure_pa",
    "boiloff_kg",
    "min_cavitation_margin_m",
    "max_slosh_angle_rad",
];

/// Instances re-simulated per headline QoI: the worst and its runners-up, so that a designer
/// sees whether the worst is alone or one of a kind.
pub const WORST_PER_QOI: usize = 3;

/// "worst", "2nd worst", "3rd worst", …
fn ordinal(rank: usize) -> String {
    match rank {
        0 => "worst".into(),
        1 => "2nd worst".into(),
        2 => "3rd worst".into(),
        n => format!("{}th worst", n + 1),
    }
}

/// One worst case drawn.
#[derive(Clone, Debug)]
pub struct WorstCase {
    pub qoi: String,
    /// 1 for the worst instance of `qoi`, 2 for the next, …
    pub rank: usize,
    pub instance: u64,
    pub value: f64,
    /// The SVG file name in the report directory.
    pub file: String,
}

/// Find, replay and draw the worst instance of each QoI in `qois` (the headline ones the run
/// has with a spread); returns what was drawn and a note per QoI that could not be.
pub fn worst_cases(
    info: &RunInfo,
    qois: &[String],
    out: &Path,
    progress: bool,
) -> Result<(Vec<WorstCase>, Vec<String>), ReportError> {
    let path = info.instances_file();
    let ids = table::read_u64(&path, "instance").map_err(|e| ReportError::read(&path, e))?;
    let mut picks = Vec::new();
    for q in qois {
        let v = table::read_f64(&path, q).map_err(|e| ReportError::read(&path, e))?;
        let smallest = worst_is_smallest(q);
        let mut rows: Vec<usize> = (0..v.len()).filter(|&r| v[r].is_finite()).collect();
        // Worst first; ties by instance index (as `run --histories worst:`).
        rows.sort_by(|&a, &b| {
            let order = v[a].total_cmp(&v[b]);
            let order = if smallest { order } else { order.reverse() };
            order.then(ids[a].cmp(&ids[b]))
        });
        for (rank, &r) in rows.iter().take(WORST_PER_QOI).enumerate() {
            picks.push((q.clone(), rank, ids[r], v[r]));
        }
    }
    drop(ids);
    let mut drawn = Vec::new();
    let mut notes = Vec::new();
    let bar = crate::montecarlo::progress_bar_of(
        progress,
        picks.len() as u64,
        "worst cases re-simulated",
    );
    // A bar on a terminal; a line per re-simulation in a log.
    let lines = progress && !std::io::IsTerminal::is_terminal(&std::io::stderr());
    for (k, (q, rank, i, value)) in picks.iter().enumerate() {
        bar.inc(1);
        if lines {
            crate::eprintln_lossy!(
                "report: re-simulating worst case {}/{} (instance {i}, {q})",
                k + 1,
                picks.len()
            );
        }
        let mut h = History::default();
        let (run, record) =
            replay::replay(&info.dir, *i, Some(&mut h)).map_err(|e| ReportError::Replay {
                instance: *i,
                message: e.to_string(),
            })?;
        if record.rejected || h.is_empty() {
            notes.push(format!(
                "{q}: instance {i} was rejected; no history to draw"
            ));
            continue;
        }
        let plan = Plan {
            campaign: &run.campaign,
            seed: run.seed,
            total: run.total,
        };
        // The instance's own MEOP and crack (they may be dispersed).
        let params = match plan.resolve(*i).1 {
            Ok(Some(c)) => c.params,
            _ => run.campaign.params,
        };
        // The worst keeps the plain name; the runners-up are numbered from 2 (`worst2_…`).
        let file = match rank {
            0 => format!("worst_{}.svg", super::file_stem(q)),
            n => format!("worst{}_{}.svg", n + 1, super::file_stem(q)),
        };
        let title = format!(
            "{} {q}: instance {i}, {} {}",
            ordinal(*rank),
            fmt_tick(*value),
            unit_of(q)
        );
        use crate::simulate::events::EventKind as K;
        let lines = Limits {
            meop_pa: params.meop_pa,
            crack_pa: params.relief.as_ref().map(|r| r.crack_pa),
            events: record
                .summary
                .events
                .iter()
                .filter(|e| {
                    matches!(
                        e.kind,
                        K::CavitationOnset
                            | K::CavitationEnd
                            | K::Depleted
                            | K::PressurantExhausted
                            | K::BulkMerged
                    )
                })
                .map(|e| e.time_s)
                .collect(),
        };
        draw_history(&out.join(&file), &title, &h, &lines)?;
        drawn.push(WorstCase {
            qoi: q.clone(),
            rank: *rank + 1,
            instance: *i,
            value: *value,
            file,
        });
    }
    bar.finish_and_clear();
    Ok((drawn, notes))
}

/// Shading of the intervals where the relief valve is open (light vermillion).
const OPEN_VALVE: RGBColor = RGBColor(245, 214, 190);

/// Pressure limits drawn on the pressure panel.
struct Limits {
    meop_pa: f64,
    crack_pa: Option<f64>,
    /// Times of the instance's outcome events (cavitation onset and end, tank dry, pressurant
    /// exhausted, bulk merged; `simulate::events`), s, marked in every panel.
    events: Vec<f64>,
}

/// The colour of the outcome-event marks (black: distinct from every series).
const EVENT: RGBColor = RGBColor(0, 0, 0);

/// One panel of the stacked time history.
struct Panel<'a> {
    y_desc: String,
    /// Unit of the y axis, for the reference lines' legend.
    unit: &'static str,
    lines: Vec<(&'a str, RGBColor)>,
    hlines: Vec<(String, f64, RGBColor)>,
}

/// Runs of (time, value) points of one history column.
type Segments = Vec<Vec<(f64, f64)>>;

/// Points of a history column against time, split at nulls (NaN) into runs, each thinned to at
/// most ~2000 points by keeping every bucket's minimum and maximum (so peaks survive).
fn segments(t: &[f64], y: &[f64]) -> Segments {
    let mut out: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut run: Vec<(f64, f64)> = Vec::new();
    for (&a, &b) in t.iter().zip(y) {
        if b.is_finite() {
            run.push((a, b));
        } else if !run.is_empty() {
            out.push(std::mem::take(&mut run));
        }
    }
    if !run.is_empty() {
        out.push(run);
    }
    out.into_iter()
        .map(|s| {
            if s.len() <= 2000 {
                return s;
            }
            let bucket = s.len().div_ceil(1000);
            let mut thin = Vec::with_capacity(2002);
            for chunk in s.chunks(bucket) {
                let lo = chunk.iter().min_by(|a, b| a.1.total_cmp(&b.1));
                let hi = chunk.iter().max_by(|a, b| a.1.total_cmp(&b.1));
                if let (Some(&lo), Some(&hi)) = (lo, hi) {
                    let (first, second) = if lo.0 <= hi.0 { (lo, hi) } else { (hi, lo) };
                    thin.push(first);
                    thin.push(second);
                }
            }
            thin
        })
        .collect()
}

/// Time intervals in which the relief valve was open: rows flagged `valve_open`, and output
/// intervals over which `vented_kg` grew (an opening shorter than one output interval falls
/// between two rows and shows only there).
fn valve_intervals(t: &[f64], valve_open: &[bool], vented_kg: &[f64]) -> Vec<(f64, f64)> {
    let mut open: Vec<(f64, f64)> = Vec::new();
    for r in 0..t.len() {
        let vented = r > 0 && vented_kg.get(r) > vented_kg.get(r - 1);
        let start = if vented { t[r - 1] } else { t[r] };
        if valve_open[r] || vented {
            match open.last_mut() {
                Some(last) if last.1 >= start => last.1 = t[r],
                _ => open.push((start, t[r])),
            }
        }
    }
    open
}

/// Draw the stacked panels of one instance's history into `path`.
fn draw_history(path: &Path, title: &str, h: &History, limits: &Limits) -> Result<(), ReportError> {
    let e = plot_err(path);
    let col = |name: &str| h.column(name).unwrap_or(&[]);
    let t = col("time_s");
    let mut pressure = vec![("MEOP".to_string(), limits.meop_pa, VERMILLION)];
    if let Some(c) = limits.crack_pa {
        pressure.push(("relief crack".to_string(), c, PURPLE));
    }
    let panels = [
        Panel {
            y_desc: label("pressure_pa"),
            unit: "Pa",
            lines: vec![("pressure_pa", BLUE)],
            hlines: pressure,
        },
        Panel {
            y_desc: "temperature (K)".into(),
            unit: "K",
            lines: vec![
                ("ullage_temp_k", VERMILLION),
                ("layer_temp_k", ORANGE),
                ("bulk_temp_k", BLUE),
                ("wall_temp_k", GREEN),
            ],
            hlines: vec![],
        },
        Panel {
            y_desc: label("fill_fraction"),
            unit: "1",
            lines: vec![("fill_fraction", BLUE)],
            hlines: vec![],
        },
        Panel {
            y_desc: label("slosh_angle_rad"),
            unit: "rad",
            lines: vec![("slosh_angle_rad", BLUE)],
            hlines: vec![],
        },
        Panel {
            y_desc: label("cavitation_margin_m"),
            unit: "m",
            lines: vec![("cavitation_margin_m", BLUE)],
            hlines: vec![("zero margin".into(), 0.0, VERMILLION)],
        },
    ];
    // Phase boundaries: where the phase name changes, at the last row of the phase ending.
    let mut phases = vec![(t[0], h.phase[0].clone())];
    for r in 1..h.len() {
        if h.phase[r] != h.phase[r - 1] {
            phases.push((t[r - 1], h.phase[r].clone()));
        }
    }
    let open = valve_intervals(t, &h.valve_open, col("vented_kg"));
    let (w, ph) = (1060u32, 250u32);
    let root = SVGBackend::new(path, (w, 50 + ph * panels.len() as u32)).into_drawing_area();
    root.fill(&WHITE).map_err(&e)?;
    let root = root.titled(title, font(18.0)).map_err(&e)?;
    let areas = root.split_evenly((panels.len(), 1));
    let t_range = padded(t[0], t[t.len() - 1]);
    for (k, (panel, area)) in panels.iter().zip(&areas).enumerate() {
        let series: Vec<(&str, RGBColor, Segments)> = panel
            .lines
            .iter()
            .map(|&(name, c)| (name, c, segments(t, col(name))))
            .collect();
        let ys = series
            .iter()
            .flat_map(|s| s.2.iter().flatten().map(|p| p.1));
        let (lo, hi) = ys.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
        let no_data = !lo.is_finite();
        let (lo, hi) = if no_data { (0.0, 1.0) } else { (lo, hi) };
        let span = (hi - lo).max(hi.abs() * 1e-3).max(1e-9);
        let hlines: Vec<&(String, f64, RGBColor)> = panel
            .hlines
            .iter()
            .filter(|l| !no_data && l.1 >= lo - 3.0 * span && l.1 <= hi + 3.0 * span)
            .collect();
        let off_scale: Vec<&(String, f64, RGBColor)> = panel
            .hlines
            .iter()
            .filter(|l| !no_data && !hlines.iter().any(|s| s.1 == l.1))
            .collect();
        let lo2 = hlines.iter().map(|l| l.1).fold(lo, f64::min);
        let hi2 = hlines.iter().map(|l| l.1).fold(hi, f64::max);
        // Room above the data of the first panel for the phase names.
        let headroom = if k == 0 {
            0.22 * (hi2 - lo2).max(span)
        } else {
            0.0
        };
        let mut chart = ChartBuilder::on(area)
            .margin(8)
            .margin_right(260)
            .x_label_area_size(if k + 1 == panels.len() { 50 } else { 26 })
            .y_label_area_size(88)
            .build_cartesian_2d(t_range.clone(), padded(lo2, hi2 + headroom))
            .map_err(&e)?;
        // A tick at zero computed as lo + k·step can land a rounding error off it (−2.8e-17).
        let y_scale = lo2.abs().max(hi2.abs()).max(f64::MIN_POSITIVE);
        let y_tick = move |v: &f64| fmt_tick(if v.abs() < 1e-9 * y_scale { 0.0 } else { *v });
        let mut mesh = chart.configure_mesh();
        // Stacked panels: a point smaller text than the single charts.
        mesh_style(&mut mesh)
            .y_desc(panel.y_desc.as_str())
            .x_labels(10)
            .y_labels(5)
            .y_label_formatter(&y_tick)
            .label_style(font(13.0))
            .axis_desc_style(font(15.0));
        if k + 1 == panels.len() {
            mesh.x_desc(label("time_s"));
        }
        mesh.draw().map_err(&e)?;
        let (y0, y1) = (lo2 - span, hi2 + span);
        let mut legend: Vec<(String, RGBColor, bool)> = Vec::new();
        chart
            .draw_series(open.iter().map(|&(a, b)| {
                // At least 0.4 % of the mission wide: an opening shorter than one output
                // interval still shows.
                let min = 0.004 * (t_range.end - t_range.start);
                let (a, b) = if b - a < min {
                    (a - 0.5 * min, a + 0.5 * min)
                } else {
                    (a, b)
                };
                Rectangle::new([(a, y0), (b, y1)], OPEN_VALVE.filled())
            }))
            .map_err(&e)?;
        chart
            .draw_series(
                limits
                    .events
                    .iter()
                    .map(|&te| PathElement::new(vec![(te, y0), (te, y1)], EVENT.stroke_width(1))),
            )
            .map_err(&e)?;
        if !limits.events.is_empty() && k == 0 {
            let n = limits.events.len();
            legend.push((
                format!(
                    "{n} event{}: cavitation, dry, bottle",
                    if n == 1 { "" } else { "s" }
                ),
                EVENT,
                false,
            ));
        }
        if !open.is_empty() && k == 0 {
            let n = open.len();
            let text = format!(
                "relief valve open ({n} opening{})",
                if n == 1 { "" } else { "s" }
            );
            legend.push((text, OPEN_VALVE, true));
        }
        chart
            .draw_series(
                phases.iter().skip(1).map(|&(tb, _)| {
                    PathElement::new(vec![(tb, y0), (tb, y1)], GREY.stroke_width(1))
                }),
            )
            .map_err(&e)?;
        for (name, c, segs) in &series {
            for s in segs {
                chart
                    .draw_series(LineSeries::new(s.iter().copied(), c.stroke_width(2)))
                    .map_err(&e)?;
            }
            if !segs.is_empty() {
                legend.push((name.to_string(), *c, false));
            }
        }
        for (name, v, c) in &hlines {
            chart
                .draw_series(LineSeries::new(
                    vec![(t_range.start, *v), (t_range.end, *v)],
                    c.stroke_width(2),
                ))
                .map_err(&e)?;
            legend.push((format!("{name} {} {}", fmt_tick(*v), panel.unit), *c, false));
        }
        for (name, v, _) in &off_scale {
            let side = if *v > hi { "above" } else { "below" };
            legend.push((
                format!("{name} {} {} (off scale, {side})", fmt_tick(*v), panel.unit),
                GREY,
                false,
            ));
        }
        let (xr, yr) = chart.plotting_area().get_pixel_range();
        if no_data {
            area.draw(&Text::new(
                "no value in this instance (the engine never drew)",
                (
                    (xr.start + xr.end) / 2 - area.get_base_pixel().0,
                    (yr.start + yr.end) / 2 - area.get_base_pixel().1,
                ),
                font(15.0).pos(Pos::new(HPos::Center, VPos::Center)),
            ))
            .map_err(&e)?;
        }
        // Legend in the right margin, outside the data.
        let base = area.get_base_pixel();
        let keys: Vec<Key> = legend
            .into_iter()
            .map(|(text, colour, block)| Key {
                text,
                colour,
                block,
            })
            .collect();
        draw_keys(
            area,
            (xr.end - base.0 + 14, yr.start - base.1 + 10),
            &keys,
            &e,
        )?;
        // Phase names along the top of the first panel.
        if k == 0 {
            // Up to three rows of names, so a short phase's name moves down instead of
            // overlapping its neighbour's.
            let mut rows: [Option<i32>; 3] = [None; 3];
            for (tb, name) in &phases {
                let (px, _) = chart.backend_coord(&(*tb, y1));
                let width = 14 + 7 * name.chars().count() as i32;
                let Some(row) = rows.iter().position(|l| l.is_none_or(|l| px >= l)) else {
                    continue;
                };
                rows[row] = Some(px + width);
                area.draw(&Text::new(
                    format!("▸ {name}"),
                    (px - base.0 + 2, yr.start - base.1 + 2 + 15 * row as i32),
                    font(12.0).color(&GREY).pos(Pos::new(HPos::Left, VPos::Top)),
                ))
                .map_err(&e)?;
            }
        }
    }
    root.present().map_err(&e)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn valve_openings_come_from_flags_and_vented_mass() {
        let t = [0.0, 10.0, 20.0, 30.0, 40.0, 50.0];
        let flag = [false, true, true, false, false, false];
        let vented = [0.0, 0.1, 0.2, 0.2, 0.5, 0.5];
        // Rows 1–2 flagged (and venting from row 0 on); rows 3→4 vented between samples.
        assert_eq!(
            valve_intervals(&t, &flag, &vented),
            vec![(0.0, 20.0), (30.0, 40.0)]
        );
        assert!(valve_intervals(&t, &[false; 6], &[0.0; 6]).is_empty());
    }

    #[test]
    fn segments_break_at_nulls_and_keep_peaks() {
        let t: Vec<f64> = (0..10).map(f64::from).collect();
        let y = [
            1.0,
            2.0,
            f64::NAN,
            f64::NAN,
            5.0,
            6.0,
            7.0,
            f64::NAN,
            9.0,
            10.0,
        ];
        let s = segments(&t, &y);
        assert_eq!(s.len(), 3);
        assert_eq!(s[1], vec![(4.0, 5.0), (5.0, 6.0), (6.0, 7.0)]);
        let t: Vec<f64> = (0..100_000).map(f64::from).collect();
        let mut y = vec![0.0; 100_000];
        y[54_321] = 9.0;
        let s = segments(&t, &y);
        assert!(s[0].len() <= 2002);
        assert!(s[0].contains(&(54_321.0, 9.0)));
    }
}
