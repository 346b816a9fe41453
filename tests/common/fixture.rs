//! The CoolProp fixture CSVs of `tests/fixtures/fluids/` (written by `tools/coolprop_fixtures.py`).

use std::path::PathBuf;

/// A fixture CSV: `#` comment lines, a header line, then numeric rows.
pub struct Fixture {
    pub name: String,
    pub comments: Vec<String>,
    pub columns: Vec<String>,
    pub rows: Vec<Vec<f64>>,
}

impl Fixture {
    pub fn load(file: &str) -> Fixture {
        let path: PathBuf = [
            env!("CARGO_MANIFEST_DIR"),
            "tests",
            "fixtures",
            "fluids",
            file,
        ]
        .iter()
        .collect();
        let text = std::fs::read_to_string(&path)
            .unwrap_or_else(|e| panic!("cannot read fixture {}: {e}", path.display()));
        let mut comments = Vec::new();
        let mut columns: Option<Vec<String>> = None;
        let mut rows = Vec::new();
        for (lineno, line) in text.lines().enumerate() {
            let line = line.trim();
            if line.is_empty() {
                continue;
            }
            if let Some(c) = line.strip_prefix('#') {
                comments.push(c.trim().to_string());
                continue;
            }
            match &columns {
                None => columns = Some(line.split(',').map(|s| s.trim().to_string()).collect()),
                Some(cols) => {
                    let row: Vec<f64> = line
                        .split(',')
                        .map(|s| {
                            s.trim().parse::<f64>().unwrap_or_else(|e| {
                                panic!("{file}:{}: bad number {s:?}: {e}", lineno + 1)
                            })
                        })
                        .collect();
                    assert_eq!(
                        row.len(),
                        cols.len(),
                        "{file}:{}: expected {} fields",
                        lineno + 1,
                        cols.len()
                    );
                    rows.push(row);
                }
            }
        }
        Fixture {
            name: file.to_string(),
            comments,
            columns: columns.unwrap_or_else(|| panic!("{file}: no header line")),
            rows,
        }
    }

    pub fn col(&self, name: &str) -> usize {
        self.columns
            .iter()
            .position(|c| c == name)
            .unwrap_or_else(|| panic!("{}: no column {name}", self.name))
    }

    pub fn column(&self, name: &str) -> Vec<f64> {
        let i = self.col(name);
        self.rows.iter().map(|r| r[i]).collect()
    }
}
