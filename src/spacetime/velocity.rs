use glam::DVec3;
use std::fmt;

/// A velocity relative to some frame, stored by its unit direction and rapidity φ (docs/physics.md §8):
/// β = tanh φ, γ = cosh φ, γβ = sinh φ, e^{±φ} are all derived in f64 without cancellation, so
/// speeds like 1 − 1e-12 keep full precision when given as rapidity or as 1 − β.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Velocity {
    dir: DVec3,
    rapidity: f64,
}

/// Why a velocity cannot be had.
#[derive(Clone, Debug, PartialEq)]
pub enum VelocityError {
    /// A component is NaN or infinite.
    NotFinite,
    /// The speed (given) is 1 or more.
    NotBelowLight(f64),
    /// A speed, rapidity or 1 − β (named) is negative.
    Negative(&'static str, f64),
    /// The direction given is the zero vector.
    ZeroDirection,
    /// 1 − β (given) is outside (0, 1].
    OneMinusBetaRange(f64),
}

impl fmt::Display for VelocityError {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            VelocityError::NotFinite => write!(f, "the speed must be a finite number"),
            VelocityError::NotBelowLight(b) => write!(
                f,
                "speed {b:?} is not below 1 (the speed of light); for speeds near 1 give `rapidity` or `one_minus_beta` with a `direction`"
            ),
            VelocityError::Negative(what, v) => write!(f, "{what} must not be negative (got {v:?}); reverse `direction` instead"),
            VelocityError::ZeroDirection => write!(f, "`direction` must not be the zero vector"),
            VelocityError::OneMinusBetaRange(e) => {
                write!(f, "one_minus_beta must lie in (0, 1] (got {e:?})")
            }
        }
    }
}

impl Velocity {
    /// At rest.
    pub const ZERO: Velocity = Velocity {
        dir: DVec3::ZERO,
        rapidity: 0.0,
    };

    /// From a β vector (units of c). |β| must be below 1.
    pub fn from_beta_vec(beta: DVec3) -> Result<Self, VelocityError> {
        if !beta.is_finite() {
            return Err(VelocityError::NotFinite);
        }
        let b = beta.length();
        if b >= 1.0 {
            return Err(VelocityError::NotBelowLight(b));
        }
        if b == 0.0 {
            return Ok(Self::ZERO);
        }
        Ok(Self {
            dir: beta / b,
            rapidity: b.atanh(),
        })
    }

    fn unit(direction: DVec3) -> Result<DVec3, VelocityError> {
        if !direction.is_finite() {
            return Err(VelocityError::NotFinite);
        }
        let l = direction.length();
        if l == 0.0 {
            return Err(VelocityError::ZeroDirection);
        }
        Ok(direction / l)
    }

    /// From a direction (any length) and a speed β in [0, 1).
    pub fn from_beta(direction: DVec3, beta: f64) -> Result<Self, VelocityError> {
        if !beta.is_finite() {
            return Err(VelocityError::NotFinite);
        }
        if beta < 0.0 {
            return Err(VelocityError::Negative("beta", beta));
        }
        if beta >= 1.0 {
            return Err(VelocityError::NotBelowLight(beta));
        }
        Self::from_rapidity(direction, beta.atanh())
    }

    /// From a direction and a rapidity φ ≥ 0.
    pub fn from_rapidity(direction: DVec3, rapidity: f64) -> Result<Self, VelocityError> {
        if !rapidity.is_finite() {
            return Err(VelocityError::NotFinite);
        }
        if rapidity < 0.0 {
            return Err(VelocityError::Negative("rapidity", rapidity));
        }
        if rapidity == 0.0 {
            return Ok(Self::ZERO);
        }
        Ok(Self {
            dir: Self::unit(direction)?,
            rapidity,
        })
    }

    /// From a direction and ε = 1 − β in (0, 1]: φ = ½ ln((2 − ε)/ε), exact for tiny ε.
    pub fn from_one_minus_beta(direction: DVec3, eps: f64) -> Result<Self, VelocityError> {
        if !eps.is_finite() {
            return Err(VelocityError::NotFinite);
        }
        if eps <= 0.0 || eps > 1.0 {
            return Err(VelocityError::OneMinusBetaRange(eps));
        }
        let phi = 0.5 * ((2.0 - eps).ln() - eps.ln());
        Self::from_rapidity(direction, phi)
    }

    /// Whether it is at rest.
    pub fn is_zero(&self) -> bool {
        self.rapidity == 0.0
    }
    /// Unit direction (zero for a velocity of zero).
    pub fn direction(&self) -> DVec3 {
        self.dir
    }
    /// The rapidity φ = artanh β.
    pub fn rapidity(&self) -> f64 {
        self.rapidity
    }
    /// The speed β = tanh φ (units of c).
    pub fn beta(&self) -> f64 {
        self.rapidity.tanh()
    }
    /// The velocity β·direction (units of c).
    pub fn beta_vec(&self) -> DVec3 {
        self.dir * self.beta()
    }
    /// The Lorentz factor γ = cosh φ.
    pub fn gamma(&self) -> f64 {
        self.rapidity.cosh()
    }
    /// γβ = sinh φ, exact for speeds near c.
    pub fn gamma_beta(&self) -> f64 {
        self.rapidity.sinh()
    }
    /// γ − 1 = 2 sinh²(φ/2), exact for small speeds.
    pub fn gamma_minus_one(&self) -> f64 {
        let s = (0.5 * self.rapidity).sinh();
        2.0 * s * s
    }
    /// 1 − β = 2 / (e^{2φ} + 1), exact near the speed of light.
    pub fn one_minus_beta(&self) -> f64 {
        2.0 / ((2.0 * self.rapidity).exp() + 1.0)
    }
    /// The same speed in the opposite direction.
    pub fn reversed(&self) -> Velocity {
        Velocity {
            dir: -self.dir,
            rapidity: self.rapidity,
        }
    }
    /// A key equal for velocities that are exactly the same (bitwise on the stored parameters;
    /// every velocity of zero alike): groups with one key share one rest frame.
    pub fn identity_key(&self) -> [u64; 4] {
        if self.is_zero() {
            return [0; 4];
        }
        let d = self.dir;
        [
            d.x.to_bits(),
            d.y.to_bits(),
            d.z.to_bits(),
            self.rapidity.to_bits(),
        ]
    }
}
