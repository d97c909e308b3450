//! Plane vector helpers (`[x, y]` arrays), the one place the models take them from.

/// Dot product.
#[inline]
pub fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

/// `(a x b)_z`.
#[inline]
pub fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// `z x a` (a turned by +90 degrees).
#[inline]
pub fn perp(a: [f64; 2]) -> [f64; 2] {
    [-a[1], a[0]]
}

/// `a` turned by `angle` \[rad\].
#[inline]
pub fn rotate(angle: f64, a: [f64; 2]) -> [f64; 2] {
    let (s, c) = angle.sin_cos();
    [c * a[0] - s * a[1], s * a[0] + c * a[1]]
}

/// `a + b`.
#[inline]
pub fn add(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] + b[0], a[1] + b[1]]
}

/// `a - b`.
#[inline]
pub fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

/// `s a`.
#[inline]
pub fn scaled(s: f64, a: [f64; 2]) -> [f64; 2] {
    [s * a[0], s * a[1]]
}
