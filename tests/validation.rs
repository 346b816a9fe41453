//! Validation against published self-pressurization data (../shared/validation): MHTB (18 m³
//! LH2 tank, 1 g) and Aydelott's 23 cm LH2 sphere. The model is not fitted to these rows; the
//! ratios predicted / measured are printed for the README table and checked against the
//! acceptance window [0.75, 1.33], with the rows the lumped model is known to miss pinned to
//! their documented values (docs/VALIDATION.md explains why they miss).

mod common;
use common::{load, validation_csv};
use cryoslosh::simulate::{simulate, History};

const WINDOW: (f64, f64) = (0.75, 1.33);

/// Rows the lumped and layered levels miss, with the documented ratios (± 5 %): (tank, fill,
/// heat, lumped ratio, layered ratio).
const KNOWN_MISSES: [(&str, f64, f64, f64, f64); 2] = [
    ("mhtb", 0.90, 54.1, 0.65, 0.65),
    ("mhtb", 0.90, 20.2, 0.63, 0.64),
];

/// Least-squares slope of pressure over [t0, t1], Pa/s.
fn slope(h: &History, t0: f64, t1: f64) -> f64 {
    let (t, p) = (
        h.column("time_s").unwrap(),
        h.column("pressure_pa").unwrap(),
    );
    let pts: Vec<(f64, f64)> = t
        .iter()
        .zip(p)
        .filter(|(t, _)| **t >= t0 && **t <= t1)
        .map(|(a, b)| (*a, *b))
        .collect();
    let n = pts.len() as f64;
    let (mt, mp) = (
        pts.iter().map(|x| x.0).sum::<f64>() / n,
        pts.iter().map(|x| x.1).sum::<f64>() / n,
    );
    let num: f64 = pts.iter().map(|(t, p)| (t - mt) * (p - mp)).sum();
    let den: f64 = pts.iter().map(|(t, _)| (t - mt) * (t - mt)).sum();
    num / den
}

/// Rows of a validation CSV (comment lines skipped, header dropped); blank cells are None.
fn rows(name: &str) -> Vec<Vec<Option<f64>>> {
    let path = validation_csv(name);
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("{}: {e} (is ../shared beside the repo?)", path.display()));
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .skip(1)
        .map(|l| l.split(',').map(|c| c.trim().parse().ok()).collect())
        .collect()
}

/// Model rate for one row at one level, in the CSV's unit.
fn rate(tank: &str, fill: f64, q: f64, p0: Option<f64>, level: &str) -> f64 {
    let (campaign, t0, t1, unit) = match tank {
        "mhtb" => ("mhtb_selfpress", 1800.0, 14400.0, 3.6),
        _ => ("aydelott_sphere", 10.0, 120.0, 1.0e-3),
    };
    let mut sets = vec![
        format!("propellant.fill_fraction={fill}"),
        format!("tank.heat_leak_w={q}"),
        format!("campaign.fidelity={level}"),
        format!("ullage.pressure_pa={}", p0.unwrap_or(101_325.0)),
    ];
    // The sensitivity tables of docs/VALIDATION.md: extra `key=value` settings, `;`-separated;
    // `layered.*` keys go to the layered level only (the other levels refuse the section).
    if let Ok(extra) = std::env::var("CRYOSLOSH_VALIDATION_SET") {
        sets.extend(
            extra
                .split(';')
                .filter(|s| !s.is_empty() && (level == "layered" || !s.starts_with("layered.")))
                .map(String::from),
        );
    }
    let refs: Vec<&str> = sets.iter().map(String::as_str).collect();
    let c = load(campaign, &refs);
    let mut h = History::default();
    let s = simulate(&c, &c.params, Some(&mut h));
    assert!(!s.diverged, "{tank} {fill} {q}: {:?}", s.diverged_reason);
    slope(&h, t0, t1) * unit
}

#[test]
fn self_pressurization_rates_against_published_data() {
    let mut cases = Vec::new();
    for r in rows("mhtb_selfpress.csv") {
        cases.push((
            "mhtb",
            r[0].unwrap(),
            r[1].unwrap(),
            r[2].map(|kpa| kpa * 1e3),
            r[3].unwrap(),
        ));
    }
    for r in rows("aydelott_sphere.csv") {
        cases.push((
            "aydelott",
            r[0].unwrap(),
            r[1].unwrap(),
            None,
            r[2].unwrap(),
        ));
    }
    assert_eq!(cases.len(), 9);
    println!(
        "| tank | fill | Q (W) | measured | lumped | ratio | layered | ratio | homogeneous ratio |"
    );
    let mut failures = Vec::new();
    for (tank, fill, q, p0, measured) in cases {
        let lumped = rate(tank, fill, q, p0, "lumped");
        let layered = rate(tank, fill, q, p0, "layered");
        let homog = rate(tank, fill, q, p0, "homogeneous");
        let (ratio, ratio_layered) = (lumped / measured, layered / measured);
        println!(
            "| {tank} | {fill} | {q} | {measured} | {lumped:.3} | {ratio:.2} | {layered:.3} | \
             {ratio_layered:.2} | {:.2} |",
            homog / measured
        );
        let miss = KNOWN_MISSES
            .iter()
            .find(|m| m.0 == tank && m.1 == fill && m.2 == q);
        for (level, r, documented) in [
            ("lumped", ratio, miss.map(|m| m.3)),
            ("layered", ratio_layered, miss.map(|m| m.4)),
        ] {
            match documented {
                Some(d) if (r / d - 1.0).abs() > 0.05 => failures.push(format!(
                    "{tank} {fill} {q} {level}: ratio {r:.3} moved from the documented {d}"
                )),
                Some(_) => {}
                None if r < WINDOW.0 || r > WINDOW.1 => failures.push(format!(
                    "{tank} {fill} {q} {level}: ratio {r:.3} outside {WINDOW:?}"
                )),
                None => {}
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}
