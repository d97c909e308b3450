//! The dense matrix of the statics' forces and tangents.

/// A dense symmetric-by-construction matrix of size `n` (row-major).
#[derive(Debug, Clone, Default)]
pub struct Dense {
    /// Size.
    pub n: usize,
    /// Entries, row-major.
    pub a: Vec<f64>,
}

impl Dense {
    /// The zero matrix of size `n`.
    pub fn zeros(n: usize) -> Self {
        Self {
            n,
            a: vec![0.0; n * n],
        }
    }
    /// Entry `(i, j)`.
    #[inline]
    pub fn at(&self, i: usize, j: usize) -> f64 {
        self.a[i * self.n + j]
    }
    /// Add `v` to entry `(i, j)`.
    #[inline]
    pub fn add(&mut self, i: usize, j: usize, v: f64) {
        self.a[i * self.n + j] += v;
    }
    /// Set every entry to `v`.
    pub fn fill(&mut self, v: f64) {
        self.a.fill(v);
    }
    /// Add `w u u^T` on the index set `idx` (`u` given on `idx`).
    #[inline]
    pub(super) fn outer(&mut self, idx: &[usize], u: &[f64], w: f64) {
        for (a, &i) in idx.iter().enumerate() {
            let wa = w * u[a];
            for (b, &j) in idx.iter().enumerate() {
                self.a[i * self.n + j] += wa * u[b];
            }
        }
    }
    /// Add `w (u v^T + v u^T)` on the index set `idx` (`u`, `v` given on `idx`).
    #[inline]
    pub(super) fn outer_sym(&mut self, idx: &[usize], u: &[f64], v: &[f64], w: f64) {
        for (a, &i) in idx.iter().enumerate() {
            for (b, &j) in idx.iter().enumerate() {
                self.a[i * self.n + j] += w * (u[a] * v[b] + v[a] * u[b]);
            }
        }
    }
    /// Replace each entry `v` of the 3x3 block at rows and columns `i0..i0 + 3` by
    /// `upd(a, b, v)` (`a`, `b` in `0..3`).
    #[inline]
    pub(super) fn update_block3(&mut self, i0: usize, upd: impl Fn(usize, usize, f64) -> f64) {
        let n = self.n;
        for a in 0..3 {
            let start = (i0 + a) * n + i0;
            for (b, v) in self.a[start..start + 3].iter_mut().enumerate() {
                *v = upd(a, b, *v);
            }
        }
    }
    /// Add `v` to the symmetric pair `(i, j)`, `(j, i)` (once on the diagonal).
    #[inline]
    pub(super) fn sym(&mut self, i: usize, j: usize, v: f64) {
        self.add(i, j, v);
        if i != j {
            self.add(j, i, v);
        }
    }
}
