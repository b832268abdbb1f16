//! What a batch accumulates: any quantity that can be summed and scaled.

/// A quantity a batch can average: radiance as a scalar, an RGB triple, or a `glam::Vec3`.
pub trait Value: Copy {
    /// The additive identity.
    fn zero() -> Self;
    /// `self + other`.
    fn add(self, other: Self) -> Self;
    /// `self * factor`.
    fn scale(self, factor: f64) -> Self;
}

impl Value for f32 {
    fn zero() -> Self {
        0.0
    }
    fn add(self, other: Self) -> Self {
        self + other
    }
    fn scale(self, factor: f64) -> Self {
        (self as f64 * factor) as f32
    }
}

impl Value for f64 {
    fn zero() -> Self {
        0.0
    }
    fn add(self, other: Self) -> Self {
        self + other
    }
    fn scale(self, factor: f64) -> Self {
        self * factor
    }
}

impl<const N: usize> Value for [f32; N] {
    fn zero() -> Self {
        [0.0; N]
    }
    fn add(self, other: Self) -> Self {
        std::array::from_fn(|i| self[i] + other[i])
    }
    fn scale(self, factor: f64) -> Self {
        self.map(|x| (x as f64 * factor) as f32)
    }
}

impl<const N: usize> Value for [f64; N] {
    fn zero() -> Self {
        [0.0; N]
    }
    fn add(self, other: Self) -> Self {
        std::array::from_fn(|i| self[i] + other[i])
    }
    fn scale(self, factor: f64) -> Self {
        self.map(|x| x * factor)
    }
}

impl Value for glam::Vec3 {
    fn zero() -> Self {
        glam::Vec3::ZERO
    }
    fn add(self, other: Self) -> Self {
        self + other
    }
    fn scale(self, factor: f64) -> Self {
        self * factor as f32
    }
}
