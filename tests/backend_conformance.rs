//! The backend conformance suite, run on every backend of this build.

mod common;

conformance_suite!(
    bvh,
    rest_embree::accel::backend_by_name("bvh").unwrap(),
    Tolerance { t_rel: 1e-9, mismatch: 0.0 }
);
