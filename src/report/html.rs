//! The report's `index.html`: one static page, its style inline, its plots as `<img>` of the SVG
//! files beside it — nothing fetched from the network and no script, so it opens from a file
//! system, an archive or an air-gapped review machine alike.

use super::data::{unit_of, RunInfo, StatRow};
use super::worst::WorstCase;
use super::{fmt_p, QoiSection, SensitivitySection};
use std::fmt::Write as _;

/// Everything the page shows.
pub(crate) struct Page<'a> {
    pub info: &'a RunInfo,
    pub confidence: f64,
    pub sections: &'a [QoiSection],
    pub skipped: &'a [String],
    pub sensitivities: &'a [SensitivitySection],
    pub probabilities: &'a [StatRow],
    pub worst: &'a [WorstCase],
    pub worst_notes: &'a [String],
}

/// `s` with the five HTML special characters escaped.
pub(crate) fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// A value with six significant digits (`–` for none).
pub(crate) fn num(v: f64) -> String {
    if !v.is_finite() {
        return "–".into();
    }
    let a = v.abs();
    if a != 0.0 && !(1e-4..1e9).contains(&a) {
        return format!("{v:.5e}");
    }
    let decimals = if a == 0.0 {
        0
    } else {
        (5 - a.log10().floor() as i32).clamp(0, 9) as usize
    };
    let s = format!("{v:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

pub(crate) const STYLE: &str =
    "body{font-family:sans-serif;font-size:16px;line-height:1.4;margin:24px;\
color:#111;max-width:1600px}h1{font-size:26px}h2{font-size:22px;margin-top:36px;\
border-bottom:2px solid #0072B2}h3{font-size:18px;margin-top:24px}table{border-collapse:collapse;\
margin:8px 0}td,th{border:1px solid #bbb;padding:3px 8px;text-align:right}th{background:#eef4f8}\
td:first-child,th:first-child{text-align:left}.plots{display:flex;flex-wrap:wrap;gap:12px}\
img{max-width:100%;height:auto;border:1px solid #ddd}pre{background:#f6f6f6;padding:8px;\
overflow-x:auto;font-size:13px}.note{color:#444}table.kv td{text-align:left}";

/// The page as HTML text.
pub(crate) fn render(p: &Page) -> String {
    let info = p.info;
    let c = &info.run.campaign;
    let mut h = String::new();
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <title>cryoslosh report: {}</title>\n<style>{STYLE}</style>\n</head>\n<body>\n\
         <h1>Campaign <code>{}</code></h1>\n",
        escape(&c.name),
        escape(&c.name)
    );
    let count = |v: Option<u64>| v.map_or("–".to_string(), |n| n.to_string());
    let header = [
        ("results directory", info.dir.display().to_string()),
        ("campaign file", c.path.display().to_string()),
        ("design", info.design.clone()),
        ("instances", info.instances.to_string()),
        ("diverged", count(info.diverged)),
        ("rejected", count(info.rejected)),
        ("depleted (tank ran dry)", count(info.depleted)),
        ("seed", info.run.seed.to_string()),
        ("fidelity", info.fidelity.clone()),
        ("integrator", info.integrator.clone()),
        ("backend", info.device.clone()),
        ("shard", info.shard.clone()),
        ("cryoslosh version", info.version.clone()),
        (
            "wall time",
            info.wall_s
                .map_or("–".into(), |w| match info.merged_shards {
                    0 => format!("{w:.2} s"),
                    n => format!("{w:.2} s, the {n} shards' summed"),
                }),
        ),
    ];
    h.push_str("<table class=\"kv\">\n");
    for (k, v) in header {
        let _ = writeln!(h, "<tr><th>{k}</th><td>{}</td></tr>", escape(&v));
    }
    h.push_str("</table>\n");
    let _ = write!(
        h,
        "<details><summary>campaign text (with its overrides)</summary>\n<pre>{}</pre>\n</details>\n",
        escape(&c.text)
    );
    h.push_str(
        "<p class=\"note\">Contents: <a href=\"#qois\">quantities of interest</a> · \
         <a href=\"#sensitivities\">sensitivities</a> · <a href=\"#probabilities\">flags and \
         probabilities</a> · <a href=\"#worst\">worst cases</a></p>\n",
    );
    qois(&mut h, p);
    sensitivities(&mut h, p);
    probabilities(&mut h, p);
    worst(&mut h, p);
    h.push_str("</body>\n</html>\n");
    h
}

fn img(h: &mut String, file: &str, alt: &str) {
    let _ = writeln!(
        h,
        "<img src=\"{}\" alt=\"{}\" loading=\"eager\">",
        escape(file),
        escape(alt)
    );
}

fn qois(h: &mut String, p: &Page) {
    let pct = format!("{:.0} %", p.confidence * 100.0);
    let _ = write!(
        h,
        "<h2 id=\"qois\">Quantities of interest</h2>\n<p class=\"note\">Each quantity of \
         <code>instances.parquet</code> with a spread, over its valid instances (diverged and \
         rejected ones are nulls and left out). The exceedance curve is the fraction of instances \
         at or above x (at or below x for a <code>min_</code> margin, whose low tail matters); \
         its band is the pointwise exact Clopper–Pearson {pct} interval of that fraction. Vertical lines: the thresholds <code>statistics.parquet</code> evaluated \
         (MEOP, boil-off budget, zero cavitation margin, <code>[[statistics.thresholds]]</code>). \
         The tables are <code>statistics.parquet</code>'s rows: quantiles with their \
         distribution-free intervals and one-sided Wilks tolerance bounds.</p>\n"
    );
    if !p.skipped.is_empty() {
        h.push_str("<p class=\"note\">Not drawn:</p>\n<ul class=\"note\">\n");
        for s in p.skipped {
            let _ = writeln!(h, "<li>{}</li>", escape(s));
        }
        h.push_str("</ul>\n");
    }
    for s in p.sections {
        let unit = unit_of(&s.name);
        let _ = writeln!(
            h,
            "<h3 id=\"q-{}\"><code>{}</code> ({}) — {} valid instances</h3>",
            escape(&super::file_stem(&s.name)),
            escape(&s.name),
            escape(unit),
            s.n
        );
        h.push_str("<div class=\"plots\">\n");
        img(h, &s.histogram, &format!("histogram of {}", s.name));
        img(h, &s.exceedance, &format!("exceedance curve of {}", s.name));
        h.push_str("</div>\n");
        if !s.off_scale.is_empty() {
            let _ = writeln!(
                h,
                "<p class=\"note\">Thresholds off the plotted range: {}.</p>",
                escape(&s.off_scale.join("; "))
            );
        }
        if s.rows.is_empty() {
            continue;
        }
        let _ = writeln!(
            h,
            "<table><tr><th>statistic</th><th>p or coverage</th><th>confidence</th>\
             <th>value ({u})</th><th>ci_low ({u})</th><th>ci_high ({u})</th><th>n</th></tr>",
            u = escape(unit)
        );
        for r in &s.rows {
            let _ = writeln!(
                h,
                "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
                escape(&r.statistic),
                num(r.probability),
                num(r.confidence),
                num(r.value),
                num(r.ci_low),
                num(r.ci_high),
                r.n
            );
        }
        h.push_str("</table>\n");
    }
}

fn sensitivities(h: &mut String, p: &Page) {
    h.push_str(
        "<h2 id=\"sensitivities\">Sensitivities</h2>\n<p class=\"note\">Spearman rank correlation \
         of each QoI with each dispersed input (Fisher-z interval with the Bonett–Wright \
         variance), largest |ρ| first; Sobol first-order and total indices with bootstrap \
         percentile intervals when the design is <code>saltelli</code>; and a scatter of the QoI \
         against its top driver (at most 4000 instances, an even stride).</p>\n",
    );
    if p.sensitivities.is_empty() {
        h.push_str("<p>No sensitivities in <code>statistics.parquet</code> (no dispersed input, or no QoI with a spread).</p>\n");
    }
    for s in p.sensitivities {
        let _ = writeln!(
            h,
            "<h3><code>{}</code></h3>\n<div class=\"plots\">",
            escape(&s.qoi)
        );
        if let Some(f) = &s.spearman {
            img(h, f, &format!("Spearman tornado of {}", s.qoi));
        }
        if let Some(f) = &s.sobol {
            img(h, f, &format!("Sobol indices of {}", s.qoi));
        }
        if let Some((f, input)) = &s.scatter {
            img(h, f, &format!("{} against {input}", s.qoi));
        }
        h.push_str("</div>\n");
    }
}

fn probabilities(h: &mut String, p: &Page) {
    h.push_str(
        "<h2 id=\"probabilities\">Flags and probabilities</h2>\n<p class=\"note\">Every \
         probability of <code>statistics.parquet</code> with its exact Clopper–Pearson interval: \
         the shares of diverged and rejected instances (of all), of depleted, \
         pressurant-exhausted and slosh-out-of-range ones (of the valid), and each threshold's \
         exceedance.</p>\n\
         <table><tr><th>quantity</th><th>statistic</th><th>threshold</th><th>probability</th>\
         <th>ci_low</th><th>ci_high</th><th>confidence</th><th>n</th></tr>\n",
    );
    for r in p.probabilities {
        let threshold = if r.threshold.is_finite() {
            format!("{} {}", num(r.threshold), unit_of(&r.quantity))
        } else {
            "–".into()
        };
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            escape(&r.quantity),
            escape(&r.statistic),
            escape(&threshold),
            fmt_p(r.value),
            fmt_p(r.ci_low),
            fmt_p(r.ci_high),
            num(r.confidence),
            r.n
        );
    }
    h.push_str("</table>\n");
}

fn worst(h: &mut String, p: &Page) {
    let _ = writeln!(
        h,
        "<h2 id=\"worst\">Worst cases</h2>\n<p class=\"note\">The {} instances with the worst \
         values of each headline QoI (largest; smallest for a <code>min_</code> margin), integrated \
         again on the CPU from the run's metadata (exact replay, as <code>simulate --run DIR \
         --instance I</code>). Grey vertical lines: phase boundaries; shaded: relief valve \
         open.</p>",
        super::worst::WORST_PER_QOI
    );
    if p.info.device.starts_with("gpu") {
        h.push_str(
            "<p class=\"note\">This run was integrated on the GPU in f32: the CPU's f64 replay \
             differs from its row in the last digits (and, under dopri5, in its step count).</p>\n",
        );
    }
    for n in p.worst_notes {
        let _ = writeln!(h, "<p class=\"note\">{}</p>", escape(n));
    }
    for w in p.worst {
        let _ = writeln!(
            h,
            "<h3><code>{}</code> #{}: instance {} ({} {})</h3>",
            escape(&w.qoi),
            w.rank,
            w.instance,
            num(w.value),
            escape(unit_of(&w.qoi))
        );
        img(
            h,
            &w.file,
            &format!("time history of instance {}", w.instance),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes_and_formats() {
        assert_eq!(escape("a<b & \"c\""), "a&lt;b &amp; &quot;c&quot;");
        assert_eq!(num(125270.982213), "125271");
        assert_eq!(num(0.156699), "0.156699");
        assert_eq!(num(f64::NAN), "–");
        assert_eq!(num(0.0), "0");
    }
}
