//! Dense LU factorisation with partial pivoting, in place and without allocation after
//! creation (the iteration matrices of the implicit method are small: n ≈ 10–100).

/// An n × n LU factorisation `P A = L U` stored in one buffer (column-major).
#[derive(Clone, Debug)]
pub(crate) struct Lu {
    n: usize,
    a: Vec<f64>,
    piv: Vec<usize>,
    /// Whether column k of L (below the diagonal) has a non-zero entry.
    l_used: Vec<bool>,
    /// Whether column k of U (above the diagonal) has a non-zero entry.
    u_used: Vec<bool>,
}

impl Lu {
    pub fn new(n: usize) -> Self {
        Self {
            n,
            a: vec![0.0; n * n],
            piv: vec![0; n],
            l_used: vec![true; n],
            u_used: vec![true; n],
        }
    }

    /// Factors `I − c J` (J column-major, n × n). Returns false when singular.
    pub fn factor_shifted(&mut self, c: f64, jac: &[f64]) -> bool {
        let n = self.n;
        for (dst, src) in self.a.iter_mut().zip(jac) {
            *dst = -c * src;
        }
        for i in 0..n {
            self.a[i + n * i] += 1.0;
        }
        self.factor()
    }

    fn factor(&mut self) -> bool {
        let n = self.n;
        let a = &mut self.a;
        for k in 0..n {
            // Pivot: largest magnitude in column k at or below the diagonal.
            let mut p = k;
            let mut best = a[k + n * k].abs();
            for i in k + 1..n {
                let v = a[i + n * k].abs();
                if v > best {
                    best = v;
                    p = i;
                }
            }
            self.piv[k] = p;
            if best == 0.0 || !best.is_finite() {
                return false;
            }
            if p != k {
                for j in 0..n {
                    a.swap(k + n * j, p + n * j);
                }
            }
            let inv = 1.0 / a[k + n * k];
            for i in k + 1..n {
                a[i + n * k] *= inv;
            }
            // Rows and columns that are those of the identity (states the Jacobian leaves
            // out) cost no elimination: zero multipliers are skipped.
            self.l_used[k] = a[k + 1 + n * k..n + n * k].iter().any(|v| *v != 0.0);
            if self.l_used[k] {
                for j in k + 1..n {
                    let akj = a[k + n * j];
                    if akj != 0.0 {
                        for i in k + 1..n {
                            a[i + n * j] -= a[i + n * k] * akj;
                        }
                    }
                }
            }
        }
        for k in 0..n {
            self.u_used[k] = a[n * k..k + n * k].iter().any(|v| *v != 0.0);
        }
        true
    }

    /// Solves `A x = b` in place.
    pub fn solve(&self, b: &mut [f64]) {
        let n = self.n;
        let a = &self.a;
        for k in 0..n {
            b.swap(k, self.piv[k]);
        }
        for k in 0..n {
            let bk = b[k];
            if self.l_used[k] && bk != 0.0 {
                for i in k + 1..n {
                    b[i] -= a[i + n * k] * bk;
                }
            }
        }
        for k in (0..n).rev() {
            b[k] /= a[k + n * k];
            let bk = b[k];
            if self.u_used[k] && bk != 0.0 {
                for i in 0..k {
                    b[i] -= a[i + n * k] * bk;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_a_shifted_system_with_pivoting() {
        // J chosen so I − c J needs a row swap.
        let n = 3;
        let jac = [1.0, 2.0, 0.5, -1.0, 0.0, 3.0, 4.0, 1.0, -2.0]; // column-major
        let c = 1.0;
        let mut lu = Lu::new(n);
        assert!(lu.factor_shifted(c, &jac));
        let x = [0.3, -1.2, 2.0];
        // b = (I − c J) x
        let mut b = [0.0; 3];
        for i in 0..n {
            b[i] = x[i];
            for j in 0..n {
                b[i] -= c * jac[i + n * j] * x[j];
            }
        }
        lu.solve(&mut b);
        for i in 0..n {
            assert!((b[i] - x[i]).abs() < 1e-14, "{b:?}");
        }
        // Singular: I − J with J = I.
        let eye = [1.0, 0.0, 0.0, 1.0];
        assert!(!Lu::new(2).factor_shifted(1.0, &eye));
    }
}
