//! Tabulated excitation: a CSV of `time_s,a_lat_m_s2[,a_ax_m_s2]` with an optional header line
//! (recognised by those column names only), `#` comments and an optional UTF-8 byte-order mark,
//! times strictly increasing. Any other line that is not numbers is an error naming the file,
//! line and column: a typo in the first data row ("2.O") used to be skipped as a header.

use super::validate::Checker;
use super::CampaignError;
use crate::model::flight::Excitation;
use std::path::Path;

/// Largest |a_lat| and |a_ax| a table row may hold, m/s² (the amplitude range of the other kinds).
const MAX_TABLE_ACCEL_M_S2: f64 = 1000.0;

/// Read and check an excitation table, naming `key` and the line on any error.
pub(super) fn read_excitation_table(
    c: &Checker,
    key: &str,
    path: &Path,
) -> Result<Excitation, CampaignError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| c.table_err(key, path.display(), format!("a readable CSV file ({e})")))?;
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    let (mut ts, mut lat, mut ax) = (Vec::new(), Vec::new(), Vec::new());
    let mut first = true;
    for (n, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let cells: Vec<&str> = line.split(',').map(str::trim).collect();
        if std::mem::take(&mut first) && is_header(&cells) {
            continue;
        }
        let mut nums = Vec::with_capacity(cells.len());
        for (col, cell) in cells.iter().enumerate() {
            match cell.parse::<f64>() {
                Ok(v) => nums.push(v),
                Err(_) => {
                    return Err(c.table_err(
                        key,
                        format!("{}:{}: column {}: {cell:?}", path.display(), n + 1, col + 1),
                        "numbers: time_s,a_lat_m_s2[,a_ax_m_s2] (a header line may name exactly \
                         those columns)",
                    ))
                }
            }
        }
        let ok_len = nums.len() == 2 || nums.len() == 3;
        let finite = nums.iter().all(|v| v.is_finite());
        let increasing = ts.last().is_none_or(|&last| nums[0] > last);
        // The accelerations keep the other kinds' amplitude range.
        let in_range = nums[1..].iter().all(|a| a.abs() <= MAX_TABLE_ACCEL_M_S2);
        if !ok_len || !finite || !increasing || !in_range {
            return Err(c.table_err(
                key,
                format!("{}:{}: {line}", path.display(), n + 1),
                "2 or 3 finite numbers per row, time strictly increasing, accelerations in \
                 [-1000, 1000] m/s²",
            ));
        }
        ts.push(nums[0]);
        lat.push(nums[1]);
        ax.push(nums.get(2).copied().unwrap_or(0.0));
    }
    if ts.len() < 2 {
        return Err(c.table_err(key, path.display(), "a table with at least two rows"));
    }
    Ok(Excitation::Table {
        time_s: ts,
        a_lat: lat,
        a_ax: ax,
    })
}

/// Whether the cells are the table's header: `time_s,a_lat_m_s2[,a_ax_m_s2]`.
fn is_header(cells: &[&str]) -> bool {
    matches!(
        cells,
        ["time_s", "a_lat_m_s2"] | ["time_s", "a_lat_m_s2", "a_ax_m_s2"]
    )
}
