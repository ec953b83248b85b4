//! The last few simulations of a fit, kept so that an evaluation that needs one again
//! reuses it: a Jacobian column that moves only a run's camera clock films the point's
//! simulation again instead of running it, and one that moves one run's release height
//! reuses the other runs'. A simulation is deterministic, so what is reused is what would
//! be computed, bit for bit.

use std::sync::{Arc, Mutex};

/// What tells two simulations apart: the run's index and the bits of every value the
/// simulation depends on.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(super) struct RecentKey {
    run: usize,
    bits: Vec<u64>,
}

impl RecentKey {
    /// The key of run `run` simulated with `values`, compared bit for bit.
    pub(super) fn new<'a>(run: usize, values: impl IntoIterator<Item = &'a f64>) -> Self {
        Self {
            run,
            bits: values.into_iter().map(|v| v.to_bits()).collect(),
        }
    }
}

/// The last `capacity` results, the most recently used kept longest. Shared by the
/// threads of a fit's Jacobian.
pub(super) struct Recent<T> {
    capacity: usize,
    /// The most recently used last.
    entries: Mutex<Vec<(RecentKey, Arc<T>)>>,
}

impl<T> Recent<T> {
    /// Keeps the last `capacity` results (none at 0).
    pub(super) fn new(capacity: usize) -> Self {
        Self {
            capacity,
            entries: Mutex::new(Vec::with_capacity(capacity)),
        }
    }

    /// The result kept under `key`, if any.
    pub(super) fn get(&self, key: &RecentKey) -> Option<Arc<T>> {
        let mut entries = self.entries.lock().ok()?;
        let i = entries.iter().position(|(k, _)| k == key)?;
        let entry = entries.remove(i);
        let value = entry.1.clone();
        entries.push(entry);
        Some(value)
    }

    /// Keeps `value` under `key`, forgetting the least recently used beyond the capacity.
    pub(super) fn put(&self, key: RecentKey, value: Arc<T>) {
        if self.capacity == 0 {
            return;
        }
        if let Ok(mut entries) = self.entries.lock() {
            if entries.len() >= self.capacity {
                entries.remove(0);
            }
            entries.push((key, value));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_least_recently_used_is_forgotten_first() {
        let recent = Recent::new(2);
        let key = |run: usize, v: f64| RecentKey::new(run, &[v]);
        recent.put(key(0, 1.0), Arc::new("a"));
        recent.put(key(0, 2.0), Arc::new("b"));
        // Using `a` makes `b` the oldest.
        assert_eq!(recent.get(&key(0, 1.0)).as_deref(), Some(&"a"));
        recent.put(key(1, 1.0), Arc::new("c"));
        assert!(recent.get(&key(0, 2.0)).is_none());
        assert_eq!(recent.get(&key(0, 1.0)).as_deref(), Some(&"a"));
        assert_eq!(recent.get(&key(1, 1.0)).as_deref(), Some(&"c"));
        // Bit for bit: −0 is not 0.
        assert!(recent.get(&key(1, -0.0)).is_none());
        let none = Recent::new(0);
        none.put(key(0, 1.0), Arc::new("a"));
        assert!(none.get(&key(0, 1.0)).is_none());
    }
}
