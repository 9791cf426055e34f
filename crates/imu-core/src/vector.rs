//! Frame-tagged 3-vectors.
use core::marker::PhantomData;
use core::ops::{Add, AddAssign, Mul, Neg, Sub};

use nalgebra::Vector3;

use crate::frame::Frame;

/// A 3-vector resolved along the axes of frame `F`, SI units implied by its use.
///
/// Adding a body-frame vector to a navigation-frame vector does not compile:
///
/// ```compile_fail
/// use imu_core::{Body, Enu, Vec3};
/// let _ = Vec3::<Body>::new(1.0, 0.0, 0.0) + Vec3::<Enu>::new(0.0, 1.0, 0.0);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vec3<F> {
    xyz: Vector3<f64>,
    frame: PhantomData<F>,
}

impl<F: Frame> Default for Vec3<F> {
    fn default() -> Self {
        Self::zeros()
    }
}

impl<F: Frame> Vec3<F> {
    /// A vector from its components along the axes of `F`.
    #[must_use]
    pub const fn new(x: f64, y: f64, z: f64) -> Self {
        Self {
            xyz: Vector3::new(x, y, z),
            frame: PhantomData,
        }
    }
    /// The zero vector.
    #[must_use]
    pub const fn zeros() -> Self {
        Self::new(0.0, 0.0, 0.0)
    }
    /// From `[x, y, z]`.
    #[must_use]
    pub const fn from_array(a: [f64; 3]) -> Self {
        Self::new(a[0], a[1], a[2])
    }
    /// Wraps an nalgebra vector known to be resolved in `F`.
    #[must_use]
    pub const fn from_nalgebra(xyz: Vector3<f64>) -> Self {
        Self {
            xyz,
            frame: PhantomData,
        }
    }
    /// `[x, y, z]`.
    #[must_use]
    pub fn to_array(self) -> [f64; 3] {
        [self.xyz.x, self.xyz.y, self.xyz.z]
    }
    /// The underlying nalgebra vector (frame tag dropped).
    #[must_use]
    pub fn as_nalgebra(&self) -> &Vector3<f64> {
        &self.xyz
    }
    /// x component.
    #[must_use]
    pub fn x(&self) -> f64 {
        self.xyz.x
    }
    /// y component.
    #[must_use]
    pub fn y(&self) -> f64 {
        self.xyz.y
    }
    /// z component.
    #[must_use]
    pub fn z(&self) -> f64 {
        self.xyz.z
    }
    /// Cross product `self × other` (both in `F`).
    #[must_use]
    pub fn cross(&self, other: &Self) -> Self {
        Self::from_nalgebra(self.xyz.cross(&other.xyz))
    }
    /// Dot product.
    #[must_use]
    pub fn dot(&self, other: &Self) -> f64 {
        self.xyz.dot(&other.xyz)
    }
    /// Euclidean norm.
    #[must_use]
    pub fn norm(&self) -> f64 {
        self.xyz.norm()
    }
    /// True when every component is finite.
    #[must_use]
    pub fn is_finite(&self) -> bool {
        self.xyz.iter().all(|c| c.is_finite())
    }
}

impl<F: Frame> Add for Vec3<F> {
    type Output = Self;
    fn add(self, rhs: Self) -> Self {
        Self::from_nalgebra(self.xyz + rhs.xyz)
    }
}
impl<F: Frame> AddAssign for Vec3<F> {
    fn add_assign(&mut self, rhs: Self) {
        self.xyz += rhs.xyz;
    }
}
impl<F: Frame> Sub for Vec3<F> {
    type Output = Self;
    fn sub(self, rhs: Self) -> Self {
        Self::from_nalgebra(self.xyz - rhs.xyz)
    }
}
impl<F: Frame> Neg for Vec3<F> {
    type Output = Self;
    fn neg(self) -> Self {
        Self::from_nalgebra(-self.xyz)
    }
}
impl<F: Frame> Mul<f64> for Vec3<F> {
    type Output = Self;
    fn mul(self, k: f64) -> Self {
        Self::from_nalgebra(self.xyz * k)
    }
}
