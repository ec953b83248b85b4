//! `piano_action._core`: the Python extension module of the `piano_action` package.
//!
//! It wraps `piano-action` as it is: parameter files, scenarios, keystrokes and sweep rows
//! run the same code as the `piano` command line, so the numbers are the same to the bit.
//! The pure-Python part of the package (`python/piano_action/`) adds the Dask sweep and
//! the command line. Errors become `piano_action.InputError` (a `ValueError` carrying the
//! file, line and field), `piano_action.PianoFileError` (an `OSError`) or
//! `piano_action.SimulationError` (a `RuntimeError`), all subclasses of
//! `piano_action.PianoError`. Simulations run with the GIL released.

use std::path::PathBuf;

use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2};
use piano_action::scenario::{InputSpec, Scenario};
use piano_action::simulate::{Run, prepare, simulate as simulate_input};
use piano_action::sweep::{SweepKind, SweepRow, check_levels, csv, levels};
use piano_action::{ActionParams, ModelKind, PianoError};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

// The exceptions are defined in Python (`python/piano_action/_errors.py`), so that they
// can also be a `ValueError`, an `OSError` or a `RuntimeError`.
pyo3::import_exception!(piano_action._errors, InputError);
pyo3::import_exception!(piano_action._errors, PianoFileError);
pyo3::import_exception!(piano_action._errors, SimulationError);

thread_local! {
    /// The exception a signal handler raised while a solve on this thread was running
    /// (Ctrl-C's `KeyboardInterrupt`): given back instead of the solve's "interrupted".
    static PENDING: std::cell::RefCell<Option<PyErr>> = const { std::cell::RefCell::new(None) };
}

/// The interrupt check of the solves run from Python: Python's signal handlers run (on the
/// main thread), and one that raises (Ctrl-C) stops the solve.
fn python_interrupted() -> bool {
    Python::attach(|py| match py.check_signals() {
        Ok(()) => false,
        Err(e) => {
            PENDING.with(|p| *p.borrow_mut() = Some(e));
            true
        }
    })
}

/// Runs `f` with the GIL released, stoppable by Ctrl-C (see [`python_interrupted`]).
fn detach_interruptible<T, F>(py: Python<'_>, f: F) -> T
where
    F: Send + FnOnce() -> T,
    T: Send,
{
    py.detach(move || mbs_integrators::with_interrupt_check(python_interrupted, f))
}

/// The Python exception for `e`, with its attributes set: `kind`, `file`, `line`, `field`
/// and `message` (None where they do not apply).
fn to_py(e: PianoError) -> PyErr {
    if let Some(raised) = PENDING.with(|p| p.borrow_mut().take()) {
        return raised;
    }
    Python::attach(|py| {
        let text = e.to_string();
        let (err, kind, file, line, field, message) = match &e {
            PianoError::Input(i) => (
                InputError::new_err(text.clone()),
                Some(i.kind.label().to_string()),
                i.file.as_ref().map(|p| p.display().to_string()),
                i.line,
                Some(i.field.clone()).filter(|f| !f.is_empty()),
                i.message.clone(),
            ),
            PianoError::UnknownParameter { path, .. } => (
                InputError::new_err(text.clone()),
                Some("parameter path".to_string()),
                None,
                None,
                Some(path.clone()),
                text.clone(),
            ),
            PianoError::Mechanism(m) => (
                InputError::new_err(text.clone()),
                Some("mechanism description".to_string()),
                m.file.clone(),
                m.line,
                Some(m.field.clone()).filter(|f| !f.is_empty()),
                m.message.clone(),
            ),
            PianoError::File { path, message } => (
                PianoFileError::new_err(text.clone()),
                None,
                Some(path.display().to_string()),
                None,
                None,
                message.clone(),
            ),
            PianoError::Io { path, .. } => (
                PianoFileError::new_err(text.clone()),
                None,
                Some(path.display().to_string()),
                None,
                None,
                text.clone(),
            ),
            _ => (
                SimulationError::new_err(text.clone()),
                None,
                None,
                None,
                None,
                text.clone(),
            ),
        };
        let value = err.value(py);
        // Setting attributes on a fresh exception instance cannot fail in practice; if it
        // did, the message still says everything.
        let _ = value.setattr("kind", kind);
        let _ = value.setattr("file", file);
        let _ = value.setattr("line", line);
        let _ = value.setattr("field", field);
        let _ = value.setattr("message", message);
        err
    })
}

/// An option of a function (`touch`, `model`, `runs`...) with a wrong value.
fn option_error(option: &str, message: String) -> PyErr {
    to_py(PianoError::option(option, message))
}

/// A set of action parameters: the embedded reference, or a parameter file.
#[pyclass(module = "piano_action._core", name = "Params", from_py_object)]
#[derive(Clone)]
struct Params {
    inner: ActionParams,
    /// The file it was read from, for `paths()`'s source tags and error messages.
    file: Option<PathBuf>,
    /// The text it was read from (None for the reference, whose text is embedded).
    text: Option<String>,
}

#[pymethods]
impl Params {
    /// The reference parameters (the embedded defaults, as `piano` without `--params`).
    #[new]
    fn new() -> Self {
        Params {
            inner: ActionParams::reference(),
            file: None,
            text: None,
        }
    }

    /// Reads a parameter file; errors name the file, the line and the field.
    #[staticmethod]
    fn load(path: PathBuf) -> PyResult<Self> {
        let text = std::fs::read_to_string(&path)
            .map_err(|e| to_py(PianoError::io(&path, "read the parameter file", e)))?;
        let inner = ActionParams::from_toml_str(&text).map_err(|e| to_py(e.in_file(&path)))?;
        Ok(Params {
            inner,
            file: Some(path),
            text: Some(text),
        })
    }

    /// Parses parameters from TOML text (the parameter file's format).
    #[staticmethod]
    fn from_toml(text: &str) -> PyResult<Self> {
        let inner = ActionParams::from_toml_str(text).map_err(to_py)?;
        Ok(Params {
            inner,
            file: None,
            text: Some(text.to_string()),
        })
    }

    /// The parameters as TOML text (a parameter file).
    fn to_toml(&self) -> PyResult<String> {
        self.inner.to_toml_string().map_err(to_py)
    }

    /// The value at a parameter path (`hammer.mass_g`, `jack.toe_mm[1]`; `paths()` lists
    /// them).
    fn get(&self, path: &str) -> PyResult<f64> {
        self.inner.parameter(path).map_err(to_py)
    }

    /// Sets the value at a parameter path; the parameters are checked again, and a value
    /// that makes them invalid is refused (the parameters stay as they were).
    fn set(&mut self, path: &str, value: f64) -> PyResult<()> {
        let mut changed = self.inner.clone();
        changed.set_parameter(path, value).map_err(to_py)?;
        changed.validate().map_err(to_py)?;
        self.inner = changed;
        // The text no longer says the same; tags are still read from it by `paths()`.
        Ok(())
    }

    /// Every numeric parameter: a list of `(path, value, unit, tags)`, tags being the
    /// source tags on its line of the parameter file (`[S]`, `[M]`, `[regulated]`, ...).
    fn paths(&self) -> PyResult<Vec<(String, f64, String, String)>> {
        let source = match &self.text {
            Some(t) => t.clone(),
            None => piano_action::params::DEFAULT_PARAMS_TOML.to_string(),
        };
        let list = self.inner.parameter_list(&source).map_err(to_py)?;
        Ok(list
            .into_iter()
            .map(|p| (p.path, p.value, p.unit.to_string(), p.tags))
            .collect())
    }

    /// A copy (`set` on it leaves this one as it is).
    fn copy(&self) -> Self {
        self.clone()
    }

    /// Two parameter sets are equal when every value is (wherever they were read from).
    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other
            .extract::<Params>()
            .is_ok_and(|o| o.inner == self.inner)
    }

    /// The file these parameters were read from, if any.
    #[getter]
    fn file(&self) -> Option<String> {
        self.file.as_ref().map(|p| p.display().to_string())
    }

    fn __repr__(&self) -> String {
        let base = match &self.file {
            Some(f) => format!("Params.load({:?})", f.display().to_string()),
            None if self.text.is_some() => "Params.from_toml(...)".to_string(),
            None => "Params()".to_string(),
        };
        // Whether `set` (or a regulation) changed it from what it was read as.
        let read = match &self.text {
            Some(t) => ActionParams::from_toml_str(t).ok(),
            None => Some(ActionParams::reference()),
        };
        if read.as_ref() == Some(&self.inner) {
            base
        } else {
            format!("<{base}, changed>")
        }
    }

    /// Pickling (Dask sends parameters to its workers): the TOML text, which gives back
    /// the same values to the bit.
    fn __getstate__(&self) -> PyResult<(String, Option<String>, Option<String>)> {
        Ok((
            self.to_toml()?,
            self.file.as_ref().map(|p| p.display().to_string()),
            self.text.clone(),
        ))
    }

    fn __setstate__(&mut self, state: (String, Option<String>, Option<String>)) -> PyResult<()> {
        self.inner = ActionParams::from_toml_str(&state.0).map_err(to_py)?;
        self.file = state.1.map(PathBuf::from);
        self.text = state.2;
        Ok(())
    }
}

impl Params {
    /// The text these parameters were read from, if they still say the same (a file's
    /// comments and source tags are kept); else the values written afresh; None for the
    /// unchanged reference.
    fn source_text(&self) -> PyResult<Option<String>> {
        let read = match &self.text {
            Some(t) => ActionParams::from_toml_str(t).ok(),
            None => Some(ActionParams::reference()),
        };
        if read.as_ref() == Some(&self.inner) {
            return Ok(self.text.clone());
        }
        self.inner.to_toml_string().map(Some).map_err(to_py)
    }
}

/// The parameters given, or the reference.
fn params_or_reference(params: Option<&Params>) -> ActionParams {
    params.map_or_else(ActionParams::reference, |p| p.inner.clone())
}

/// A scenario: what drives the key, for how long, on which model (the scenario file's
/// format; see `piano-action/scenarios/`).
#[pyclass(module = "piano_action._core", name = "Scenario", from_py_object)]
#[derive(Clone)]
struct ScenarioPy {
    inner: Scenario,
    file: Option<PathBuf>,
}

#[pymethods]
impl ScenarioPy {
    /// Reads a scenario file (and a motion's CSV beside it); errors name the file, the
    /// line and the field.
    #[staticmethod]
    fn load(path: PathBuf) -> PyResult<Self> {
        let inner = Scenario::load(&path).map_err(to_py)?;
        Ok(ScenarioPy {
            inner,
            file: Some(path),
        })
    }

    /// Parses a scenario from TOML text; the files it names (a mechanism description, a
    /// motion's `csv`) are read relative to the folder `base` (the working folder by
    /// default).
    #[staticmethod]
    #[pyo3(signature = (text, base=None))]
    fn from_toml(text: &str, base: Option<PathBuf>) -> PyResult<Self> {
        let base = base.unwrap_or_else(|| PathBuf::from("."));
        let inner = Scenario::from_toml_str_in(text, &base, None).map_err(to_py)?;
        Ok(ScenarioPy { inner, file: None })
    }

    /// The scenario as TOML text, as its file says it (a motion read from a `csv` names
    /// the file, not its points).
    fn to_toml(&self) -> PyResult<String> {
        let mut s = self.inner.clone();
        if let InputSpec::Motion(m) = &mut s.input
            && m.csv.is_some()
        {
            m.points = None;
        }
        toml::to_string(&s).map_err(|e| {
            to_py(PianoError::scenario(
                "",
                format!("cannot write as TOML: {e}"),
            ))
        })
    }

    /// The model (`simplified`, `single` or `double`; empty for a mechanism scenario).
    #[getter]
    fn model(&self) -> String {
        self.inner.model.clone()
    }

    /// Simulated time (s).
    #[getter]
    fn duration_s(&self) -> f64 {
        self.inner.duration_s
    }

    /// Output grid spacing (s).
    #[getter]
    fn output_step_s(&self) -> f64 {
        self.inner.output_step_s
    }

    /// The file it was read from, if any.
    #[getter]
    fn file(&self) -> Option<String> {
        self.file.as_ref().map(|p| p.display().to_string())
    }

    fn __repr__(&self) -> String {
        match &self.file {
            Some(f) => format!("Scenario.load({:?})", f.display().to_string()),
            None => format!(
                "Scenario(model={:?}, duration_s={})",
                self.inner.model, self.inner.duration_s
            ),
        }
    }
}

/// Something that happened in a keystroke (`let_off`, `string_contact_start`, ...).
#[pyclass(module = "piano_action._core", frozen, get_all)]
#[derive(Clone)]
struct Event {
    /// What happened.
    name: String,
    /// When (s).
    time_s: f64,
}

#[pymethods]
impl Event {
    fn __repr__(&self) -> String {
        format!("Event({:?}, time_s={})", self.name, self.time_s)
    }
}

/// One blow of the hammer on the string.
#[pyclass(module = "piano_action._core", frozen, get_all)]
#[derive(Clone)]
struct Strike {
    /// Start of string contact (s).
    time_s: f64,
    /// Speed of the strike point at contact (m/s).
    hammer_velocity_m_s: f64,
    /// From first touch to last release (s), if the hammer left the string in the run.
    contact_duration_s: Option<f64>,
    /// Speed of the strike point leaving the string (m/s), if it did.
    rebound_velocity_m_s: Option<f64>,
    /// Contact pulses in the blow (1 for a clean blow).
    pulses: usize,
}

#[pymethods]
impl Strike {
    fn __repr__(&self) -> String {
        format!(
            "Strike(time_s={}, hammer_velocity_m_s={})",
            self.time_s, self.hammer_velocity_m_s
        )
    }
}

/// The result of a keystroke on a grand model: arrays on the output grid, the events, the
/// strikes and the times a technician reads.
#[pyclass(module = "piano_action._core", name = "Run")]
struct RunPy {
    run: Run,
    params: ActionParams,
    scenario: Scenario,
    names: Vec<String>,
}

#[pymethods]
impl RunPy {
    /// `simplified`, `single` or `double`.
    #[getter]
    fn model(&self) -> &'static str {
        self.run.kind.name()
    }

    /// Output times (s), shape `(n,)`.
    #[getter]
    fn t<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.run.solution.t.clone())
    }

    /// The coordinates' names (the columns of `q` and `v`).
    #[getter]
    fn coordinate_names(&self) -> Vec<String> {
        self.names.clone()
    }

    /// Coordinates (rad for joints, m for the key's presser), shape `(n, coordinates)`.
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.columns(py, 0, self.names.len())
    }

    /// Velocities, shape `(n, coordinates)`.
    #[getter]
    fn v<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let nv = self.names.len();
        self.columns(py, nv, 2 * nv)
    }

    /// The whole state (coordinates, velocities, then the force elements' internal states
    /// such as the string's modal amplitudes), shape `(n, states)`.
    #[getter]
    fn states<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.columns(py, 0, self.run.solution.n)
    }

    /// Under a prescribed key motion (`kind = "motion"`), the vertical force the hand
    /// applies at the finger point (N, pressing down positive) at each output time; None
    /// for the other inputs.
    #[getter]
    fn key_drive_force_n<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray1<f64>>> {
        let f = &self.run.key_drive_force_n;
        (f.len() == self.run.solution.len() && !f.is_empty())
            .then(|| PyArray1::from_vec(py, f.clone()))
    }

    /// The events, in time order.
    #[getter]
    fn events(&self) -> Vec<Event> {
        self.run
            .events
            .iter()
            .map(|e| Event {
                name: e.name.to_string(),
                time_s: e.time_s,
            })
            .collect()
    }

    /// The blows of the hammer on the string.
    #[getter]
    fn strikes(&self) -> Vec<Strike> {
        self.run
            .strikes
            .iter()
            .map(|s| Strike {
                time_s: s.time_s,
                hammer_velocity_m_s: s.hammer_velocity_m_s,
                contact_duration_s: s.contact_duration_s,
                rebound_velocity_m_s: s.rebound_velocity_m_s,
                pulses: s.pulses,
            })
            .collect()
    }

    /// When the key front has gone down 0.1 mm (s).
    #[getter]
    fn key_start_time_s(&self) -> Option<f64> {
        self.run.key_start_time_s
    }

    /// From key start to string contact (s).
    #[getter]
    fn travel_time_s(&self) -> Option<f64> {
        self.run.travel_time_s
    }

    /// Let-off: the jack tripped by its button (s).
    #[getter]
    fn let_off_time_s(&self) -> Option<f64> {
        self.run.let_off_time_s
    }

    /// The key reaching its front-rail punching (s).
    #[getter]
    fn key_bottom_time_s(&self) -> Option<f64> {
        self.run.key_bottom_time_s
    }

    /// The hammer caught by the backcheck (s).
    #[getter]
    fn check_time_s(&self) -> Option<f64> {
        self.run.check_time_s
    }

    /// The integrator's work: steps, rejected steps, derivative and Jacobian evaluations,
    /// LU decompositions, Newton iterations and failures, event evaluations.
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = &self.run.solution.stats;
        let d = PyDict::new(py);
        d.set_item("steps", s.steps)?;
        d.set_item("rejected", s.rejected)?;
        d.set_item("derivative_evals", s.derivative_evals)?;
        d.set_item("jacobian_evals", s.jacobian_evals)?;
        d.set_item("lu_decompositions", s.lu_decompositions)?;
        d.set_item("newton_iterations", s.newton_iterations)?;
        d.set_item("newton_failures", s.newton_failures)?;
        d.set_item("event_evals", s.event_evals)?;
        Ok(d)
    }

    /// The summary, as `summary.json` of `piano simulate` has it (a dict).
    fn summary<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let value = piano_action::scenario::run_summary(&self.run);
        json_to_py(py, &value)
    }

    /// Every contact on the output grid, as `contacts.csv` of `piano simulate` has it: a
    /// dict from the contact's name to a dict of arrays `gap_mm`, `force_n`, `px_mm`,
    /// `py_mm`, `nx`, `ny` and `active` (bool). Computed at each call (it rebuilds the
    /// action at rest, a few milliseconds), with the GIL released.
    fn contacts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let (params, scenario, run) = (&self.params, &self.scenario, &self.run);
        let table = detach_interruptible(py, || {
            let input = scenario.input.to_input()?;
            let prepared = prepare(params, run.kind, &input)?;
            let action = &prepared.action;
            let sol = &run.solution;
            let mut out = Vec::new();
            for name in action.contacts.keys() {
                let mut cols: [Vec<f64>; 6] = Default::default();
                let mut active = Vec::with_capacity(sol.len());
                for i in 0..sol.len() {
                    let o = action.contact_output(name, sol.t[i], sol.state(i))?;
                    let vals = piano_action::scenario::contact_columns(&o);
                    for (c, v) in cols.iter_mut().zip(vals) {
                        c.push(v);
                    }
                    active.push(o.active);
                }
                out.push((name.clone(), cols, active));
            }
            Ok::<_, PianoError>(out)
        })
        .map_err(to_py)?;
        let d = PyDict::new(py);
        for (name, cols, active) in table {
            let c = PyDict::new(py);
            let keys = ["gap_mm", "force_n", "px_mm", "py_mm", "nx", "ny"];
            for (k, col) in keys.into_iter().zip(cols) {
                c.set_item(k, PyArray1::from_vec(py, col))?;
            }
            c.set_item("active", PyArray1::from_vec(py, active))?;
            d.set_item(name, c)?;
        }
        Ok(d)
    }

    fn __repr__(&self) -> String {
        format!(
            "Run(model={:?}, points={}, strikes={})",
            self.run.kind.name(),
            self.run.solution.len(),
            self.run.strikes.len()
        )
    }
}

impl RunPy {
    /// Columns `from..to` of the states as an `(n, to − from)` array.
    fn columns<'py>(
        &self,
        py: Python<'py>,
        from: usize,
        to: usize,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        state_columns(py, &self.run.solution, from, to)
    }
}

/// A mechanism description (TOML or JSON): bodies, joints, contacts, inputs, events and
/// metrics (see `examples/mechanisms/`).
#[pyclass(module = "piano_action._core", name = "Mechanism", from_py_object)]
#[derive(Clone)]
struct MechanismPy {
    inner: piano_action::mechanism::Mechanism,
}

#[pymethods]
impl MechanismPy {
    /// Reads and checks a description; errors name the file, the line and the field.
    #[staticmethod]
    fn load(path: PathBuf) -> PyResult<Self> {
        let inner = piano_action::mechanism::Mechanism::load(&path)
            .map_err(|e| to_py(PianoError::from(e)))?;
        inner.validate().map_err(|e| to_py(PianoError::from(e)))?;
        Ok(MechanismPy { inner })
    }

    /// Its name.
    #[getter]
    fn name(&self) -> String {
        self.inner.name.clone()
    }

    /// Its bodies' names.
    #[getter]
    fn bodies(&self) -> Vec<String> {
        self.inner.bodies.iter().map(|b| b.name.clone()).collect()
    }

    /// Its contacts' names.
    #[getter]
    fn contacts(&self) -> Vec<String> {
        self.inner.contacts.iter().map(|c| c.name.clone()).collect()
    }

    /// The whole description as a dict (its JSON form).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let v =
            serde_json::to_value(&self.inner).map_err(|e| PyValueError::new_err(e.to_string()))?;
        json_to_py(py, &v)
    }

    fn __repr__(&self) -> String {
        format!("Mechanism({:?})", self.inner.name)
    }
}

/// The result of a scenario running a mechanism description.
#[pyclass(module = "piano_action._core", name = "MechanismRun")]
struct MechanismRunPy {
    run: piano_action::mechanism_run::MechanismRun,
}

#[pymethods]
impl MechanismRunPy {
    /// The description's name.
    #[getter]
    fn mechanism(&self) -> String {
        self.run.mechanism.name.clone()
    }

    /// Output times (s), shape `(n,)`.
    #[getter]
    fn t<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.run.solution.t.clone())
    }

    /// The coordinates' names (the columns of `q` and `v`).
    #[getter]
    fn coordinate_names(&self) -> Vec<String> {
        self.run.built.system.model().coordinate_names().to_vec()
    }

    /// Coordinates, shape `(n, coordinates)`.
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let nv = self.run.built.system.model().coordinate_names().len();
        state_columns(py, &self.run.solution, 0, nv)
    }

    /// Velocities, shape `(n, coordinates)`.
    #[getter]
    fn v<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let nv = self.run.built.system.model().coordinate_names().len();
        state_columns(py, &self.run.solution, nv, 2 * nv)
    }

    /// The whole state, shape `(n, states)`.
    #[getter]
    fn states<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        state_columns(py, &self.run.solution, 0, self.run.solution.n)
    }

    /// The description's named events, in time order.
    #[getter]
    fn events(&self) -> Vec<Event> {
        self.run
            .events
            .iter()
            .map(|e| Event {
                name: e.name.clone(),
                time_s: e.time_s,
            })
            .collect()
    }

    /// Contact onsets and releases: `(contact, onset, time_s)`.
    #[getter]
    fn contact_events(&self) -> Vec<(String, bool, f64)> {
        self.run.contact_events.clone()
    }

    /// The description's metrics: name to value (None when its event never happened).
    #[getter]
    fn metrics(&self) -> Vec<(String, Option<f64>, String)> {
        self.run
            .metrics
            .iter()
            .map(|m| (m.name.clone(), m.value, m.unit.clone()))
            .collect()
    }

    /// Every contact on the output grid, as `contacts.csv` of `piano simulate` has it: a
    /// dict from the contact's name to a dict of arrays `gap_mm`, `force_n` (zero when not
    /// pressed), `px_mm`, `py_mm`, `nx` and `ny` (None for a contact without numbers).
    fn contacts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let run = &self.run;
        let series = detach_interruptible(py, || piano_action::mechanism_run::contact_series(run))
            .map_err(to_py)?;
        let d = PyDict::new(py);
        for (name, rows) in series {
            let Some(rows) = rows else {
                d.set_item(name, py.None())?;
                continue;
            };
            let c = PyDict::new(py);
            let keys = ["gap_mm", "force_n", "px_mm", "py_mm", "nx", "ny"];
            for (k, key) in keys.into_iter().enumerate() {
                let col: Vec<f64> = rows.iter().map(|r| r[k]).collect();
                c.set_item(key, PyArray1::from_vec(py, col))?;
            }
            d.set_item(name, c)?;
        }
        Ok(d)
    }

    /// The summary, as `summary.json` of `piano simulate` has it (a dict).
    fn summary<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let mut v = piano_action::mechanism_run::mechanism_summary(&self.run);
        if let Some(map) = v.as_object_mut() {
            map.remove("all_events");
        }
        json_to_py(py, &v)
    }

    fn __repr__(&self) -> String {
        format!(
            "MechanismRun({:?}, points={})",
            self.run.mechanism.name,
            self.run.solution.len()
        )
    }
}

/// The hammer swing test: the hammer alone on its flange, released from an angle.
#[pyclass(module = "piano_action._core", name = "Swing")]
struct SwingPy {
    swing: piano_action::pendulum::Swing,
    params: ActionParams,
}

#[pymethods]
impl SwingPy {
    /// Output times (s).
    #[getter]
    fn t<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.swing.t.clone())
    }

    /// Angle from the hanging position (rad).
    #[getter]
    fn angle_rad<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.swing.angle_rad.clone())
    }

    /// Angular rate (rad/s).
    #[getter]
    fn rate_rad_s<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.swing.rate_rad_s.clone())
    }

    /// Turning points: `(time_s, angle_rad)`.
    #[getter]
    fn turns(&self) -> Vec<(f64, f64)> {
        self.swing
            .turns
            .iter()
            .map(|t| (t.time_s, t.angle_rad))
            .collect()
    }

    /// Centre of mass to the centre pin (m).
    #[getter]
    fn com_distance_m(&self) -> f64 {
        self.swing.com_distance_m
    }

    /// Inertia about the centre pin (kg m²).
    #[getter]
    fn inertia_pin_kg_m2(&self) -> f64 {
        self.swing.inertia_pin_kg_m2
    }

    /// The summary, as `summary.json` of `piano simulate` has it (a dict).
    fn summary<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(
            py,
            &piano_action::scenario::pendulum_summary(&self.params, &self.swing),
        )
    }

    fn __repr__(&self) -> String {
        format!(
            "Swing(points={}, turns={})",
            self.swing.t.len(),
            self.swing.turns.len()
        )
    }
}

/// Columns `from..to` of a solution's states as an `(n, to − from)` array.
fn state_columns<'py>(
    py: Python<'py>,
    sol: &mbs_integrators::Solution,
    from: usize,
    to: usize,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let mut data = Vec::with_capacity(sol.len() * (to - from));
    for i in 0..sol.len() {
        data.extend_from_slice(&sol.state(i)[from..to]);
    }
    let a = Array2::from_shape_vec((sol.len(), to - from), data)
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    Ok(a.into_pyarray(py))
}

/// A JSON value as Python objects (dicts, lists, floats, ints, str, None).
fn json_to_py<'py>(py: Python<'py>, v: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    use serde_json::Value;
    Ok(match v {
        Value::Null => py.None().into_bound(py),
        Value::Bool(b) => b.into_pyobject(py)?.to_owned().into_any(),
        Value::Number(n) => match (n.as_u64(), n.as_i64(), n.as_f64()) {
            (Some(u), _, _) => u.into_pyobject(py)?.into_any(),
            (None, Some(i), _) => i.into_pyobject(py)?.into_any(),
            (None, None, Some(f)) => f.into_pyobject(py)?.into_any(),
            _ => py.None().into_bound(py),
        },
        Value::String(s) => s.into_pyobject(py)?.into_any(),
        Value::Array(a) => {
            let list = PyList::empty(py);
            for x in a {
                list.append(json_to_py(py, x)?)?;
            }
            list.into_any()
        }
        Value::Object(o) => {
            let d = PyDict::new(py);
            for (k, x) in o {
                d.set_item(k, json_to_py(py, x)?)?;
            }
            d.into_any()
        }
    })
}

/// Runs a scenario: a keystroke on a grand model (a `Run`), a mechanism description (a
/// `MechanismRun`) or the hammer swing test (a `Swing`), with the GIL released.
fn run_scenario(py: Python<'_>, scenario: ScenarioPy, params: ActionParams) -> PyResult<Py<PyAny>> {
    let s = &scenario.inner;
    let in_file = |e: PianoError| match &scenario.file {
        Some(f) => e.in_file(f),
        None => e,
    };
    if s.loaded_mechanism.is_some() {
        let run = detach_interruptible(py, || s.run_mechanism(&params, &mut |_| {}))
            .map_err(|e| to_py(in_file(e)))?;
        return Ok(Py::new(py, MechanismRunPy { run })?.into_any());
    }
    if let InputSpec::Pendulum(spec) = &s.input {
        let swing = detach_interruptible(py, || {
            piano_action::pendulum::swing_sampled(
                &params,
                spec.release_angle_deg,
                s.duration_s,
                s.output_step_s,
            )
        })
        .map_err(|e| to_py(in_file(e)))?;
        return Ok(Py::new(py, SwingPy { swing, params })?.into_any());
    }
    let kind = s.model_kind().map_err(to_py)?;
    let input = s.input.to_input().map_err(to_py)?;
    let names = piano_action::simulate::coordinate_names(&params, kind, &input).map_err(to_py)?;
    let run = detach_interruptible(py, || s.run(&params)).map_err(|e| to_py(in_file(e)))?;
    Ok(Py::new(
        py,
        RunPy {
            run,
            params,
            scenario: scenario.inner,
            names,
        },
    )?
    .into_any())
}

/// Simulates `scenario` (a `Scenario`, a path to a scenario file, or a dict in the
/// scenario file's shape) with `params` (the reference by default), as `piano simulate`
/// does: the same numbers to the bit. Returns a `Run` for a keystroke on a grand model, a
/// `MechanismRun` for a scenario with a mechanism description and a `Swing` for the
/// hammer swing test. The GIL is released while it runs.
#[pyfunction]
#[pyo3(signature = (scenario, params=None))]
fn simulate(
    py: Python<'_>,
    scenario: &Bound<'_, PyAny>,
    params: Option<Params>,
) -> PyResult<Py<PyAny>> {
    let scenario = scenario_from(scenario)?;
    run_scenario(py, scenario, params_or_reference(params.as_ref()))
}

/// A `Scenario` from what `simulate` accepts.
fn scenario_from(obj: &Bound<'_, PyAny>) -> PyResult<ScenarioPy> {
    if let Ok(s) = obj.extract::<ScenarioPy>() {
        return Ok(s);
    }
    if let Ok(dict) = obj.cast::<PyDict>() {
        // Into TOML text, so the file's own checks (and field paths) apply.
        let table = py_to_toml(dict.as_any(), "")?;
        let toml_text = toml::to_string(&table).map_err(|e| {
            to_py(PianoError::scenario(
                "",
                format!("cannot be written as a scenario: {e}"),
            ))
        })?;
        // Files it names (a mechanism description, a motion's CSV) are read relative to the
        // working folder.
        let inner = Scenario::from_toml_str_in(&toml_text, std::path::Path::new("."), None)
            .map_err(|e| {
                to_py(match e {
                    // Lines of the TOML made from the dict mean nothing to the caller; those
                    // of a file it names (a motion's CSV) do.
                    PianoError::Input(mut i) if i.file.is_none() => {
                        i.line = None;
                        PianoError::Input(i)
                    }
                    other => other,
                })
            })?;
        return Ok(ScenarioPy { inner, file: None });
    }
    if let Ok(path) = obj.extract::<PathBuf>() {
        return ScenarioPy::load(path);
    }
    Err(to_py(PianoError::scenario(
        "",
        format!(
            "expected a Scenario, a path to a scenario file or a dict, got {}",
            obj.get_type().name()?
        ),
    )))
}

/// A Python value of a scenario dict as TOML (`path` names it in errors): dicts with string
/// keys, lists and tuples, str, bool, int (or anything with `__index__`, such as numpy's
/// integers), float (or anything with `__float__`, such as numpy's floats; NaN and inf are
/// kept for the scenario's checks to name).
fn py_to_toml(obj: &Bound<'_, PyAny>, path: &str) -> PyResult<toml::Value> {
    use pyo3::types::{PyBool, PyFloat, PyInt, PyString, PyTuple};
    let at = |key: &str| {
        if path.is_empty() {
            key.to_string()
        } else {
            format!("{path}.{key}")
        }
    };
    let wrong = |message: String| to_py(PianoError::scenario(path, message));
    if obj.is_none() {
        return Err(wrong(
            "is None: leave the field out for its default".to_string(),
        ));
    }
    if let Ok(b) = obj.cast::<PyBool>() {
        return Ok(toml::Value::Boolean(b.is_true()));
    }
    if let Ok(t) = obj.cast::<PyString>() {
        return Ok(toml::Value::String(t.to_str()?.to_string()));
    }
    if let Ok(d) = obj.cast::<PyDict>() {
        let mut table = toml::Table::new();
        for (k, v) in d.iter() {
            let key: String = k
                .extract()
                .map_err(|_| wrong(format!("has a key that is not a string: {k}")))?;
            let value = py_to_toml(&v, &at(&key))?;
            table.insert(key, value);
        }
        return Ok(toml::Value::Table(table));
    }
    if obj.is_instance_of::<PyList>() || obj.is_instance_of::<PyTuple>() {
        let mut out = Vec::new();
        for (i, v) in obj.try_iter()?.enumerate() {
            out.push(py_to_toml(&v?, &format!("{path}[{i}]"))?);
        }
        return Ok(toml::Value::Array(out));
    }
    if obj.is_instance_of::<PyInt>() || obj.hasattr("__index__")? {
        let i: i64 = obj
            .extract()
            .map_err(|_| wrong(format!("{obj} is out of range")))?;
        return Ok(toml::Value::Integer(i));
    }
    if obj.is_instance_of::<PyFloat>() || obj.hasattr("__float__")? {
        return Ok(toml::Value::Float(obj.extract()?));
    }
    Err(wrong(format!(
        "a {} is not a scenario value (numbers, strings, booleans, lists and dicts are)",
        obj.get_type().name()?
    )))
}

/// The kind of a sweep by its command-line name.
fn sweep_kind(touch: &str) -> PyResult<SweepKind> {
    [SweepKind::Force, SweepKind::Pressed, SweepKind::Struck]
        .into_iter()
        .find(|k| k.name() == touch)
        .ok_or_else(|| {
            option_error(
                "touch",
                format!("unknown '{touch}' (force, pressed or struck)"),
            )
        })
}

/// A model kind by name.
fn model_kind(model: &str) -> PyResult<ModelKind> {
    ModelKind::ALL
        .into_iter()
        .find(|k| k.name() == model)
        .ok_or_else(|| {
            option_error(
                "model",
                format!("unknown model '{model}' (simplified, single or double)"),
            )
        })
}

/// The levels of a sweep, as `piano sweep --touch T --from A --to B --runs N [--linear]`
/// makes them (its defaults for A and B), each checked.
#[pyfunction]
#[pyo3(signature = (touch="struck", start=None, stop=None, runs=100, linear=false))]
fn sweep_levels(
    touch: &str,
    start: Option<f64>,
    stop: Option<f64>,
    runs: usize,
    linear: bool,
) -> PyResult<Vec<f64>> {
    let kind = sweep_kind(touch)?;
    let (lo, hi) = match kind {
        SweepKind::Force => (1.0, 40.0),
        SweepKind::Pressed => (0.7, 50.0),
        SweepKind::Struck => (0.08, 2.0),
    };
    let values = levels(start.unwrap_or(lo), stop.unwrap_or(hi), runs, !linear).map_err(to_py)?;
    check_levels(kind, &values).map_err(to_py)?;
    Ok(values)
}

/// Checks levels given one by one, as `sweep_levels` checks its own: each must make a
/// valid input (a finger speed, a force in range).
#[pyfunction]
fn check_sweep_levels(touch: &str, values: Vec<f64>) -> PyResult<()> {
    check_levels(sweep_kind(touch)?, &values).map_err(to_py)
}

/// Checks a sweep's model name and duration before any run (errors name `model` or
/// `duration_s`).
#[pyfunction]
fn check_sweep(model: &str, duration_s: f64) -> PyResult<()> {
    model_kind(model)?;
    piano_action::simulate::check_duration(duration_s, 1e-3).map_err(to_py)
}

/// The header of a sweep's CSV (`piano sweep`'s).
#[pyfunction]
fn sweep_header() -> &'static str {
    piano_action::sweep::CSV_HEADER
}

/// One keystroke of a sweep: `touch` at `value` for `duration_s` on `model`, as one line
/// of `piano sweep`'s CSV (no newline). A run that fails gives its row with the reason in
/// the `error` column, as the command line does; a wrong argument raises. The GIL is
/// released while it runs.
#[pyfunction]
#[pyo3(signature = (touch, value, duration_s=0.3, model="double", params=None))]
fn sweep_row(
    py: Python<'_>,
    touch: &str,
    value: f64,
    duration_s: f64,
    model: &str,
    params: Option<Params>,
) -> PyResult<String> {
    let kind = sweep_kind(touch)?;
    let model = model_kind(model)?;
    piano_action::simulate::check_duration(duration_s, 1e-3).map_err(to_py)?;
    check_levels(kind, &[value]).map_err(to_py)?;
    let params = params_or_reference(params.as_ref());
    let row = detach_interruptible(py, || SweepRow {
        value,
        run: simulate_input(&params, model, &kind.input(value), duration_s, 1e-3)
            .map_err(|e| e.to_string()),
    });
    let text = csv(kind, &[row]);
    Ok(text.lines().nth(1).map(str::to_string).unwrap_or_default())
}

/// The row of a run that failed for `reason` (a task a cluster lost), as `piano sweep`
/// writes a failed run: the level, then empty cells, then the reason.
#[pyfunction]
fn sweep_failed_row(touch: &str, value: f64, reason: &str) -> PyResult<String> {
    let kind = sweep_kind(touch)?;
    let row = SweepRow {
        value,
        run: Err(reason.to_string()),
    };
    Ok(csv(kind, &[row])
        .lines()
        .nth(1)
        .map(str::to_string)
        .unwrap_or_default())
}

/// A number as the command line writes it in its CSV files (the shortest text that reads
/// back to the same bits).
#[pyfunction]
fn format_number(value: f64) -> String {
    format!("{value}")
}

/// The static touchweight of `model` with `params` (a dict in grams-force: down, up,
/// balance and friction weight), as `piano touchweight --json` prints it. The GIL is
/// released while it runs.
#[pyfunction]
#[pyo3(signature = (params=None, model="double"))]
fn touchweight<'py>(
    py: Python<'py>,
    params: Option<Params>,
    model: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let kind = model_kind(model)?;
    let params = params_or_reference(params.as_ref());
    let w = detach_interruptible(py, || piano_action::touchweight::measure(&params, kind))
        .map_err(to_py)?;
    json_to_py(py, &w.to_json())
}

/// Regulates `model` as `piano regulate` does (punching, capstan, let-off button, drop
/// screw, backcheck, rest rail, into the literature's bands): the dict `piano regulate
/// --json` prints, with the regulated parameters under `"params"` (a `Params`). The GIL is
/// released while it runs.
#[pyfunction]
#[pyo3(signature = (params=None, model="double"))]
fn regulate<'py>(
    py: Python<'py>,
    params: Option<Params>,
    model: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let kind = model_kind(model)?;
    let base = params_or_reference(params.as_ref());
    let done = detach_interruptible(py, || {
        piano_action::regulation::regulate(
            &base,
            kind,
            &piano_action::regulation::Targets::default(),
        )
    })
    .map_err(to_py)?;
    let out = json_to_py(py, &done.to_json(kind).map_err(to_py)?)?;
    let regulated = Params {
        inner: done.params,
        file: None,
        text: None,
    };
    out.set_item("params", Py::new(py, regulated)?)?;
    Ok(out)
}

/// Runs the validation experiments against the published measurements, as `piano validate
/// --json` does, and returns its dict (every row: the figure, the band, the source, and
/// whether it holds). The GIL is released while it runs.
#[pyfunction]
#[pyo3(signature = (params=None, model="double"))]
fn validate<'py>(
    py: Python<'py>,
    params: Option<Params>,
    model: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let kind = model_kind(model)?;
    let params = params_or_reference(params.as_ref());
    let v = detach_interruptible(py, || {
        piano_action::validate::validate_with_known(&params, kind)
    })
    .map_err(to_py)?;
    json_to_py(py, &v.to_json())
}

/// Writes a synthetic dataset with a hidden effect, as `piano synth` does: into the folder
/// `out`, its truth into the JSON file `truth` (outside it); neither replaced unless
/// `force`. `experiment` is `pendulum` (releases in degrees above horizontal) or
/// `key_drive` (release heights in mm, `mass_kg` on the key, `markers` tracked). Returns
/// what was written: runs, their length (s) and the camera's fps.
#[pyfunction]
#[pyo3(signature = (out, truth, experiment="pendulum", effect=None, seed=0, releases_deg=None,
    heights_mm=None, markers=None, mass_kg=1.0, duration_s=None, params=None, force=false))]
#[allow(clippy::too_many_arguments)]
fn synth<'py>(
    py: Python<'py>,
    out: PathBuf,
    truth: PathBuf,
    experiment: &str,
    effect: Option<String>,
    seed: u64,
    releases_deg: Option<Vec<f64>>,
    heights_mm: Option<Vec<f64>>,
    markers: Option<Vec<String>>,
    mass_kg: f64,
    duration_s: Option<f64>,
    params: Option<Params>,
    force: bool,
) -> PyResult<Bound<'py, PyDict>> {
    use piano_action::identify::commands::{SynthRequest, synth_request_to_disk};
    let defaults = SynthRequest::default();
    let request = SynthRequest {
        experiment: experiment.to_string(),
        effect,
        seed,
        releases_deg: releases_deg.unwrap_or(defaults.releases_deg),
        heights_mm: heights_mm.unwrap_or(defaults.heights_mm),
        markers,
        mass_kg,
        duration_s,
    };
    let params = params_or_reference(params.as_ref());
    let done = detach_interruptible(py, || {
        synth_request_to_disk(&params, &request, &out, &truth, force)
    })
    .map_err(to_py)?;
    let d = PyDict::new(py);
    d.set_item("dataset", out.display().to_string())?;
    d.set_item("truth", truth.display().to_string())?;
    d.set_item("runs", done.runs)?;
    d.set_item("duration_s", done.duration_s)?;
    d.set_item("fps", done.fps)?;
    Ok(d)
}

/// Diagnoses the dataset in the folder `dataset` as `piano diagnose` does (the swing test
/// or the key drive, by its `experiment`), writing `report.json`, `report.md` and
/// `report.html` into `out` (refused if it holds an earlier report, unless `force`) and, for
/// a swing test, the corrected parameter file `write_params` if asked. `library` names the
/// effects to try (comma-separated ids; all by default). Returns the paths written and,
/// when `write_params` was asked for but not written, why; the report itself is
/// `report.json` (see `piano_action.diagnose`, which reads it). The corrected parameter
/// file keeps the comments of the file `params` was read from, unless `params` was changed
/// since (by `set`, or a regulation): then it is written from the values. The GIL is
/// released while it runs.
#[pyfunction]
#[pyo3(signature = (dataset, out, params=None, library=None, write_params=None, force=false))]
fn diagnose_to_disk(
    py: Python<'_>,
    dataset: PathBuf,
    out: PathBuf,
    params: Option<Params>,
    library: Option<String>,
    write_params: Option<PathBuf>,
    force: bool,
) -> PyResult<(Vec<String>, Option<String>)> {
    let base = params_or_reference(params.as_ref());
    let source = params.as_ref().map_or(Ok(None), |p| p.source_text())?;
    let source = source.unwrap_or_else(|| piano_action::params::DEFAULT_PARAMS_TOML.to_string());
    let done = detach_interruptible(py, || {
        piano_action::identify::commands::diagnose_dataset_to_disk(
            &base,
            &source,
            &dataset,
            library.as_deref(),
            &out,
            write_params.as_deref(),
            force,
            &|_: &str, _: f64| {},
        )
    })
    .map_err(to_py)?;
    let refused = match &done {
        piano_action::identify::commands::Diagnosed::Pendulum(o) => o.params_refused.clone(),
        piano_action::identify::commands::Diagnosed::KeyDrive(..) => None,
    };
    let written = done
        .written()
        .iter()
        .map(|p| p.display().to_string())
        .collect();
    Ok((written, refused))
}

/// The extension module.
#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add(
        "PanicException",
        m.py().get_type::<pyo3::panic::PanicException>(),
    )?;
    m.add_class::<Params>()?;
    m.add_class::<ScenarioPy>()?;
    m.add_class::<RunPy>()?;
    m.add_class::<Event>()?;
    m.add_class::<Strike>()?;
    m.add_class::<MechanismPy>()?;
    m.add_class::<MechanismRunPy>()?;
    m.add_class::<SwingPy>()?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(sweep_levels, m)?)?;
    m.add_function(wrap_pyfunction!(sweep_row, m)?)?;
    m.add_function(wrap_pyfunction!(sweep_header, m)?)?;
    m.add_function(wrap_pyfunction!(check_sweep_levels, m)?)?;
    m.add_function(wrap_pyfunction!(check_sweep, m)?)?;
    m.add_function(wrap_pyfunction!(sweep_failed_row, m)?)?;
    m.add_function(wrap_pyfunction!(format_number, m)?)?;
    m.add_function(wrap_pyfunction!(touchweight, m)?)?;
    m.add_function(wrap_pyfunction!(regulate, m)?)?;
    m.add_function(wrap_pyfunction!(validate, m)?)?;
    m.add_function(wrap_pyfunction!(synth, m)?)?;
    m.add_function(wrap_pyfunction!(diagnose_to_disk, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
