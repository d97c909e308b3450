//! Helpers shared by the unit tests.

/// `a` and `b` agree to the relative tolerance `rel` of the larger magnitude.
pub(crate) fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs())
}
