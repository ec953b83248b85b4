//! A way for whoever runs a solve (a Python session, a GUI) to stop it: a check that the
//! driver asks every few hundred steps whether to stop. Per thread, so that solves on other
//! threads are not affected.

use std::cell::Cell;

thread_local! {
    static CHECK: Cell<Option<fn() -> bool>> = const { Cell::new(None) };
}

/// How many steps (accepted or not) pass between two checks: a check may cost microseconds
/// (a Python binding takes the GIL to look at its signals), a step about ten.
pub(crate) const EVERY: usize = 256;

/// Runs `f` with `check` asked, every [`EVERY`] steps of any solve `f` makes on this thread,
/// whether to stop; when it says so, the solve ends with [`crate::IntegratorError::Interrupted`].
/// The check in place before is restored afterwards, also if `f` panics.
pub fn with_interrupt_check<T>(check: fn() -> bool, f: impl FnOnce() -> T) -> T {
    struct Restore(Option<fn() -> bool>);
    impl Drop for Restore {
        fn drop(&mut self) {
            CHECK.with(|c| c.set(self.0));
        }
    }
    let _restore = Restore(CHECK.with(|c| c.replace(Some(check))));
    f()
}

/// Whether the check in place (if any) asks to stop.
pub(crate) fn interrupted() -> bool {
    CHECK.with(|c| c.get()).is_some_and(|check| check())
}
