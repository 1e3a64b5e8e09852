//! Special-relativistic kinematics in f64: events, velocities stored by rapidity, Lorentz boosts
//! in any direction, past-directed null rays and the Doppler factor.
//!
//! Conventions (docs/physics.md §0): c = 1; a boost `Boost::to_rest(v)` is the passive
//! transformation from the world frame W into the frame that moves at `v` relative to W.

mod boost;
mod event;
mod hyperbola;
mod null_ray;
mod pinhole;
mod retarded;
mod velocity;
mod wigner;
mod window;

pub use boost::Boost;
pub use event::Event;
pub use hyperbola::{cosh_m1, Hyperbola};
pub use null_ray::NullRay;
pub use pinhole::Pinhole;
pub use retarded::{retarded_delay, retarded_position};
pub use velocity::{Velocity, VelocityError};
pub use wigner::wigner_rotation;
pub use window::{Slice, Window};
