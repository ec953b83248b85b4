//! Candidate effects: what a library of named physical effects declares about each, so
//! that a diagnosis can fit it, judge it and report it without knowing the physics.

/// One parameter of an effect.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EffectParam {
    /// Its name, part of the report's contract (`c_n_m_s`).
    pub name: &'static str,
    /// Its unit (`N·m·s`).
    pub unit: &'static str,
    /// The value at which the effect vanishes (`None` for a shape parameter, such as a
    /// velocity scale, that means nothing when the effect's strength is at its null).
    pub null: Option<f64>,
    /// The physically plausible range: a fit outside it is not accepted.
    pub range: [f64; 2],
    /// A typical clearly visible value, used as a fit's start (strength parameters start
    /// at a tenth of it).
    pub typical: f64,
    /// Whether the fit moves it on a log scale (shape parameters spanning decades).
    pub log_scale: bool,
    /// Values a screening tries for this shape parameter besides the strength's grid (a
    /// flexibility's location); empty: its typical value only.
    pub screen: &'static [f64],
}

/// An effect of a library.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EffectSpec {
    /// Its id, part of the report's contract (`pivot_viscous`).
    pub id: &'static str,
    /// What it is, in one line, with its law.
    pub summary: &'static str,
    /// Its parameters; the first is its strength (with a null).
    pub params: &'static [EffectParam],
    /// The effects it is easily mistaken for.
    pub confusable_with: &'static [&'static str],
    /// The experiment that would separate it from those.
    pub discriminating_experiment: &'static str,
}

impl EffectSpec {
    /// The parameter named `name`.
    pub fn param(&self, name: &str) -> Option<&EffectParam> {
        self.params.iter().find(|p| p.name == name)
    }
}
