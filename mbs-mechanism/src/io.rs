//! Reading and writing descriptions as TOML or JSON.

use std::path::Path;

use crate::description::Mechanism;
use crate::error::{MechanismError, Result};
use crate::toml_lines::line_at;

/// The format of a description file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// TOML (`.toml`).
    Toml,
    /// JSON (`.json`).
    Json,
}

impl Format {
    /// The format of a path by its extension (TOML unless it ends in `.json`).
    pub fn of(path: &Path) -> Format {
        match path.extension().and_then(|e| e.to_str()) {
            Some(e) if e.eq_ignore_ascii_case("json") => Format::Json,
            _ => Format::Toml,
        }
    }
}

fn path_field(path: &serde_path_to_error::Path) -> String {
    match path.to_string() {
        p if p == "." => String::new(),
        p => p,
    }
}

impl Mechanism {
    /// Parses a TOML description (not yet checked: see [`Mechanism::validate`]). A syntax
    /// error gives its line; a value that does not fit gives its field path and line.
    pub fn from_toml_str(text: &str) -> Result<Mechanism> {
        let de = toml::Deserializer::parse(text).map_err(|e| {
            let mut err = MechanismError::field("", e.message().trim().to_string());
            err.line = e.span().map(|s| line_at(text, s.start));
            err
        })?;
        serde_path_to_error::deserialize(de).map_err(|e| {
            let field = path_field(e.path());
            let inner = e.inner();
            let mut err = MechanismError::field(&field, inner.message().trim().to_string());
            err.line = crate::toml_lines::line_of(text, &field)
                .or_else(|| inner.span().map(|s| line_at(text, s.start)));
            err
        })
    }

    /// Parses a JSON description (not yet checked). Errors give the line and field path.
    pub fn from_json_str(text: &str) -> Result<Mechanism> {
        let mut de = serde_json::Deserializer::from_str(text);
        serde_path_to_error::deserialize(&mut de).map_err(|e| {
            let field = path_field(e.path());
            let inner = e.inner();
            let mut err = MechanismError::field(&field, inner.to_string());
            if inner.line() > 0 {
                err.line = Some(inner.line());
            }
            err
        })
    }

    /// Reads and checks a description file (TOML, or JSON by its `.json` extension); every
    /// error names the file, and for TOML the line of the field.
    pub fn load(path: &Path) -> Result<Mechanism> {
        let shown = path.display().to_string();
        let text = std::fs::read_to_string(path)
            .map_err(|e| MechanismError::caused("", e).in_file(&shown, None))?;
        let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
        let (parsed, toml_text) = match Format::of(path) {
            Format::Toml => (Mechanism::from_toml_str(text), Some(text)),
            Format::Json => (Mechanism::from_json_str(text), None),
        };
        let m = parsed.map_err(|e| e.in_file(&shown, toml_text))?;
        m.validate().map_err(|e| e.in_file(&shown, toml_text))?;
        Ok(m)
    }

    /// The description as JSON (numbers round-trip exactly).
    pub fn to_json_string(&self) -> Result<String> {
        serde_json::to_string_pretty(self).map_err(|e| MechanismError::caused("", e))
    }

    /// The description as TOML, with a header from `about` and a comment before each
    /// section saying what its numbers mean (numbers round-trip exactly).
    pub fn to_toml_string(&self) -> Result<String> {
        let body = toml::to_string(self).map_err(|e| MechanismError::caused("", e))?;
        let mut out = String::new();
        out.push_str(&format!("# Mechanism description: {}\n", self.name));
        for line in self.about.lines() {
            out.push_str(&format!("# {line}\n"));
        }
        out.push_str(
            "# Units: m, kg, kg·m², rad, N, N·m, s. Each body's frame is its joint's frame: \
             `joint.at` and `joint.angle` place it in the parent's frame (the world for the \
             ground), and the body's com, outline, shapes and points are given in it. \
             Numbers are written to their last digit, so the file builds exactly the \
             mechanism it was written from.\n\n",
        );
        let mut seen = std::collections::BTreeSet::new();
        for line in body.lines() {
            let header = line.trim();
            if let Some(section) = header
                .strip_prefix("[[")
                .and_then(|h| h.strip_suffix("]]"))
                .filter(|h| !h.contains('.'))
                && seen.insert(section.to_string())
                && let Some(comment) = section_comment(section)
            {
                out.push_str(&format!("\n# {comment}\n"));
            }
            out.push_str(line);
            out.push('\n');
        }
        Ok(out)
    }

    /// Writes the description to `path` (TOML, or JSON by its `.json` extension).
    pub fn save(&self, path: &Path) -> Result<()> {
        let text = match Format::of(path) {
            Format::Toml => self.to_toml_string()?,
            Format::Json => self.to_json_string()?,
        };
        std::fs::write(path, text)
            .map_err(|e| MechanismError::caused("", e).in_file(&path.display().to_string(), None))
    }
}

fn section_comment(section: &str) -> Option<&'static str> {
    Some(match section {
        "ground" => "Fixed parts, for drawings: outlines in world coordinates.",
        "bodies" => {
            "Bodies: mass (kg), com (m) and inertia about the com (kg·m²); the joint \
             (revolute, prismatic or fixed) with its stops (limits) and pivot friction \
             (coulomb N·m, regularization rad/s); an outline (polygon or circle, thickness \
             and z in m) to draw it."
        }
        "torsion_springs" => {
            "Torsion springs on joints: tau = preload - stiffness (q - rest) - damping qdot \
             (N·m, rad)."
        }
        "point_springs" => "Springs between two points: tension = preload + k (l - rest_length).",
        "cords" => "Cords that only pull: tension = k (l - length) when taut, zero when slack.",
        "loads" => "Constant forces (N) along a world direction.",
        "contacts" => {
            "Contact pairs: shapes on each side in the body frame (the ground's in world \
             coordinates), a normal law (a material preset or explicit parameters, N/m^p) \
             and friction."
        }
        "strings" => {
            "Strikers on modal strings: the string at rest, the striker's felt, the string."
        }
        "extensions" => "Force elements provided by the program that reads this file.",
        "inputs" => {
            "Where the mechanism is driven: a force at a point, or a prescribed coordinate."
        }
        "markers" => "Named points on bodies.",
        "events" => "Named events: a contact's onset or release, a coordinate crossing a value.",
        "metrics" => "Named measurements read at the first occurrence of an event.",
        _ => return None,
    })
}
