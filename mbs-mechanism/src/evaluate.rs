//! Reading a solution through a description: its named events and metrics.

use mbs_integrators::Solution;
use serde::Serialize;

use crate::build::Built;
use crate::description::{ContactPhase, Mechanism, Quantity};
use crate::error::{MechanismError, Result};

/// One occurrence of a named event.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EventOccurrence {
    /// The event's name in the description.
    pub name: String,
    /// When (s).
    pub time_s: f64,
    /// The integrator's record of it: its index in `Solution::events`.
    #[serde(skip)]
    pub record: usize,
}

/// A metric's value.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MetricValue {
    /// The metric's name.
    pub name: String,
    /// Its value, `None` when its event never happened.
    pub value: Option<f64>,
    /// Its unit.
    pub unit: String,
}

fn core(e: mbs_core::CoreError) -> MechanismError {
    MechanismError::caused("", e)
}

impl Mechanism {
    /// The occurrences of the description's named events in `solution` (integrated from
    /// `built`, which this description built), in time order.
    pub fn events_in(&self, built: &Built, solution: &Solution) -> Result<Vec<EventOccurrence>> {
        let mut out = Vec::new();
        for (record, ev) in solution.events.iter().enumerate() {
            let Some(mbs_integrators::EventSource { element, local }) = ev.source else {
                continue;
            };
            for spec in &self.events {
                let hit = match (&spec.contact, spec.on) {
                    (Some(c), Some(phase)) => {
                        if built.contacts.get(c) != Some(&element) || local != 0 {
                            continue;
                        }
                        // A contact's switching function is its gap: falling, the shapes
                        // touch.
                        let onset = ev.direction == mbs_integrators::Crossing::Falling;
                        onset == (phase == ContactPhase::Onset)
                    }
                    _ => built.watches.get(&spec.name) == Some(&element),
                };
                if hit {
                    out.push(EventOccurrence {
                        name: spec.name.clone(),
                        time_s: ev.time,
                        record,
                    });
                }
            }
        }
        out.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
        Ok(out)
    }

    /// The description's metrics, each read at the first occurrence of its event.
    pub fn metrics_in(&self, built: &Built, solution: &Solution) -> Result<Vec<MetricValue>> {
        let events = self.events_in(built, solution)?;
        let system = &built.system;
        let model = system.model();
        let mut out = Vec::new();
        for m in &self.metrics {
            let first = events.iter().find(|e| e.name == m.at);
            let value = match first.and_then(|e| solution.events.get(e.record)) {
                None => None,
                Some(record) => {
                    let (t, state) = (record.time, record.state.as_slice());
                    match (m.quantity, &m.marker) {
                        (Quantity::Time, _) => Some(t),
                        (q, Some(marker)) => {
                            let mk = self.markers.iter().find(|k| &k.name == marker).ok_or_else(
                                || {
                                    MechanismError::field(
                                        "metrics",
                                        format!("no marker '{marker}'"),
                                    )
                                },
                            )?;
                            let (body, point) = if mk.at.body == crate::GROUND {
                                (mbs_core::BodyId::GROUND, mk.at.point)
                            } else {
                                let frame = model.frame_id(&mk.at.body).map_err(core)?;
                                mbs_core::frame_point(model, frame, mk.at.point)
                            };
                            let mut ws = system.workspace();
                            let ctx = system.kinematics(&mut ws, t, state).map_err(core)?;
                            let p = ctx.point_position(body, point);
                            let v = ctx.point_velocity(body, point);
                            Some(match q {
                                Quantity::Speed => v[0].hypot(v[1]),
                                Quantity::X => p[0],
                                Quantity::Y => p[1],
                                Quantity::VelocityX => v[0],
                                Quantity::VelocityY => v[1],
                                Quantity::Time => t,
                            })
                        }
                        (_, None) => None,
                    }
                }
            };
            out.push(MetricValue {
                name: m.name.clone(),
                value,
                unit: m.unit.clone(),
            });
        }
        Ok(out)
    }
}
