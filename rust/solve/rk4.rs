//! Classical fixed-step fourth-order Runge-Kutta on `(q, v, work)`.

use crate::error::Result;
use crate::solve::system::{MechanicalSystem, State};

/// Reusable stage storage for RK4.
#[derive(Debug, Default)]
pub struct Rk4 {
    kq: [Vec<f64>; 4],
    kv: [Vec<f64>; 4],
    kw: [[f64; 3]; 4],
    q: Vec<f64>,
    v: Vec<f64>,
}

impl Rk4 {
    /// Advance `st` by `h` [s].
    #[allow(clippy::needless_range_loop)]
    pub fn step<S: MechanicalSystem>(&mut self, sys: &S, st: &mut State, h: f64) -> Result<()> {
        let n = st.q.len();
        for k in 0..4 {
            self.kq[k].resize(n, 0.0);
            self.kv[k].resize(n, 0.0);
        }
        self.q.resize(n, 0.0);
        self.v.resize(n, 0.0);
        let c = [0.0, 0.5, 0.5, 1.0];
        for s in 0..4 {
            if s == 0 {
                // First stage = the state's own evaluation (kept from the previous step).
                self.kq[0].copy_from_slice(&st.v);
                self.kv[0].copy_from_slice(&st.a);
                self.kw[0] = st.power;
                continue;
            }
            for i in 0..n {
                self.q[i] = st.q[i] + c[s] * h * self.kq[s - 1][i];
                self.v[i] = st.v[i] + c[s] * h * self.kv[s - 1][i];
            }
            self.kq[s].copy_from_slice(&self.v);
            let (kv, kw) = (&mut self.kv[s], &mut self.kw[s]);
            sys.eval(st.t + c[s] * h, &self.q, &self.v, kv, kw)?;
        }
        for i in 0..n {
            st.q[i] += h / 6.0
                * (self.kq[0][i] + 2.0 * self.kq[1][i] + 2.0 * self.kq[2][i] + self.kq[3][i]);
            st.v[i] += h / 6.0
                * (self.kv[0][i] + 2.0 * self.kv[1][i] + 2.0 * self.kv[2][i] + self.kv[3][i]);
        }
        for j in 0..3 {
            st.work[j] += h / 6.0
                * (self.kw[0][j] + 2.0 * self.kw[1][j] + 2.0 * self.kw[2][j] + self.kw[3][j]);
        }
        st.t += h;
        sys.eval(st.t, &st.q, &st.v, &mut st.a, &mut st.power)?;
        Ok(())
    }
}
