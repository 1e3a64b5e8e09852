//! The Thomas-Wigner rotation of two boosts that are not along one line (docs/physics.md §1.4):
//! boosting by β1 and then, in the frame reached, by β2 is the boost by β1 ⊕ β2 followed by a
//! turn of the axes by ω about β1 × β2.

use super::Velocity;
use glam::{DMat3, DVec3};

/// The rotation R with Λ(β2) Λ(β1) = R Λ(β1 ⊕ β2), β2 measured in the frame moving at β1 (as
/// passive maps; `Boost::to_rest(v2)` after `Boost::to_rest(v1)` is
/// `Boost::to_rest(v1 ⊕ v2).turned(R)`). With t_i = tanh(θ_i/2) of the rapidities and φ the
/// angle between the directions, tan(ω/2) = t1 t2 sin φ / (1 + t1 t2 cos φ): no cancellation
/// but in the denominator when both speeds near c and the directions near opposite (there
/// 1 − t1 t2 loses digits), exact for small and for most ultra-relativistic speeds.
pub fn wigner_rotation(v1: &Velocity, v2: &Velocity) -> DMat3 {
    if v1.is_zero() || v2.is_zero() {
        return DMat3::IDENTITY;
    }
    let (n1, n2) = (v1.direction(), v2.direction());
    let cross = n1.cross(n2);
    let sin_phi = cross.length();
    if sin_phi == 0.0 {
        return DMat3::IDENTITY;
    }
    let k = (0.5 * v1.rapidity()).tanh() * (0.5 * v2.rapidity()).tanh();
    let half = (k * sin_phi).atan2(1.0 + k * n1.dot(n2));
    let axis: DVec3 = cross / sin_phi;
    DMat3::from_axis_angle(axis, 2.0 * half)
}
