//! The backend conformance suite, run on every backend of this build.

conformance_suite!(
    bvh,
    rest_embree::accel::backend_by_name("bvh").unwrap(),
    Tolerance {
        t_rel: 1e-9,
        mismatch: 0.0
    }
);

// The same tree with f32 nodes: leaves are opened conservatively, so hits are the f64 BVH's.
conformance_suite!(
    bvh_f32,
    rest_embree::accel::backend_by_name("bvh-f32").unwrap(),
    Tolerance {
        t_rel: 1e-9,
        mismatch: 0.0
    }
);

// Embree intersects in f32 (about each group's centre) and the hit is refined in f64 on the
// primitive it found, so t is as exact as the BVH's; grazing rays may still disagree.
#[cfg(feature = "embree")]
conformance_suite!(
    embree,
    rest_embree::accel::backend_by_name("embree").unwrap(),
    Tolerance {
        t_rel: 1e-9,
        mismatch: 0.002
    }
);

// The same with 8-wide packets (Embree's own choice on CPUs without 16-wide support): its
// callbacks see eight lanes (lane_cull.rs has a path of its own for them).
#[cfg(feature = "embree")]
conformance_suite!(
    embree_8,
    rest_embree::accel::backend_by_name("embree-8").unwrap(),
    Tolerance {
        t_rel: 1e-9,
        mismatch: 0.002
    }
);

// And 4-wide (SSE's native width): lane_cull.rs culls four lanes at once.
#[cfg(feature = "embree")]
conformance_suite!(
    embree_4,
    rest_embree::accel::backend_by_name("embree-4").unwrap(),
    Tolerance {
        t_rel: 1e-9,
        mismatch: 0.002
    }
);
