//! Dense LU factorisation with partial pivoting, in place and without allocation after
//! creation (the iteration matrices of the implicit method are small: n ≈ 10–100).

/// An n × n LU factorisation `P A = L U` stored in one buffer (column-major).
#[derive(Clone, Debug)]
pub(crate) struct Lu {
    n: usize,
    a: Vec<f64>,
    piv: Vec<usize>,
}

impl Lu {
    pub fn new(n: usize) -> Self {
        Self {
            n,
            a: vec![0.0; n * n],
            piv: vec![0; n],
        }
    }

    /// The same factorisation for an `n × n` matrix, in the buffers it has (no allocation
    /// up to the size it was made for).
    pub fn resize(&mut self, n: usize) {
        self.n = n;
        self.a.resize(n * n, 0.0);
        self.piv.resize(n, 0);
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
            for j in k + 1..n {
                let akj = a[k + n * j];
                if akj != 0.0 {
                    for i in k + 1..n {
                        a[i + n * j] -= a[i + n * k] * akj;
                    }
                }
            }
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
            for i in k + 1..n {
                b[i] -= a[i + n * k] * bk;
            }
        }
        for k in (0..n).rev() {
            b[k] /= a[k + n * k];
            let bk = b[k];
            for i in 0..k {
                b[i] -= a[i + n * k] * bk;
            }
        }
    }
}

/// The iteration matrix `W = I − c J` of an implicit method, factored with the zero
/// columns of `J` taken out. A state whose column of `J` is zero (the Jacobian leaves it out,
/// or nothing depends on it) has the column `e_j` in `W`; with the others (`A`) first, `W`
/// is block lower triangular,
///
/// ```text
/// [ I − c J_AA   0 ] [x_A]   [b_A]
/// [  − c J_ZA    I ] [x_Z] = [b_Z]
/// ```
///
/// so `x_A` comes from an LU of the `A` block alone and `x_Z = b_Z + c J_ZA x_A`. A
/// string's 100 modal amplitudes then cost a product per solve instead of a 100 × 100
/// elimination per factorisation.
#[derive(Clone, Debug)]
pub(crate) struct IterationMatrix {
    n: usize,
    /// States with a non-zero Jacobian column, in order.
    active: Vec<usize>,
    /// States with a zero Jacobian column.
    passive: Vec<usize>,
    lu: Lu,
    /// The passive states whose row of `J_ZA` is not zero.
    coupled: Vec<usize>,
    /// `c J_ZA`, row-major over the coupled states (`coupled.len() × active.len()`).
    coupling: Vec<f64>,
    /// The active block `J_AA`, column-major, then work space for a solve.
    block: Vec<f64>,
    work: Vec<f64>,
    /// Whether the Jacobian changed since `active` and `coupled` were found.
    stale: bool,
    /// Columns the Jacobian's maker knows to be zero (not searched).
    known_zero: Vec<bool>,
}

impl IterationMatrix {
    pub fn new(n: usize) -> Self {
        Self {
            n,
            active: (0..n).collect(),
            // Room for every split of the states, so that none allocates later.
            passive: Vec::with_capacity(n),
            lu: Lu::new(n),
            coupled: Vec::with_capacity(n),
            coupling: Vec::with_capacity(n * n / 4 + 1),
            block: vec![0.0; n * n],
            work: vec![0.0; n],
            stale: true,
            known_zero: vec![false; n],
        }
    }

    /// Tells the matrix that the Jacobian changed: its zero columns, and the passive
    /// states' coupling rows, are looked for again at the next factorisation. The columns
    /// flagged in `known_zero` (when it is as long as the state) are zero already, as the
    /// Jacobian's maker knows, and are not searched (a string's modal amplitudes: 96 of
    /// its 106 columns).
    pub fn jacobian_changed(&mut self, known_zero: &[bool]) {
        self.stale = true;
        self.known_zero.clear();
        if known_zero.len() == self.n {
            self.known_zero.extend_from_slice(known_zero);
        } else {
            self.known_zero.resize(self.n, false);
        }
    }

    /// Factors `I − c J` (J column-major, n × n). Returns false when singular.
    pub fn factor_shifted(&mut self, c: f64, jac: &[f64]) -> bool {
        let n = self.n;
        if self.stale {
            self.active.clear();
            self.passive.clear();
            for j in 0..n {
                if !self.known_zero[j] && jac[n * j..n * (j + 1)].iter().any(|v| *v != 0.0) {
                    self.active.push(j);
                } else {
                    self.passive.push(j);
                }
            }
            // Only the passive states whose rates depend on active ones need a row: a
            // string's modal amplitudes out of contact have none, and then a solve costs
            // no product. Which they are depends on `J` alone, not on `c`.
            self.coupled.clear();
            for &i in &self.passive {
                if self.active.iter().any(|&j| jac[i + n * j] != 0.0) {
                    self.coupled.push(i);
                }
            }
            self.stale = false;
        }
        let na = self.active.len();
        if self.lu.n != na {
            self.lu.resize(na);
            self.block.resize(na * na, 0.0);
        }
        for (cb, &j) in self.active.iter().enumerate() {
            for (rb, &i) in self.active.iter().enumerate() {
                self.block[rb + na * cb] = jac[i + n * j];
            }
        }
        self.coupling.clear();
        for &i in &self.coupled {
            self.coupling
                .extend(self.active.iter().map(|&j| c * jac[i + n * j]));
        }
        self.lu.factor_shifted(c, &self.block)
    }

    /// The states whose row and column of `W` are the identity's, ascending: outside the
    /// Jacobian, and with a rate that does not depend on the states inside it. Solving
    /// leaves their entries of the right-hand side as they are. Valid after
    /// [`Self::factor_shifted`].
    pub fn identity_rows(&self) -> impl Iterator<Item = usize> + '_ {
        // Both lists ascend (built in index order): walk `coupled` along `passive`.
        let mut coupled = self.coupled.iter().copied().peekable();
        self.passive.iter().copied().filter(move |&i| {
            while coupled.next_if(|&c| c < i).is_some() {}
            coupled.next_if_eq(&i).is_none()
        })
    }

    /// Solves `W x = b` in place.
    pub fn solve(&mut self, b: &mut [f64]) {
        let na = self.active.len();
        self.work.clear();
        self.work.extend(self.active.iter().map(|&i| b[i]));
        self.lu.solve(&mut self.work);
        for (k, &i) in self.active.iter().enumerate() {
            b[i] = self.work[k];
        }
        for (row, &i) in self.coupling.chunks_exact(na.max(1)).zip(&self.coupled) {
            b[i] += row.iter().zip(&self.work).map(|(a, x)| a * x).sum::<f64>();
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

    #[test]
    fn the_zero_columns_of_the_jacobian_are_solved_by_substitution() {
        // States 1 and 3 have zero columns (nothing depends on them) but rates that depend
        // on states 0 and 2: the block solve must agree with a dense solve of I − c J.
        let n = 4;
        let mut jac = vec![0.0; n * n];
        let set = |jac: &mut Vec<f64>, i: usize, j: usize, v: f64| jac[i + n * j] = v;
        set(&mut jac, 0, 0, -3.0);
        set(&mut jac, 2, 0, 1.5);
        set(&mut jac, 0, 2, 2.0);
        set(&mut jac, 2, 2, -0.5);
        set(&mut jac, 1, 0, 4.0);
        set(&mut jac, 3, 2, -7.0);
        set(&mut jac, 1, 2, 0.25);
        let c = 0.3;
        let x = [0.7, -1.1, 2.3, 0.4];
        let mut b = [0.0; 4];
        for i in 0..n {
            b[i] = x[i];
            for j in 0..n {
                b[i] -= c * jac[i + n * j] * x[j];
            }
        }
        let mut w = IterationMatrix::new(n);
        assert!(w.factor_shifted(c, &jac));
        assert_eq!(w.active, vec![0, 2]);
        w.solve(&mut b);
        for i in 0..n {
            assert!((b[i] - x[i]).abs() < 1e-14, "{b:?}");
        }
        assert_eq!(w.coupled, vec![1, 3]);
        // State 3 made independent of the others: its row is dropped, its solution is b.
        set(&mut jac, 3, 2, 0.0);
        w.jacobian_changed(&[]);
        assert!(w.factor_shifted(c, &jac));
        assert_eq!(w.coupled, vec![1]);
        let mut b = [0.7, -1.1, 2.3, 0.4];
        let rhs = b;
        w.solve(&mut b);
        assert_eq!(b[3], rhs[3]);
        let mut back = [0.0; 4];
        for i in 0..n {
            back[i] = b[i];
            for j in 0..n {
                back[i] -= c * jac[i + n * j] * b[j];
            }
        }
        for i in 0..n {
            assert!((back[i] - rhs[i]).abs() < 1e-14, "{back:?}");
        }
        // A full Jacobian again: every state active.
        let full: Vec<f64> = (0..n * n).map(|k| 0.1 * (k as f64 + 1.0)).collect();
        w.jacobian_changed(&[]);
        assert!(w.factor_shifted(c, &full));
        assert_eq!(w.active.len(), n);
    }
}
