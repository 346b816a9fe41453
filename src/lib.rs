//! cryoslosh: Monte Carlo dispersion engine for cryogenic propellant tanks — thermal
//! stratification, slosh, pressurization, venting and suction margin (see MODEL.md).
//!
//! The CLI (`src/main.rs`) adds nothing this library cannot do: load a [`campaign::Campaign`],
//! [`simulate::simulate`] an instance, write its history with [`history::write_history`], or run
//! a dispersion campaign with [`montecarlo::run`] on an [`engine::Backend`].

pub mod campaign;
pub mod engine;
pub mod fluids;
pub mod geometry;
pub mod gpu;
pub mod history;
pub mod lanes;
pub mod model;
pub mod montecarlo;
pub mod output;
pub mod report;
pub mod runner;
pub mod sampling;
pub mod simulate;
pub mod stats;

/// `eprintln!` that cannot panic: where standard error is closed or fails (`cryoslosh … 2>&1 |
/// head` after `head` has exited), the line is lost instead of the command ending in a panic
/// (exit 101) in place of its own exit code.
#[macro_export]
macro_rules! eprintln_lossy {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}

/// An error and its sources on one line, joined by ": " as anyhow's `{:#}` joins them, without a
/// source that the message wrapping it already ends with: errors that put their source in their
/// own message ("cannot write X: {source}", so that `to_string` alone keeps the reason) and also
/// return it as `source()` printed the OS error twice. What the CLI prints after `error: ` and
/// the Python exceptions carry.
pub fn error_text(e: &dyn std::error::Error) -> String {
    let mut text = e.to_string();
    let mut outer = text.clone();
    let mut source = e.source();
    while let Some(s) = source {
        let c = s.to_string();
        if !c.is_empty() && !outer.ends_with(&format!(": {c}")) {
            text.push_str(": ");
            text.push_str(&c);
        }
        outer = c;
        source = s.source();
    }
    text
}

/// Crate version, recorded in every output file.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
