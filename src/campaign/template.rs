//! The commented template campaign that `cryoslosh init` writes (`campaigns/template.toml`,
//! embedded at build time so the binary carries it).

use std::io::Write;
use std::path::Path;

/// The template campaign text: a small LN2 tank, a pad hold and a short burn with a gust, helium
/// pressurization, a relief valve and three dispersions; every key commented with its unit,
/// allowed range and default, and the optional sections it leaves out listed.
pub const TEMPLATE: &str = include_str!("../../campaigns/template.toml");

/// Write [`TEMPLATE`] to `path`. An existing file is overwritten only when `force` is set;
/// otherwise the error is `ErrorKind::AlreadyExists` and the file is left as it was.
pub fn write_template(path: &Path, force: bool) -> std::io::Result<()> {
    let mut options = std::fs::OpenOptions::new();
    options.write(true);
    if force {
        options.create(true).truncate(true);
    } else {
        // Checked and created in one step: no window in which another writer's file is lost.
        options.create_new(true);
    }
    options.open(path)?.write_all(TEMPLATE.as_bytes())
}
