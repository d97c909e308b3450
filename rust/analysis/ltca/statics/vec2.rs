//! Small helpers on plane vectors `[x, y]` and `(cos, sin)` pairs.

#[inline]
pub(super) fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}
#[inline]
pub(super) fn perp(a: [f64; 2]) -> [f64; 2] {
    [-a[1], a[0]]
}
#[inline]
pub(super) fn rotate(cs: [f64; 2], a: [f64; 2]) -> [f64; 2] {
    [cs[0] * a[0] - cs[1] * a[1], cs[1] * a[0] + cs[0] * a[1]]
}
#[inline]
pub(super) fn cos_sin(a: f64) -> [f64; 2] {
    let (s, c) = a.sin_cos();
    [c, s]
}
