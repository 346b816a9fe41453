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
        for (key, v) in &overrides {
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
    /// Errors: an override on a dispersed key ([`CampaignError::Invalid`]), a key the schema
    /// does not have or a value out of range ([`CampaignError::Variant`] around the error
    /// `--set` would give).
    pub fn variant(&self, k: usize) -> Result<Campaign, CampaignError> {
        let v = &self.variants[k];
        let wrap = |source: CampaignError| CampaignError::Variant {
            name: v.name.clone(),
            source: Box::new(source),
        };
        let mut doc: toml::Table = toml::from_str(&self.text).map_err(|e| {
            wrap(CampaignError::Syntax {
                file: self.path.clone(),
                message: e.to_string(),
            })
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
                return Err(CampaignError::Invalid {
                    file: self.path.clone(),
                    key: format!("variants.{}.{key}", v.name),
                    value: value.to_string(),
                    allowed: format!(
                        "a key that [dispersions] does not vary (dispersions.inputs.{j} samples \
                         it for every instance; variants share the dispersed inputs)"
                    ),
                });
            }
            apply_value(&mut doc, key, value.clone()).map_err(|(key, message)| {
                wrap(CampaignError::Override {
                    file: self.path.clone(),
                    key,
                    message,
                })
            })?;
        }
        let text = toml::to_string(&doc).map_err(|e| {
            wrap(CampaignError::Schema {
                file: self.path.clone(),
                message: e.to_string(),
            })
        })?;
        let mut c = Campaign::from_text(&self.path, &text, &[]).map_err(wrap)?;
        c.record_events = self.record_events;
        Ok(c)
    }

    /// Every variant's campaign, in order (the first is the baseline).
    pub fn variant_campaigns(&self) -> Result<Vec<Campaign>, CampaignError> {
        (0..self.variants.len()).map(|k| self.variant(k)).collect()
    }
}
