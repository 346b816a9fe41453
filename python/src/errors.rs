//! Library errors → the Python exception classes of `cryoslosh.errors`, one per CLI exit code:
//! `BadInputError` (exit 2, with file, key, value and allowed range when the campaign names
//! them) and `RunFailedError` (exit 1); `UntrustedError` (exit 3) is raised by the Python side,
//! which holds the finished result it carries. Messages are the CLI's.

use cryoslosh::campaign::CampaignError;
use cryoslosh::runner::RunnerError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The message the CLI prints after `error: ` ([`cryoslosh::error_text`]).
pub fn message(e: &dyn std::error::Error) -> String {
    cryoslosh::error_text(e)
}

/// An instance of the class `name` of `cryoslosh.errors`, called with `message` and `kwargs`.
fn raise(py: Python<'_>, name: &str, message: String, kwargs: &Bound<'_, PyDict>) -> PyErr {
    let made = py
        .import("cryoslosh.errors")
        .and_then(|m| m.getattr(name))
        .and_then(|class| class.call((message,), Some(kwargs)));
    match made {
        Ok(exception) => PyErr::from_value(exception),
        Err(e) => e,
    }
}

/// A runner error as the exception of its exit-code class.
pub fn to_py(py: Python<'_>, e: &RunnerError) -> PyErr {
    let kwargs = PyDict::new(py);
    if !e.is_bad_input() {
        return raise(py, "RunFailedError", message(e), &kwargs);
    }
    if let Some(c) = e.campaign_error() {
        if let Err(err) = campaign_fields(c, &kwargs) {
            return err;
        }
    }
    raise(py, "BadInputError", message(e), &kwargs)
}

/// A runtime failure (exit code 1 on the CLI).
pub fn failed(py: Python<'_>, message: String) -> PyErr {
    raise(py, "RunFailedError", message, &PyDict::new(py))
}

/// file, key, value and allowed of a campaign error, where it has them (a variant's error names
/// its key under the variant, `variants.<name>.<key>`).
fn campaign_fields(c: &CampaignError, kwargs: &Bound<'_, PyDict>) -> PyResult<()> {
    let file = match c {
        CampaignError::Read { file, .. }
        | CampaignError::Syntax { file, .. }
        | CampaignError::Schema { file, .. }
        | CampaignError::Override { file, .. }
        | CampaignError::Invalid { file, .. }
        | CampaignError::InvalidOverride { file, .. }
        | CampaignError::Distribution { file, .. } => file,
    };
    kwargs.set_item("file", file.display().to_string())?;
    kwargs.set_item("key", c.key())?;
    if let CampaignError::Invalid { value, allowed, .. }
    | CampaignError::InvalidOverride { value, allowed, .. } = c
    {
        kwargs.set_item("value", value)?;
        kwargs.set_item("allowed", allowed)?;
    }
    Ok(())
}
