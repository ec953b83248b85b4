//! Every numeric parameter of [`ActionParams`] by a stable path, with its unit and source
//! tag: what a calibration frees and what `piano params --list` prints.
//!
//! A path is the parameter file's own: table keys joined by dots, an array element by its
//! index (`hammer.pivot_friction_n_m`, `contacts.hammer_string.k`, `jack.toe_mm[1]`). The
//! unit follows from the field name's suffix (`_mm`, `_n_m`, `_kg_m2`, ...), as the file's
//! convention has it; the tag (`[V]`, `[S]`, `[M]`, `[D]`, `[regulated]`, ...) is read from
//! the comment on the value's line in the file the parameters came from.

use serde_json::Value;

use crate::error::{PianoError, Result};
use crate::params::ActionParams;

/// One numeric parameter.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamInfo {
    /// Its path (`hammer.mass_g`, `jack.toe_mm[0]`).
    pub path: String,
    /// Its value, in `unit`.
    pub value: f64,
    /// Its unit (`mm`, `N m`, `1` for a pure number).
    pub unit: &'static str,
    /// The source tags on its line of the parameter file (`[S]`, `[D/M]`, `[regulated]`),
    /// space-separated; empty when the line has none.
    pub tags: String,
}

/// Units by field-name suffix, longest first.
const SUFFIX_UNITS: [(&str, &str); 16] = [
    ("_n_m_s_per_rad", "N m s/rad"),
    ("_n_m_per_rad", "N m/rad"),
    ("_kg_m2", "kg m^2"),
    ("_rad_s", "rad/s"),
    ("_per_s", "1/s"),
    ("_n_m", "N m"),
    ("_m_s", "m/s"),
    ("_mm", "mm"),
    ("_deg", "deg"),
    ("_rad", "rad"),
    ("_hz", "Hz"),
    ("_kg", "kg"),
    ("_g", "g"),
    ("_m", "m"),
    ("_n", "N"),
    ("_s", "s"),
];

/// The unit of the field `key` (its last path part, without an index).
fn unit_of(key: &str) -> &'static str {
    // An effect's parameter (`[[effects]]`) has its unit in the library.
    if let Some(unit) = crate::identify::effects::PENDULUM_EFFECTS
        .iter()
        .flat_map(|e| e.params)
        .find(|p| p.name == key)
        .map(|p| p.unit)
    {
        return unit;
    }
    if let Some((_, unit)) = SUFFIX_UNITS.iter().find(|(s, _)| key.ends_with(s)) {
        return unit;
    }
    match key {
        // A contact law's stiffness: F = k d^p.
        "k" => "N/m^p",
        // Exponent, restitution, friction coefficient, ratios, counts, unit vectors.
        _ => "1",
    }
}

/// The numeric leaves of `value` under `prefix`, in file order.
fn leaves(prefix: &str, value: &Value, out: &mut Vec<(String, f64, String)>) {
    match value {
        Value::Object(map) => {
            for (k, v) in map {
                let path = if prefix.is_empty() {
                    k.clone()
                } else {
                    format!("{prefix}.{k}")
                };
                leaves(&path, v, out);
            }
        }
        Value::Array(items) => {
            for (i, v) in items.iter().enumerate() {
                leaves(&format!("{prefix}[{i}]"), v, out);
            }
        }
        Value::Number(n) => {
            if let Some(x) = n.as_f64() {
                let key = prefix.rsplit('.').next().unwrap_or(prefix);
                let key = key.split('[').next().unwrap_or(key);
                out.push((prefix.to_string(), x, key.to_string()));
            }
        }
        _ => {}
    }
}

/// The tags (`[...]`) in the comment of line `line` (1-based) of `text`.
fn tags_on_line(text: &str, line: usize) -> String {
    let Some(src) = text.lines().nth(line.saturating_sub(1)) else {
        return String::new();
    };
    let Some((_, comment)) = src.split_once('#') else {
        return String::new();
    };
    let mut tags = Vec::new();
    let mut rest = comment;
    while let Some(open) = rest.find('[') {
        let after = &rest[open + 1..];
        let Some(close) = after.find(']') else { break };
        let inner = &after[..close];
        if !inner.is_empty() && inner.len() <= 16 && !inner.contains('[') {
            tags.push(format!("[{inner}]"));
        }
        rest = &after[close + 1..];
    }
    tags.join(" ")
}

fn as_value(params: &ActionParams) -> Result<Value> {
    serde_json::to_value(params)
        .map_err(|e| PianoError::params("", format!("cannot list the parameters: {e}")))
}

/// The closest known path to `path` (for "did you mean"), if any is close.
fn closest<'a>(path: &str, known: impl Iterator<Item = &'a str>) -> Option<&'a str> {
    fn distance(a: &str, b: &str) -> usize {
        let b: Vec<char> = b.chars().collect();
        let mut row: Vec<usize> = (0..=b.len()).collect();
        for (i, ca) in a.chars().enumerate() {
            let mut prev = row[0];
            row[0] = i + 1;
            for (j, cb) in b.iter().enumerate() {
                let cur = row[j + 1];
                row[j + 1] = (prev + usize::from(ca != *cb)).min(row[j] + 1).min(cur + 1);
                prev = cur;
            }
        }
        row[b.len()]
    }
    known
        .map(|k| (distance(path, k), k))
        .filter(|(d, k)| *d <= 3.max(k.len() / 5))
        .min_by_key(|(d, _)| *d)
        .map(|(_, k)| k)
}

impl ActionParams {
    /// Every numeric parameter in the order of `source`: path, value, unit, and the tags of
    /// its line in `source`, the TOML text the parameters were read from (the embedded
    /// default file: [`crate::params::DEFAULT_PARAMS_TOML`]).
    pub fn parameter_list(&self, source: &str) -> Result<Vec<ParamInfo>> {
        let mut out = Vec::new();
        leaves("", &as_value(self)?, &mut out);
        let mut list: Vec<(usize, ParamInfo)> = out
            .into_iter()
            .map(|(path, value, key)| {
                let line = crate::toml_lines::line_of(source, &path);
                let info = ParamInfo {
                    tags: line
                        .map(|line| tags_on_line(source, line))
                        .unwrap_or_default(),
                    unit: unit_of(&key),
                    value,
                    path,
                };
                (line.unwrap_or(usize::MAX), info)
            })
            .collect();
        // In the file's order (a parameter the file leaves to its default goes last).
        list.sort_by(|a, b| a.0.cmp(&b.0).then_with(|| a.1.path.cmp(&b.1.path)));
        Ok(list.into_iter().map(|(_, info)| info).collect())
    }

    /// The value of the parameter at `path` (in the unit of [`ActionParams::parameter_list`]).
    /// An unknown path is [`PianoError::UnknownParameter`].
    pub fn parameter(&self, path: &str) -> Result<f64> {
        let mut out = Vec::new();
        leaves("", &as_value(self)?, &mut out);
        out.iter()
            .find(|(p, _, _)| p == path)
            .map(|(_, v, _)| *v)
            .ok_or_else(|| unknown(path, out.iter().map(|(p, _, _)| p.as_str())))
    }

    /// Sets the parameter at `path` to `value` and checks the whole set again
    /// ([`ActionParams::validate`]); on any error the parameters are left unchanged. An
    /// unknown path is [`PianoError::UnknownParameter`]; a value the parameter cannot take
    /// (a count that is not a whole number, a negative mass) is an error naming the path.
    pub fn set_parameter(&mut self, path: &str, value: f64) -> Result<()> {
        let mut tree = as_value(self)?;
        let mut list = Vec::new();
        leaves("", &tree, &mut list);
        let Some((_, old, _)) = list.iter().find(|(p, _, _)| p == path) else {
            return Err(unknown(path, list.iter().map(|(p, _, _)| p.as_str())));
        };
        let slot = pointer(path)
            .and_then(|ptr| tree.pointer_mut(&ptr))
            .ok_or_else(|| unknown(path, std::iter::empty()))?;
        let was_integer = slot.is_u64() || slot.is_i64();
        *slot = if was_integer {
            if value.fract() != 0.0 || !(0.0..=u32::MAX as f64).contains(&value) {
                return Err(PianoError::params(
                    path,
                    format!("must be a whole number, got {value} (now {old})"),
                ));
            }
            Value::from(value as u64)
        } else {
            serde_json::Number::from_f64(value)
                .map(Value::Number)
                .ok_or_else(|| PianoError::params(path, format!("must be finite, got {value}")))?
        };
        let updated: ActionParams = serde_json::from_value(tree)
            .map_err(|e| PianoError::params(path, format!("cannot take {value}: {e}")))?;
        updated.validate()?;
        *self = updated;
        Ok(())
    }
}

/// `a.b[2]` as the JSON pointer `/a/b/2`.
fn pointer(path: &str) -> Option<String> {
    use crate::toml_lines::Step;
    let mut out = String::new();
    for step in crate::toml_lines::steps(path)? {
        out.push('/');
        match step {
            Step::Key(k) => out.push_str(k),
            Step::Index(i) => out.push_str(&i.to_string()),
        }
    }
    Some(out)
}

fn unknown<'a>(path: &str, known: impl Iterator<Item = &'a str>) -> PianoError {
    PianoError::UnknownParameter {
        path: path.to_string(),
        suggestion: closest(path, known).map(str::to_string),
    }
}
