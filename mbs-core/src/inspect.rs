//! Cross-checking a model against another engine: evaluate the mass matrix, RNEA, nonlinear
//! effects, gravity torques and ABA at a list of states, in the JSON shapes used by
//! `examples/inspect.rs` and by the golden data in `planar5_reference.json`.

use serde::{Deserialize, Serialize};

use crate::aba::aba;
use crate::crba::crba;
use crate::data::Data;
use crate::error::{CoreError, Result};
use crate::model::Model;
use crate::rnea::{gravity_torque, nonlinear_effects, rnea};

/// One state to evaluate.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StateInput {
    /// Coordinates.
    pub q: Vec<f64>,
    /// Velocities.
    pub v: Vec<f64>,
    /// Accelerations, for `rnea_tau`.
    pub a: Vec<f64>,
    /// Generalized forces, for `aba_qdd`.
    pub tau: Vec<f64>,
}

/// The input file: `{"states": [{"q": [...], "v": [...], "a": [...], "tau": [...]}]}`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StatesFile {
    /// The states.
    pub states: Vec<StateInput>,
}

/// What is computed at one state.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StateReport {
    /// `M(q)`, row by row.
    pub mass_matrix: Vec<Vec<f64>>,
    /// `RNEA(q, v, a)`.
    pub rnea_tau: Vec<f64>,
    /// `C(q, v) v + g(q)`.
    pub nonlinear_effects: Vec<f64>,
    /// `g(q)`.
    pub gravity_torque: Vec<f64>,
    /// `ABA(q, v, tau)`.
    pub aba_qdd: Vec<f64>,
}

/// The output: `{"states": [StateReport, ...]}`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReportFile {
    /// One report per input state, in order.
    pub states: Vec<StateReport>,
}

impl StatesFile {
    /// Parses the JSON states file; errors name the field path.
    /// An empty list of states is refused, and so is a value that is not finite.
    pub fn from_json_str(text: &str) -> Result<Self> {
        let de = &mut serde_json::Deserializer::from_str(text);
        let file: StatesFile = serde_path_to_error::deserialize(de).map_err(|e| {
            let inner = e.inner();
            // serde_json ends its message with the place, which is said first here.
            let message = inner.to_string();
            let message = message
                .rsplit_once(" at line ")
                .map_or(message.as_str(), |(m, _)| m);
            let field = match e.path().to_string() {
                p if p == "." => String::new(),
                p => format!(", field `{p}`"),
            };
            CoreError::States(format!(
                "line {}, column {}{field}: {message}",
                inner.line(),
                inner.column(),
            ))
        })?;
        if file.states.is_empty() {
            return Err(CoreError::States(
                "field `states`: the list is empty; give at least one state".into(),
            ));
        }
        for (k, s) in file.states.iter().enumerate() {
            for (name, values) in [("q", &s.q), ("v", &s.v), ("a", &s.a), ("tau", &s.tau)] {
                if let Some((i, v)) = values.iter().enumerate().find(|(_, v)| !v.is_finite()) {
                    return Err(CoreError::States(format!(
                        "field `states[{k}].{name}[{i}]`: {v} is not a finite number"
                    )));
                }
            }
        }
        Ok(file)
    }
}

/// Evaluates every state; an error names the state index and what is wrong with it: a
/// vector of the wrong length, a non-finite entry, or numbers so large that a result
/// overflows (a report holds only finite numbers).
pub fn inspect(model: &Model, input: &StatesFile) -> Result<ReportFile> {
    let mut data = Data::new(model);
    let n = model.nv();
    let mut states = Vec::with_capacity(input.states.len());
    for (k, s) in input.states.iter().enumerate() {
        let at = |e: CoreError| CoreError::States(format!("field `states[{k}]`: {e}"));
        let m = crba(model, &mut data, &s.q).map_err(at)?;
        let mass_matrix: Vec<Vec<f64>> = (0..n)
            .map(|i| (0..n).map(|j| m[(i, j)]).collect())
            .collect();
        let rnea_tau = rnea(model, &mut data, &s.q, &s.v, &s.a)
            .map_err(at)?
            .as_slice()
            .to_vec();
        let nle = nonlinear_effects(model, &mut data, &s.q, &s.v)
            .map_err(at)?
            .as_slice()
            .to_vec();
        let g = gravity_torque(model, &mut data, &s.q)
            .map_err(at)?
            .as_slice()
            .to_vec();
        let qdd = aba(model, &mut data, &s.q, &s.v, &s.tau)
            .map_err(at)?
            .as_slice()
            .to_vec();
        // A finite state can still overflow (v = 1e300 squares to infinity): say so rather
        // than print `null`.
        let mass_entries = mass_matrix.concat();
        let outputs = [
            ("mass_matrix", &mass_entries),
            ("rnea_tau", &rnea_tau),
            ("nonlinear_effects", &nle),
            ("gravity_torque", &g),
            ("aba_qdd", &qdd),
        ];
        for (what, values) in outputs {
            if let Some(value) = values.iter().find(|x| !x.is_finite()) {
                return Err(CoreError::States(format!(
                    "field `states[{k}]`: {what} is not finite ({value}): q, v, a or tau are \
                     too large for the model"
                )));
            }
        }
        states.push(StateReport {
            mass_matrix,
            rnea_tau,
            nonlinear_effects: nle,
            gravity_torque: g,
            aba_qdd: qdd,
        });
    }
    Ok(ReportFile { states })
}
