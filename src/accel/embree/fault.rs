//! What can go wrong inside Embree's callbacks, where nothing can be returned and no panic may
//! unwind (into Embree's C++ it would abort the process): each callback's body runs in
//! `guarded`, which catches a panic and records it as the query's `Fault`; the query hands it
//! to the backend's `Faults`, which the render checks. And the test hook that makes a callback
//! panic on purpose (`Injection`), to prove it.

use std::cell::Cell;
use std::sync::atomic::{AtomicU8, Ordering};

/// The callbacks of the backend's user geometry.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Callback {
    /// Closest hits of the exact primitives (spheres, rods, boxes).
    Intersect,
    /// Occlusion by the exact primitives.
    Occluded,
    /// Closest hits of an instanced block's members.
    BlockIntersect,
    /// Occlusion by an instanced block's members.
    BlockOccluded,
    /// The culler's offer of a group's box to the renderer's exact test.
    Cull,
}

impl Callback {
    #[cfg(test)]
    pub const ALL: [Callback; 5] = [
        Callback::Intersect,
        Callback::Occluded,
        Callback::BlockIntersect,
        Callback::BlockOccluded,
        Callback::Cull,
    ];

    /// Its name in messages.
    pub fn name(self) -> &'static str {
        match self {
            Callback::Intersect => "closest-hit",
            Callback::Occluded => "occlusion",
            Callback::BlockIntersect => "instanced block closest-hit",
            Callback::BlockOccluded => "instanced block occlusion",
            Callback::Cull => "culling",
        }
    }

    fn code(self) -> u8 {
        self as u8 + 1
    }
}

/// What went wrong inside a query's callbacks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fault {
    None,
    /// A panic in that callback, caught before it could unwind into Embree.
    Panicked(Callback),
    /// Embree called back with a ray whose id names no ray of the query.
    StrayRay,
}

impl Fault {
    /// What it means, for the render's error.
    pub fn message(self) -> String {
        match self {
            Fault::None => "no fault".to_string(),
            Fault::Panicked(c) => format!(
                "Embree's {} callback panicked while tracing rays (the panic was caught; its message is above)",
                c.name()
            ),
            Fault::StrayRay => {
                "Embree called back with a ray that is not one of the query's".to_string()
            }
        }
    }
}

/// The test hook of `EmbreeBackend::with_fault_injected`: armed, the next run of the named
/// callback (or of any, `REST_EMBREE_FAULT=callback`) panics, once, so the log shows one panic.
#[derive(Debug, Default)]
pub struct Injection(AtomicU8);

const ANY: u8 = u8::MAX;

impl Injection {
    /// Arm it for `callback` (None: whichever runs first).
    pub fn arm(&self, callback: Option<Callback>) {
        self.0
            .store(callback.map_or(ANY, Callback::code), Ordering::Relaxed);
    }

    /// Whether it is armed (a query takes it along only then).
    pub fn armed(&self) -> bool {
        self.0.load(Ordering::Relaxed) != 0
    }

    /// Whether `callback` is to panic now (disarming it).
    fn fires(&self, callback: Callback) -> bool {
        let armed = self.0.load(Ordering::Relaxed);
        (armed == ANY || armed == callback.code())
            && self
                .0
                .compare_exchange(armed, 0, Ordering::Relaxed, Ordering::Relaxed)
                .is_ok()
    }
}

/// Run a callback's body: a panic is caught here and recorded in `fault`. Once the query has
/// a fault the body is skipped: a bug that panics every time shows its message once a query.
#[inline(always)]
pub(crate) fn guarded(
    callback: Callback,
    fault: &Cell<Fault>,
    inject: Option<&Injection>,
    body: impl FnOnce(),
) {
    if fault.get() != Fault::None {
        return;
    }
    let run = || {
        if inject.is_some_and(|i| i.fires(callback)) {
            panic!(
                "a fault injected into Embree's {} callback ({})",
                callback.name(),
                super::FAULT_ENV
            );
        }
        body()
    };
    if std::panic::catch_unwind(std::panic::AssertUnwindSafe(run)).is_err() {
        fault.set(Fault::Panicked(callback));
    }
}
