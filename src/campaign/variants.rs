//! `[[variants]]`: design variants of one campaign, each a name and key-path overrides with the
//! syntax and validation of `--set`. `run` integrates every instance under every variant with
//! the same dispersed inputs (common random numbers), so the variants' differences are paired.
//!
//! ```toml
//! [[variants]]
//! name = "baseline"          # the first variant is the baseline of every difference
//!
//! [[variants]]
//! name = "no_baffles"
//! "slosh.baffle_count" = 0   # a quoted dotted key path, as --set takes it
//! tank = { heat_leak_w = 30.0 }   # or nested tables: the same as "tank.heat_leak_w"
//! ```
//!
//! A variant may not override a key that `[dispersions]` varies (each instance overwrites it with
//! its sample, so a variant could not differ there without breaking the pairing), nor
//! `[dispersions]`, `[statistics]`, `campaign.instances` or `campaign.seed` (what is sampled and
//! how it is summarised is one thing for every variant).

use super::raw::RawCampaign;
use super::{apply_value, canonical_key, Campaign, CampaignError};

/// One design variant: its name and its overrides (key path, value) in file order.
#[derive(Clone, Debug, PartialEq)]
pub struct Variant {
    pub name: String,
    pub overrides: Vec<(String, toml::Value)>,
}

impl Variant {
    /// The overrides as `--set` would spell them (`slosh.baffle_count=0`).
    pub fn describe(&self) -> String {
        let sets: Vec<String> = self
            .overrides
            .iter()
            .map(|(k, v)| match v {
                toml::Value::String(s) => format!("{k}={s}"),
                v => format!("{k}={v}"),
            })
            .collect();
        if sets.is_empty() {
            "(the campaign as written)".into()
        } else {
            sets.join(", ")
        }
    }
}

/// Keys (and key prefixes) no variant may set, with why.
const FIXED: [(&str, &str); 5] = [
    ("dispersions", "what is sampled is common to every variant"),
    (
        "statistics",
        "how results are summarised is common to every variant",
    ),
    ("variants", "a variant cannot define variants"),
    (
        "campaign.instances",
        "every variant integrates the same instances",
    ),
    (
        "campaign.seed",
        "every variant integrates the same instances",
    ),
];

/// Most variants one campaign may carry.
pub const MAX_VARIANTS: usize = 64;

/// Flatten a variant's table into key paths: `{tank = {heat_leak_w = 30}}` and
/// `"tank.heat_leak_w" = 30` both give `tank.heat_leak_w`.
fn flatten(prefix: &str, t: &toml::Table, out: &mut Vec<(String, toml::Value)>) {
    for (k, v) in t {
        let key = if prefix.is_empty() {
            k.clone()
        } else {
            format!("{prefix}.{k}")
        };
        match v {
            toml::Value::Table(inner) => flatten(&key, inner, out),
            v => out.push((key, v.clone())),
        }
    }
}

/// Read the `variants` array out of a campaign document (removing it) and check names and
/// keys that need no campaign: at least two variants, unique names of letters, digits, `_` and
/// `-`, no key from [`FIXED`].
pub(super) fn extract(
    doc: &mut toml::Table,
    file: &std::path::Path,
) -> Result<Vec<Variant>, CampaignError> {
    let Some(value) = doc.remove("variants") else {
        return Ok(Vec::new());
    };
    let invalid = |key: String, value: String, allowed: &str| CampaignError::Invalid {
        file: file.to_path_buf(),
        key,
        value,
        allowed: allowed.to_string(),
    };
    let toml::Value::Array(entries) = value else {
        return Err(invalid(
            "variants".into(),
            value.to_string(),
            "an array of tables ([[variants]])",
        ));
    };
    if entries.len() < 2 || entries.len() > MAX_VARIANTS {
        return Err(invalid(
            "variants".into(),
            format!("{} entries", entries.len()),
            &format!("2 to {MAX_VARIANTS} [[variants]] (the first is the baseline)"),
        ));
    }
    let mut out: Vec<Variant> = Vec::new();
    for (i, entry) in entries.iter().enumerate() {
        let toml::Value::Table(t) = entry else {
            return Err(invalid(
                format!("variants.{i}"),
                entry.to_string(),
                "a table with a name and key-path overrides",
            ));
        };
        let name = match t.get("name") {
            Some(toml::Value::String(s))
                if !s.is_empty()
                    && s.len() <= 64
                    && s.chars()
                        .all(|ch| ch.is_ascii_alphanumeric() || ch == '_' || ch == '-') =>
            {
                s.clone()
            }
            other => {
                return Err(invalid(
                    format!("variants.{i}.name"),
                    other.map_or("(missing)".into(), ToString::to_string),
                    "a name of 1 to 64 letters, digits, '_' and '-' (it names a directory)",
                ))
            }
        };
        if out.iter().any(|v| v.name == name) {
            return Err(invalid(
                format!("variants.{i}.name"),
                format!("{name:?}"),
                "a name no other variant has",
            ));
        }
        let mut rest = t.clone();
        rest.remove("name");
        let mut overrides = Vec::new();
        flatten("", &rest, &mut overrides);
        for (k, (key, v)) in overrides.iter().enumerate() {
            // One key, however spelled (a quoted dotted key and a table; a phase by index and
            // by name), is set once: both were accepted and one value silently dropped.
            let at = canonical_key(doc, key);
            if let Some((first, _)) = overrides[..k]
                .iter()
                .find(|(o, _)| canonical_key(doc, o) == at)
            {
                return Err(invalid(
                    format!("variants.{name}.{key}"),
                    v.to_string(),
                    &format!("a key this variant sets once (it also sets it as {first})"),
                ));
            }
            if matches!(v, toml::Value::Array(_)) {
                return Err(invalid(
                    format!("variants.{name}.{key}"),
                    v.to_string(),
                    "a scalar (a variant sets scalars by key path, as --set does)",
                ));
            }
            if let Some((_, why)) = FIXED
                .iter()
                .find(|(f, _)| key == f || key.starts_with(&format!("{f}.")))
            {
                return Err(invalid(
                    format!("variants.{name}.{key}"),
                    v.to_string(),
                    &format!("a key outside {}: {why}", FIXED.map(|f| f.0).join(", ")),
                ));
            }
        }
        out.push(Variant { name, overrides });
    }
    Ok(out)
}

impl Campaign {
    /// The campaign of variant `k`: the campaign (with its `--set` overrides) without
    /// `[[variants]]`, the variant's overrides applied, then validated like any campaign. Its
    /// `text` is that resolved document, so a run of the variant replays alone.
    ///
    /// Errors are one [`CampaignError::Invalid`] naming the campaign file, the key path under
    /// the variant (`variants.<name>.<key>`), the value and what is allowed: an override on a
    /// dispersed key, a key the schema does not have, a value of the wrong type or out of range,
    /// or a setting the variant's campaign refuses as a whole (a step too coarse for it).
    pub fn variant(&self, k: usize) -> Result<Campaign, CampaignError> {
        let v = &self.variants[k];
        let invalid = |key: &str, value: String, allowed: String| CampaignError::Invalid {
            file: self.path.clone(),
            key: format!("variants.{}.{key}", v.name),
            value,
            allowed,
        };
        let shown = |value: &toml::Value| match value {
            toml::Value::String(s) => s.clone(),
            other => other.to_string(),
        };
        let mut doc: toml::Table =
            toml::from_str(&self.text).map_err(|e| CampaignError::Syntax {
                file: self.path.clone(),
                message: super::one_line(&e.to_string()),
            })?;
        doc.remove("variants");
        for (key, value) in &v.overrides {
            let at = canonical_key(&self.document, key);
            if let Some(j) = self
                .dispersions
                .inputs
                .iter()
                .position(|input| canonical_key(&self.document, &input.key) == at)
            {
                return Err(invalid(
                    key,
                    shown(value),
                    format!(
                        "a key that [dispersions] does not vary (dispersions.inputs.{j} samples \
                         it for every instance; variants share the dispersed inputs)"
                    ),
                ));
            }
            apply_value(&mut doc, key, value.clone()).map_err(|(_, message)| {
                invalid(
                    key,
                    shown(value),
                    format!("a key path of the campaign: {message}"),
                )
            })?;
            // Checked one override at a time, so the error names the one that breaks the schema
            // (the whole document's error would point into the rebuilt text, not the file).
            if let Err(e) = toml::Value::Table(doc.clone()).try_into::<RawCampaign>() {
                return Err(invalid(key, shown(value), schema_allowed(e.message())));
            }
        }
        // A variant that adds [insulation] replaces the campaign's fixed heat leak (one it
        // sets itself is refused below).
        if doc.contains_key("insulation") && !self.document.contains_key("insulation") {
            if let Some(toml::Value::Table(tank)) = doc.get_mut("tank") {
                tank.remove("heat_leak_w");
            }
        }
        let text = toml::to_string(&doc).map_err(|e| CampaignError::Schema {
            file: self.path.clone(),
            message: format!("variant {}: {e}", v.name),
        })?;
        let mut c = Campaign::from_text(&self.path, &text, &[]).map_err(|e| match e {
            // The key as the variant spells it when it set that key, else the campaign's own.
            CampaignError::Invalid {
                key,
                value,
                allowed,
                ..
            } => {
                let at = canonical_key(&doc, &key);
                match v
                    .overrides
                    .iter()
                    .find(|(o, _)| canonical_key(&doc, o) == at)
                {
                    Some((written, _)) => invalid(written, value, allowed),
                    // A key of the campaign the variant did not set (a dispersion its overrides
                    // made invalid): the campaign's own path, which a variant cannot hold.
                    None => CampaignError::Invalid {
                        file: self.path.clone(),
                        key,
                        value,
                        allowed: format!("{allowed} (under variant {}'s overrides)", v.name),
                    },
                }
            }
            CampaignError::Distribution {
                key,
                distribution,
                input,
                message,
                ..
            } => invalid(
                &key,
                format!("{distribution} of {input}"),
                format!("a valid distribution ({message})"),
            ),
            CampaignError::Schema { message, .. } | CampaignError::Syntax { message, .. } => {
                CampaignError::Schema {
                    file: self.path.clone(),
                    message: format!("variant {}: {message}", v.name),
                }
            }
            other => other,
        })?;
        // An insulated variant computes its heat leak: its own tank.heat_leak_w would change
        // nothing, and the difference against the baseline would be zero for no stated reason.
        if c.params.insulation.is_some() {
            if let Some((key, value)) = v
                .overrides
                .iter()
                .find(|(o, _)| canonical_key(&doc, o) == super::INSULATION_REPLACES)
            {
                return Err(invalid(
                    key,
                    shown(value),
                    "a key the variant uses: with an [insulation] section the heat leak comes \
                     from the stack (override insulation.* keys instead)"
                        .to_string(),
                ));
            }
        }
        c.record_events = self.record_events;
        Ok(c)
    }

    /// Every variant's campaign, in order (the first is the baseline).
    pub fn variant_campaigns(&self) -> Result<Vec<Campaign>, CampaignError> {
        (0..self.variants.len()).map(|k| self.variant(k)).collect()
    }
}

/// What serde's message about a variant's override says is allowed: `unknown field `x`,
/// expected one of `a`, `b`` → "a key of the schema: one of `a`, `b`"; `invalid type: string
/// "abc", expected f64` → "f64 (not string "abc")"; anything else as it is.
fn schema_allowed(message: &str) -> String {
    let message = super::one_line(message);
    if let Some(rest) = message.strip_prefix("unknown field ") {
        let expected = rest.split_once(", expected ").map_or("", |(_, e)| e);
        return format!("a key the schema has here: {expected}");
    }
    if let Some(rest) = message.strip_prefix("invalid type: ") {
        if let Some((got, expected)) = rest.split_once(", expected ") {
            return format!("{expected} (not {got})");
        }
    }
    if let Some(rest) = message.strip_prefix("unknown variant ") {
        if let Some((_, expected)) = rest.split_once(", expected ") {
            return expected.to_string();
        }
    }
    message
}
