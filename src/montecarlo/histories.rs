//! `run --histories worst:peak_pressure_pa:5,instance:17`: after a run, the time histories of
//! chosen instances (by index, or the worst N of a QoI) are integrated again on the CPU and
//! written to `DIR/histories/instance_<I>.parquet`, one file per instance, so the cases that size
//! a margin can be plotted without a second command.

use super::plan::Plan;
use super::table;
use super::RunError;
use crate::campaign::Campaign;
use crate::simulate::{simulate, History};
use std::path::{Path, PathBuf};

/// One item of `--histories`.
#[derive(Clone, Debug, PartialEq)]
pub enum Pick {
    /// Instance `I` (`instance:I`).
    Instance(u64),
    /// The `n` worst instances of a QoI (`worst:QOI:N`): the smallest for a `min_*` quantity
    /// (a margin), the largest otherwise; ties by instance index.
    Worst { quantity: String, n: u64 },
}

/// Whether the worst value of `quantity` is its smallest.
pub fn worst_is_smallest(quantity: &str) -> bool {
    quantity.starts_with("min_")
}

/// Parse a `--histories` list (comma-separated `instance:I` and `worst:QOI:N` items).
pub fn parse(spec: &str) -> Result<Vec<Pick>, String> {
    let bad = |item: &str, why: &str| {
        format!("--histories {item:?}: {why} (expected instance:I or worst:QOI:N, comma-separated)")
    };
    let mut picks = Vec::new();
    for item in spec.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let parts: Vec<&str> = item.split(':').collect();
        match parts.as_slice() {
            ["instance", i] => picks.push(Pick::Instance(
                i.parse()
                    .map_err(|_| bad(item, "the index is not an integer"))?,
            )),
            ["worst", q, n] => {
                if q.is_empty() {
                    return Err(bad(item, "the quantity is empty"));
                }
                let n: u64 = n.parse().map_err(|_| bad(item, "N is not an integer"))?;
                if n == 0 || n > 1000 {
                    return Err(bad(item, "N must lie in [1, 1000]"));
                }
                picks.push(Pick::Worst {
                    quantity: q.to_string(),
                    n,
                });
            }
            _ => return Err(bad(item, "not understood")),
        }
    }
    if picks.is_empty() {
        return Err(bad(spec, "nothing listed"));
    }
    Ok(picks)
}

/// The `worst:` picks naming none of the QoI columns `qois`: the message for the first.
pub fn check_quantities(picks: &[Pick], qois: &[String]) -> Result<(), String> {
    for p in picks {
        if let Pick::Worst { quantity, n } = p {
            if !qois.iter().any(|name| name == quantity) {
                return Err(format!(
                    "--histories worst:{quantity}:{n}: {quantity} is not a quantity column of instances.parquet: {}",
                    qois.join(", ")
                ));
            }
        }
    }
    Ok(())
}

/// Check the picks against the campaign's QoI columns and the instances a run will hold
/// (`range`).
pub fn check(picks: &[Pick], c: &Campaign, range: &std::ops::Range<u64>) -> Result<(), RunError> {
    check_quantities(picks, &table::qoi_names(&table::phase_names(c))).map_err(RunError::Input)?;
    for p in picks {
        if let Pick::Instance(i) = p {
            if !range.contains(i) {
                return Err(RunError::Input(format!(
                    "--histories instance:{i}: this run holds instances {} to {}",
                    range.start,
                    range.end.saturating_sub(1)
                )));
            }
        }
    }
    Ok(())
}

/// The instances the picks name in the run's `instances.parquet`, ascending, without repeats
/// (an `instance:I` the file does not hold, e.g. past where `--until` stopped, is left out),
/// and a note for each `worst:` pick that found fewer instances with a value than asked.
pub fn select(picks: &[Pick], instances_file: &Path) -> Result<(Vec<u64>, Vec<String>), RunError> {
    let ids = table::read_u64(instances_file, "instance")?;
    let mut chosen = Vec::new();
    let mut notes = Vec::new();
    for p in picks {
        match p {
            Pick::Instance(i) => {
                if ids.contains(i) {
                    chosen.push(*i);
                }
            }
            Pick::Worst { quantity, n } => {
                let values = table::read_f64(instances_file, quantity)?;
                let mut rows: Vec<usize> = (0..values.len())
                    .filter(|&r| values[r].is_finite())
                    .collect();
                let smallest = worst_is_smallest(quantity);
                rows.sort_by(|&a, &b| {
                    let order = values[a].total_cmp(&values[b]);
                    let order = if smallest { order } else { order.reverse() };
                    order.then(ids[a].cmp(&ids[b]))
                });
                if rows.len() < *n as usize {
                    notes.push(format!(
                        "worst {n} of {quantity}: only {} valid instances have a value",
                        rows.len()
                    ));
                }
                chosen.extend(rows.iter().take(*n as usize).map(|&r| ids[r]));
            }
        }
    }
    chosen.sort_unstable();
    chosen.dedup();
    Ok((chosen, notes))
}

/// File of instance `i`'s history under `dir/histories`.
pub fn history_path(dir: &Path, i: u64) -> PathBuf {
    dir.join("histories")
        .join(format!("instance_{i:09}.parquet"))
}

/// What `--histories` did: per instance named or chosen, the file written or why none was.
pub fn outcome(picks: &[Pick], chosen: &[u64], written: &[(u64, Option<PathBuf>)]) -> Vec<String> {
    let mut notes: Vec<String> = written
        .iter()
        .map(|(i, file)| match file {
            Some(f) => format!("instance {i}: {}", f.display()),
            None => format!("instance {i}: rejected, no history"),
        })
        .collect();
    for p in picks {
        match p {
            Pick::Instance(i) if !chosen.contains(i) => {
                notes.push(format!(
                    "instance {i}: not in this run (it stopped earlier)"
                ));
            }
            _ => {}
        }
    }
    notes
}

/// Integrate the chosen instances again with their histories and write one file each. Returns
/// per instance the file written (`None`: the instance was rejected, nothing to integrate).
pub fn write(
    plan: &Plan,
    dir: &Path,
    instances: &[u64],
) -> Result<Vec<(u64, Option<PathBuf>)>, RunError> {
    if instances.is_empty() {
        return Ok(Vec::new());
    }
    let out = dir.join("histories");
    std::fs::create_dir_all(&out).map_err(|source| crate::output::OutputError::Io {
        path: out.clone(),
        source,
    })?;
    let mut files = Vec::new();
    for &i in instances {
        let (_, resolved) = plan.resolve(i);
        let Ok(ci) = resolved else {
            files.push((i, None)); // rejected: nothing to integrate
            continue;
        };
        let mut ci: Campaign = ci.unwrap_or_else(|| plan.campaign.clone());
        ci.text = plan.campaign.text.clone();
        ci.path = plan.campaign.path.clone();
        ci.seed = plan.seed;
        let mut h = History::default();
        let q = simulate(&ci, &ci.params, Some(&mut h));
        let path = history_path(dir, i);
        crate::history::write_history(&path, &ci, &h, &i.to_string(), q.divergence())?;
        files.push((i, Some(path)));
    }
    Ok(files)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_the_documented_spelling() {
        assert_eq!(
            parse("worst:peak_pressure_pa:5,instance:17").unwrap(),
            vec![
                Pick::Worst {
                    quantity: "peak_pressure_pa".into(),
                    n: 5
                },
                Pick::Instance(17)
            ]
        );
        let qois = table::qoi_names(&["burn".to_string()]);
        let picks = |spec| parse(spec).unwrap();
        assert!(check_quantities(&picks("worst:peak_presure_pa:5"), &qois).is_err());
        assert!(check_quantities(&picks("worst:boiloff_kg.burn:5"), &qois).is_ok());
        assert!(check_quantities(&picks("worst:boiloff_kg.coast:5"), &qois).is_err());
        assert!(parse("worst::5").is_err());
        assert!(parse("worst:peak_pressure_pa:0").is_err());
        assert!(parse("instance:x").is_err());
        assert!(parse("").is_err());
        assert!(worst_is_smallest("min_cavitation_margin_m"));
        assert!(!worst_is_smallest("peak_pressure_pa"));
    }
}
