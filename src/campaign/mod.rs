//! Campaign files: TOML → `--set` overrides → serde (unknown keys rejected) → validated
//! [`Campaign`]. Errors name the file, the key path, the value and the allowed range.

mod describe;
pub mod dispersion;
mod raw;
pub mod statistics;
pub mod steps;
mod table;
pub mod template;
mod validate;
pub mod variants;

pub use describe::describe;
pub use describe::number;
pub use raw::RawCampaign;
pub use validate::{DEFAULT_LAYER_M, DEFAULT_WALL_HEAT_TO_LAYER};

use crate::model::flight::Phase;
use crate::model::params::Params;
use std::path::{Path, PathBuf};

/// Why a campaign could not be loaded. Every variant names the file.
#[derive(Debug, thiserror::Error)]
pub enum CampaignError {
    /// The OS error is in the message (`to_string` alone keeps it) and is the source too;
    /// [`crate::error_text`] prints it once.
    #[error("cannot read campaign {file}: {source}")]
    Read {
        file: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{file}: invalid TOML: {message}")]
    Syntax { file: PathBuf, message: String },
    #[error("{file}: {message}")]
    Schema { file: PathBuf, message: String },
    #[error("{file}: --set {key}: {message}")]
    Override {
        file: PathBuf,
        key: String,
        message: String,
    },
    #[error("{file}: {key} = {value} is not allowed: expected {allowed}")]
    Invalid {
        file: PathBuf,
        key: String,
        value: String,
        allowed: String,
    },
    /// A `--set` whose value a field's rule refuses (the file's own value was allowed): `key` as
    /// the override spells it.
    #[error("--set {key}={value} is not allowed: expected {allowed} (overriding {file})")]
    InvalidOverride {
        file: PathBuf,
        key: String,
        value: String,
        allowed: String,
    },
    #[error("{file}: {key}: the {distribution} distribution of {input} is invalid: {message}")]
    Distribution {
        file: PathBuf,
        key: String,
        distribution: String,
        input: String,
        message: String,
    },
}

impl CampaignError {
    /// The key path the error is about, when it names one.
    pub fn key(&self) -> Option<&str> {
        match self {
            CampaignError::Override { key, .. }
            | CampaignError::Invalid { key, .. }
            | CampaignError::InvalidOverride { key, .. }
            | CampaignError::Distribution { key, .. } => Some(key),
            _ => None,
        }
    }
}

/// Default relative tolerance of the adaptive integrator (`campaign.rtol`).
pub const DEFAULT_RTOL: f64 = 1.0e-6;
/// Default absolute tolerance of the adaptive integrator (`campaign.atol`), a fraction of each
/// state slot's reference scale (`simulate::tolerance`).
pub const DEFAULT_ATOL: f64 = 1.0e-9;

/// Which integrator advances the state.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Integrator {
    /// Dormand–Prince 5(4) with error control per instance (CPU backend).
    Dopri5,
    /// Classical fourth-order Runge–Kutta with the phases' fixed `dt_s` (the default).
    Rk4,
}

impl Integrator {
    /// Campaign spelling.
    pub fn name(self) -> &'static str {
        match self {
            Integrator::Dopri5 => "dopri5",
            Integrator::Rk4 => "rk4",
        }
    }
}

/// The `[campaign]` integrator settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stepping {
    pub integrator: Integrator,
    /// Relative tolerance on every state slot.
    pub rtol: f64,
    /// Absolute tolerance as a fraction of each slot's reference scale.
    pub atol: f64,
    /// Campaign-wide longest adaptive step, s (`INFINITY`: none).
    pub max_step_s: f64,
    /// The campaign accepts a fixed RK4 step that resolves a slosh or excitation period with
    /// fewer than [`crate::simulate::MIN_STEPS_PER_PERIOD`] steps.
    pub allow_coarse_step: bool,
}

/// A validated campaign: the physics parameters, the trajectory and the run settings.
#[derive(Clone, Debug)]
pub struct Campaign {
    /// Where it was read from.
    pub path: PathBuf,
    /// The campaign text with the overrides applied (provenance for output metadata).
    pub text: String,
    pub name: String,
    pub params: Params,
    pub phases: Vec<Phase>,
    /// Time-history sampling interval, s.
    pub output_interval_s: f64,
    /// How the phases are integrated.
    pub stepping: Stepping,
    /// Dispersion-campaign size (used by `run`).
    pub instances: u64,
    /// Random seed (used by `run`).
    pub seed: u64,
    /// Initial slosh angle, rad (free-decay studies).
    pub initial_slosh_angle_rad: f64,
    /// What varies between instances of `cryoslosh run`.
    pub dispersions: dispersion::Dispersions,
    /// What `cryoslosh run` reports about them (`[statistics]`).
    pub statistics: statistics::StatisticsPlan,
    /// The resolved document without `[dispersions]`: each instance applies its sampled values
    /// to it and goes through the same validation as the nominal.
    pub document: toml::Table,
    /// Record each instance's located events (`simulate::events`): set by `run --events` and
    /// `simulate`, not a campaign key (it changes what is written, not the results).
    pub record_events: bool,
    /// The `[[variants]]` (empty: a single design); the first is the baseline.
    pub variants: Vec<variants::Variant>,
}

/// With `[insulation]` the heat leak comes from the stack and the environment of each phase:
/// a dispersion of [`INSULATION_REPLACES`] would change nothing (a `--set` or a line of it is
/// refused by validation, which sees the key in the document; a dispersion is not there).
fn unused_with_insulation(c: &Campaign, doc: &toml::Table) -> Result<(), CampaignError> {
    if c.params.insulation.is_none() {
        return Ok(());
    }
    for (i, input) in c.dispersions.inputs.iter().enumerate() {
        if canonical_key(doc, &input.key) == INSULATION_REPLACES {
            return Err(CampaignError::Invalid {
                file: c.path.clone(),
                key: format!("dispersions.inputs.{i}.key"),
                value: input.key.clone(),
                allowed: format!(
                    "a key the model uses: {INSULATION_REPLACES} is not used with an \
                     [insulation] section (the heat leak comes from the stack and each \
                     phase's environment): disperse insulation.* keys instead"
                ),
            });
        }
    }
    Ok(())
}

/// Fixed regulator gains never read a reference ullage: a dispersion of [`SCHEDULE_REFERENCE`]
/// beside `gain_schedule = "fixed"` would fail every instance (a line or `--set` of it is
/// refused by validation).
fn unused_with_fixed_gains(c: &Campaign, doc: &toml::Table) -> Result<(), CampaignError> {
    let fixed = c
        .params
        .pressurization
        .is_some_and(|ps| ps.gain_schedule == crate::model::params::GainSchedule::Fixed);
    if !fixed {
        return Ok(());
    }
    for (i, input) in c.dispersions.inputs.iter().enumerate() {
        if canonical_key(doc, &input.key) == SCHEDULE_REFERENCE {
            return Err(CampaignError::Invalid {
                file: c.path.clone(),
                key: format!("dispersions.inputs.{i}.key"),
                value: input.key.clone(),
                allowed: format!(
                    "a key the model uses: {SCHEDULE_REFERENCE} is read only with \
                     pressurization.gain_schedule = \"ullage_volume\""
                ),
            });
        }
    }
    Ok(())
}

/// The reference ullage of the regulator's gain schedule.
pub const SCHEDULE_REFERENCE: &str = "pressurization.schedule_reference_ullage_m3";

/// The key an `[insulation]` section replaces.
pub const INSULATION_REPLACES: &str = "tank.heat_leak_w";

impl Campaign {
    /// Read, override and validate the campaign at `path`. `overrides` are `key=value` strings.
    pub fn load(path: &Path, overrides: &[String]) -> Result<Campaign, CampaignError> {
        let text = std::fs::read_to_string(path).map_err(|source| CampaignError::Read {
            file: path.to_path_buf(),
            source,
        })?;
        let c = Campaign::from_text(path, &text, overrides)?;
        // Here, not in `from_text`: a run made before this check (whose text replay, merge and
        // report read back) stays readable.
        dispersion::check_supports(
            &validate::Checker { file: path },
            &c.dispersions,
            |key, v| c.with_numbers([(key, v)]).map(|_| ()),
            |key| canonical_key(&c.document, key),
        )
        .map_err(|e| attribute_to_override(e, &override_keys(&c.document, overrides)))?;
        Ok(c)
    }

    /// Parse campaign `text` as if read from `path`.
    pub fn from_text(
        path: &Path,
        text: &str,
        overrides: &[String],
    ) -> Result<Campaign, CampaignError> {
        let file = path.to_path_buf();
        let mut doc: toml::Table = toml::from_str(text).map_err(|e| CampaignError::Syntax {
            file: file.clone(),
            message: one_line(&e.to_string()),
        })?;
        for o in overrides {
            apply_override(&mut doc, o).map_err(|(key, message)| CampaignError::Override {
                file: file.clone(),
                key,
                message,
            })?;
        }
        let resolved = if overrides.is_empty() {
            text.to_string()
        } else {
            toml::to_string(&doc).map_err(|e| CampaignError::Schema {
                file: file.clone(),
                message: e.to_string(),
            })?
        };
        let raw: RawCampaign =
            toml::from_str(&resolved).map_err(|e| schema_error(&file, text, overrides, &e))?;
        let set_keys = override_keys(&doc, overrides);
        Campaign::validated(path, &raw, resolved, doc)
            .map_err(|e| attribute_to_override(e, &set_keys))
    }

    /// The campaign of a parsed document (`resolved` its text): values, dispersions,
    /// statistics and variants validated.
    fn validated(
        path: &Path,
        raw: &RawCampaign,
        resolved: String,
        mut doc: toml::Table,
    ) -> Result<Campaign, CampaignError> {
        let mut c = validate::validate(raw, path, resolved)?;
        steps::check_fixed_step(&c, raw)?;
        doc.remove("dispersions");
        doc.remove("statistics");
        let variant_list = variants::extract(&mut doc, path)?;
        let checker = validate::Checker { file: path };
        if let Some(d) = &raw.dispersions {
            c.dispersions = dispersion::validate(
                &checker,
                d,
                |key| is_numeric_key(&doc, key),
                |key| canonical_key(&doc, key),
            )?;
        }
        unused_with_insulation(&c, &doc)?;
        unused_with_fixed_gains(&c, &doc)?;
        c.statistics = statistics::validate(
            &checker,
            &raw.statistics.clone().unwrap_or_default(),
            raw.dispersions.as_ref().and_then(|d| d.confidence),
        )?;
        c.document = doc;
        c.variants = variant_list;
        // Every variant must be a valid campaign before anything runs.
        c.variant_campaigns()?;
        Ok(c)
    }

    /// Refuse a `--set` on a key that `[dispersions]` varies: every instance overwrites it with
    /// its sample, so the override would be silently ignored by `run` (the nominal of `check`
    /// and `simulate` does use it).
    pub fn check_overrides_not_dispersed(&self, overrides: &[String]) -> Result<(), CampaignError> {
        let doc = &self.document;
        for o in overrides {
            let key = o.split_once('=').map_or(o.as_str(), |(k, _)| k.trim());
            let at = canonical_key(doc, key);
            if let Some(j) = self
                .dispersions
                .inputs
                .iter()
                .position(|input| canonical_key(doc, &input.key) == at)
            {
                return Err(CampaignError::Override {
                    file: self.path.clone(),
                    key: key.to_string(),
                    message: {
                        let input = &self.dispersions.inputs[j];
                        let kind = input.distribution.name();
                        let first = dispersion::parameters(kind).first().copied().unwrap_or("…");
                        format!(
                            "the key is dispersed by dispersions.inputs.{j} ({kind}): every \
                             instance overwrites it with its sample; set that entry's parameters \
                             instead (e.g. --set dispersions.inputs.{j}.{first}=…)"
                        )
                    },
                });
            }
        }
        Ok(())
    }

    /// The files the campaign reads: itself and its excitation tables.
    pub fn input_files(&self) -> Vec<PathBuf> {
        let dir = self.path.parent().unwrap_or_else(|| Path::new("."));
        let mut files = vec![self.path.clone()];
        if let Some(phases) = self.document.get("phases").and_then(toml::Value::as_array) {
            files.extend(phases.iter().filter_map(|ph| {
                ph.get("excitation")?
                    .get("file")?
                    .as_str()
                    .map(|f| dir.join(f))
            }));
        }
        files
    }

    /// The campaign of one instance: `values[j]` set at `dispersions.inputs[j].key`, then
    /// validated like the nominal. An error means the sample left a field's allowed range.
    pub fn instance(&self, values: &[f64]) -> Result<Campaign, CampaignError> {
        let keys = self
            .dispersions
            .inputs
            .iter()
            .map(|input| input.key.as_str());
        let mut c = self.with_numbers(keys.zip(values.iter().copied()))?;
        c.dispersions = dispersion::Dispersions::default();
        c.statistics = self.statistics.clone();
        c.variants = Vec::new();
        c.record_events = self.record_events;
        Ok(c)
    }

    /// The document with each `(key, value)` set, validated like the nominal (no dispersions,
    /// statistics or variants).
    fn with_numbers<'k>(
        &self,
        values: impl IntoIterator<Item = (&'k str, f64)>,
    ) -> Result<Campaign, CampaignError> {
        let mut doc = self.document.clone();
        for (key, v) in values {
            set_number(&mut doc, key, v).map_err(|(key, message)| CampaignError::Override {
                file: self.path.clone(),
                key,
                message,
            })?;
        }
        let raw: RawCampaign =
            toml::Value::Table(doc)
                .try_into()
                .map_err(|e: toml::de::Error| CampaignError::Schema {
                    file: self.path.clone(),
                    message: one_line(&e.to_string()),
                })?;
        validate::validate(&raw, &self.path, String::new())
    }
}

/// A schema error with positions the user can find: when the file itself is wrong, its own
/// error (line and column in the file); otherwise the first `--set` that breaks it, named.
fn schema_error(
    file: &Path,
    text: &str,
    overrides: &[String],
    e: &toml::de::Error,
) -> CampaignError {
    let schema = |message: String| CampaignError::Schema {
        file: file.to_path_buf(),
        message,
    };
    if overrides.is_empty() {
        return located(file, text, e);
    }
    if let Err(own) = toml::from_str::<RawCampaign>(text) {
        return located(file, text, &own);
    }
    let Ok(mut doc) = toml::from_str::<toml::Table>(text) else {
        return schema(one_line(&e.to_string()));
    };
    for o in overrides {
        if apply_override(&mut doc, o).is_err() {
            break;
        }
        if let Err(err) = toml::Value::Table(doc.clone()).try_into::<RawCampaign>() {
            let key = o.split_once('=').map_or(o.as_str(), |(k, _)| k.trim());
            return CampaignError::Override {
                file: file.to_path_buf(),
                key: key.to_string(),
                message: one_line(err.message()),
            };
        }
    }
    schema(format!(
        "{} (after the --set overrides)",
        one_line(&e.to_string())
    ))
}

/// A schema error of the file's own `text`, on one line with its key path: a value of the wrong
/// type or range as [`CampaignError::Invalid`] (key, value as written, what was expected, line
/// and column), any other (an unknown or missing key) as the key path, the message and the
/// position. TOML's own rendering put the source line and a caret on the same line as the
/// message when joined, and named no key.
fn located(file: &Path, text: &str, e: &toml::de::Error) -> CampaignError {
    let schema = |message: String| CampaignError::Schema {
        file: file.to_path_buf(),
        message,
    };
    let Some(span) = e.span().filter(|s| s.start <= s.end && s.end <= text.len()) else {
        return schema(one_line(&e.to_string()));
    };
    let before = &text[..span.start];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    let at = format!("line {line}, column {column}");
    let Some(key) = key_at(text, &span) else {
        return schema(format!("{} ({at})", one_line(e.message())));
    };
    let message = one_line(e.message());
    let expected = ["invalid type: ", "invalid value: "]
        .iter()
        .find_map(|p| message.strip_prefix(p))
        .and_then(|rest| rest.rsplit_once(", expected "))
        .map(|(_, expected)| expected);
    match expected {
        Some(expected) => CampaignError::Invalid {
            file: file.to_path_buf(),
            key,
            value: one_line(&text[span]),
            allowed: format!("{} ({at})", expectation(expected)),
        },
        None => schema(format!("{key}: {message} ({at})")),
    }
}

/// What serde's name of an expected type means in a campaign file.
fn expectation(serde: &str) -> String {
    match serde {
        "f64" | "f32" => "a number".into(),
        "u8" | "u16" | "u32" | "u64" | "usize" => "a whole number ≥ 0".into(),
        "i8" | "i16" | "i32" | "i64" | "isize" => "a whole number".into(),
        "a boolean" => "true or false".into(),
        "a string" => "a string in quotes".into(),
        other => other.into(),
    }
}

/// The dotted key path (array entries by index) of the deepest key or value of `text` whose
/// source span holds `span`.
fn key_at(text: &str, span: &std::ops::Range<usize>) -> Option<String> {
    use toml::de::{DeTable, DeValue};
    fn holds(outer: std::ops::Range<usize>, inner: &std::ops::Range<usize>) -> bool {
        outer.start <= inner.start && inner.end <= outer.end
    }
    fn in_value(v: &DeValue, span: &std::ops::Range<usize>, path: &mut Vec<String>) -> bool {
        match v {
            DeValue::Table(t) => in_table(t, span, path),
            DeValue::Array(a) => a.iter().enumerate().any(|(i, x)| {
                path.push(i.to_string());
                let found = in_value(x.get_ref(), span, path) || holds(x.span(), span);
                if !found {
                    path.pop();
                }
                found
            }),
            _ => false,
        }
    }
    fn in_table(t: &DeTable, span: &std::ops::Range<usize>, path: &mut Vec<String>) -> bool {
        t.iter().any(|(k, v)| {
            path.push(k.get_ref().to_string());
            // A table's span need not cover its body (a `[section]` header): look inside first.
            let found =
                in_value(v.get_ref(), span, path) || holds(k.span(), span) || holds(v.span(), span);
            if !found {
                path.pop();
            }
            found
        })
    }
    let doc = DeTable::parse(text).ok()?;
    let mut path = Vec::new();
    in_table(doc.get_ref(), span, &mut path).then(|| path.join("."))
}

/// Each `--set`'s key as written, with its canonical form in `doc` (phases by index).
fn override_keys(doc: &toml::Table, overrides: &[String]) -> Vec<(String, String)> {
    overrides
        .iter()
        .map(|o| {
            let key = o.split_once('=').map_or(o.as_str(), |(k, _)| k.trim());
            (canonical_key(doc, key), key.to_string())
        })
        .collect()
}

/// A value refused at a key that a `--set` gave is the override's fault, not the file's: say so.
/// `set_keys` from [`override_keys`]; the last override of a key is the one in force.
fn attribute_to_override(e: CampaignError, set_keys: &[(String, String)]) -> CampaignError {
    match e {
        CampaignError::Invalid {
            file,
            key,
            value,
            allowed,
        } => match set_keys
            .iter()
            .rev()
            .find(|(canonical, written)| *canonical == key || *written == key)
        {
            Some((_, written)) => CampaignError::InvalidOverride {
                file,
                key: written.clone(),
                value,
                allowed,
            },
            None => CampaignError::Invalid {
                file,
                key,
                value,
                allowed,
            },
        },
        other => other,
    }
}

/// Whether `key` names a numeric scalar the schema accepts (present or defaulted).
fn is_numeric_key(doc: &toml::Table, key: &str) -> bool {
    let mut probe = doc.clone();
    set_number(&mut probe, key, 1.0).is_ok()
        && toml::Value::Table(probe).try_into::<RawCampaign>().is_ok()
}

/// Set a number at a key path: an integer when it is integral (integer fields need one; float
/// fields accept it), else a float.
fn set_number(doc: &mut toml::Table, key: &str, v: f64) -> Result<(), (String, String)> {
    let value = if v.fract() == 0.0 && v.abs() < 9.0e15 {
        toml::Value::Integer(v as i64)
    } else {
        toml::Value::Float(v)
    };
    apply_value(doc, key, value)
}

/// Flatten toml's multi-line diagnostic into one line that still carries the key and position.
fn one_line(s: &str) -> String {
    s.lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && *l != "|")
        .collect::<Vec<_>>()
        .join(" ")
}

/// Parse a `--set` value: integer, float, boolean, any TOML literal written as in the file
/// (`1_000`, `1_000.5`, `0x10`, a quoted string `"helium"`, an array `[1, 2]`, an inline table;
/// no field takes a date, so `2024-01-01` stays text), else the text as a bare string
/// (`pressurization.gas=helium`). A quoted value used to keep its quotes and fail validation,
/// and `1_000` to be refused as the string "1_000". An integral number (`3.0`, `1e3`) is an
/// integer, so that a count key takes it.
fn parse_value(v: &str) -> toml::Value {
    let value = if let Ok(i) = v.parse::<i64>() {
        toml::Value::Integer(i)
    } else if let Ok(x) = v.parse::<f64>() {
        toml::Value::Float(x)
    } else if let Ok(b) = v.parse::<bool>() {
        toml::Value::Boolean(b)
    } else if let Some(literal) = toml::from_str::<toml::Table>(&format!("v = {v}"))
        .ok()
        .filter(|t| t.len() == 1)
        .and_then(|mut t| t.remove("v"))
        .filter(|v| !matches!(v, toml::Value::Datetime(_)))
    {
        literal
    } else {
        toml::Value::String(v.to_string())
    };
    // An integral number is written as an integer, as a dispersion sample is (`set_number`): a
    // count copied from instances.parquet (`slosh.baffle_count=3.0`) was refused ("invalid type:
    // floating point, expected u32"); a float key takes an integer alike.
    match value {
        toml::Value::Float(x) if x.fract() == 0.0 && x.abs() < 9.0e15 => {
            toml::Value::Integer(x as i64)
        }
        other => other,
    }
}

/// Apply a `--set KEY=VALUE` string.
fn apply_override(doc: &mut toml::Table, spec: &str) -> Result<(), (String, String)> {
    let (key, value) = spec
        .split_once('=')
        .ok_or_else(|| (spec.to_string(), "expected KEY=VALUE".to_string()))?;
    apply_value(doc, key.trim(), parse_value(value.trim()))
}

/// `key` with array entries given by name replaced by their index, so two spellings of one key
/// compare equal; segments that resolve to nothing are kept as written.
fn canonical_key(doc: &toml::Table, key: &str) -> String {
    let mut out = Vec::new();
    let mut node: Option<&toml::Value> = None;
    for (n, part) in key.split('.').enumerate() {
        let next = match node {
            None if n == 0 => doc.get(part),
            Some(toml::Value::Table(t)) => t.get(part),
            Some(toml::Value::Array(a)) => match array_index(a, part) {
                Ok(i) => {
                    out.push(i.to_string());
                    node = a.get(i);
                    continue;
                }
                Err(_) => None,
            },
            _ => None,
        };
        out.push(part.to_string());
        node = next;
    }
    out.join(".")
}

/// Position of `part` in an array: a numeric index, or the `name` of exactly one of its tables
/// (`phases.restart.thrust_n`: inserting a phase does not retarget a named key).
fn array_index(a: &[toml::Value], part: &str) -> Result<usize, String> {
    if let Ok(i) = part.parse::<usize>() {
        return Ok(i);
    }
    let name_of = |v: &toml::Value| {
        v.get("name")
            .and_then(toml::Value::as_str)
            .map(str::to_owned)
    };
    let hits: Vec<usize> = (0..a.len())
        .filter(|&i| name_of(&a[i]).as_deref() == Some(part))
        .collect();
    match hits.as_slice() {
        [i] => Ok(*i),
        [] => {
            let names: Vec<String> = a.iter().filter_map(name_of).collect();
            Err(if names.is_empty() {
                format!("no entry is named {part:?} (the entries have no names: use an index)")
            } else {
                format!("no entry is named {part:?}; names: {}", names.join(", "))
            })
        }
        many => Err(format!(
            "{} entries are named {part:?} (indices {many:?}): use an index",
            many.len()
        )),
    }
}

/// Set `a.b.0.c` (or `a.name.c`, see [`array_index`]) to `value`: tables by key (created when
/// missing), arrays by index or entry name (must exist).
/// Unknown keys are caught afterwards by serde's `deny_unknown_fields`.
fn apply_value(
    doc: &mut toml::Table,
    key: &str,
    value: toml::Value,
) -> Result<(), (String, String)> {
    let parts: Vec<&str> = key.split('.').collect();
    if parts.iter().any(|p| p.is_empty()) {
        return Err((key.to_string(), "empty segment in the key path".to_string()));
    }
    let fail = |m: &str| (key.to_string(), m.to_string());
    let mut node: &mut toml::Value = doc
        .entry(parts[0].to_string())
        .or_insert_with(|| toml::Value::Table(toml::Table::new()));
    for part in &parts[1..] {
        node = match node {
            toml::Value::Table(t) => t
                .entry(part.to_string())
                .or_insert_with(|| toml::Value::Table(toml::Table::new())),
            toml::Value::Array(a) => {
                let i = array_index(a, part).map_err(|m| fail(&m))?;
                let len = a.len();
                a.get_mut(i).ok_or_else(|| {
                    fail(&format!("index {i} out of range (array has {len} entries)"))
                })?
            }
            _ => return Err(fail("the path goes through a scalar")),
        };
    }
    if matches!(node, toml::Value::Table(t) if !t.is_empty())
        || matches!(node, toml::Value::Array(_))
    {
        return Err(fail("names a table or array; --set takes a scalar key"));
    }
    *node = value;
    Ok(())
}
