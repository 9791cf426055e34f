//! Damped Gauss–Newton (Levenberg–Marquardt) over a fixed number of parameters, on the normal
//! equations summed as the residuals come: nothing is stored per residual, so a fit over a long
//! log needs no heap.
use nalgebra::{SMatrix, SVector};

use crate::math;

/// `JᵀJ`, `Jᵀr` and `rᵀr` of a set of residuals `r` with Jacobian rows `J` (`∂r/∂p`).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Normal<const P: usize> {
    pub jtj: SMatrix<f64, P, P>,
    pub jtr: SVector<f64, P>,
    pub cost: f64,
    pub count: usize,
}

impl<const P: usize> Normal<P> {
    pub fn zero() -> Self {
        Self {
            jtj: SMatrix::zeros(),
            jtr: SVector::zeros(),
            cost: 0.0,
            count: 0,
        }
    }

    /// One residual and its Jacobian row.
    pub fn add(&mut self, r: f64, j: &SVector<f64, P>) {
        self.jtj += j * j.transpose();
        self.jtr += j * r;
        self.cost += r * r;
        self.count += 1;
    }
}

/// The parameters that minimise `rᵀr`, with the normal equations there.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Solution<const P: usize> {
    pub params: SVector<f64, P>,
    pub normal: Normal<P>,
}

impl<const P: usize> Solution<P> {
    /// The covariance of the parameters, `s²(JᵀJ)⁻¹` with `s² = rᵀr/(n − P)` the residuals'
    /// variance (the model's own scatter), or `floor²` when that is larger (a residual's noise
    /// known from elsewhere: with few residuals their scatter is itself uncertain); `None`
    /// without more residuals than parameters or for a singular `JᵀJ`.
    pub fn covariance_at_least(&self, floor: f64) -> Option<SMatrix<f64, P, P>> {
        if self.normal.count <= P {
            return None;
        }
        let s2 = (self.normal.cost / (self.normal.count - P) as f64).max(floor * floor);
        let inverse = self.normal.jtj.try_inverse()?;
        let c = inverse * s2;
        c.iter().all(|v| v.is_finite()).then_some(c)
    }

    /// [`Self::covariance_at_least`] with no floor.
    pub fn covariance(&self) -> Option<SMatrix<f64, P, P>> {
        self.covariance_at_least(0.0)
    }

    /// The standard deviation of each parameter, from [`Self::covariance_at_least`] (zero where
    /// the covariance is not known).
    pub fn sigma(&self, floor: f64) -> SVector<f64, P> {
        self.covariance_at_least(floor)
            .map_or(SVector::zeros(), |c| {
                SVector::from_fn(|i, _| math::sqrt(c[(i, i)].max(0.0)))
            })
    }
}

/// Iterations at most.
const MAX_ITERATIONS: usize = 200;

/// Minimises the sum of squares that `accumulate` forms at given parameters (it returns
/// `false` where the model cannot be evaluated, such as a non-finite residual), from `start`.
/// `None` when the start cannot be evaluated or the equations are singular there.
pub(crate) fn least_squares<const P: usize>(
    start: SVector<f64, P>,
    mut accumulate: impl FnMut(&SVector<f64, P>, &mut Normal<P>) -> bool,
) -> Option<Solution<P>> {
    let evaluate =
        |p: &SVector<f64, P>, f: &mut dyn FnMut(&SVector<f64, P>, &mut Normal<P>) -> bool| {
            let mut n = Normal::zero();
            (f(p, &mut n) && n.cost.is_finite()).then_some(n)
        };
    let mut params = start;
    let mut normal = evaluate(&params, &mut accumulate)?;
    let mut lambda = 1e-3;
    for _ in 0..MAX_ITERATIONS {
        let mut damped = normal.jtj;
        for i in 0..P {
            damped[(i, i)] += lambda * normal.jtj[(i, i)].max(1e-300);
        }
        let Some(step) = damped.cholesky().map(|c| c.solve(&(-normal.jtr))) else {
            lambda *= 10.0;
            if lambda > 1e12 {
                break;
            }
            continue;
        };
        let trial = params + step;
        match evaluate(&trial, &mut accumulate) {
            Some(next) if next.cost <= normal.cost => {
                let small = step.norm() <= 1e-12 * (params.norm() + 1e-12);
                let settled = normal.cost - next.cost <= 1e-15 * normal.cost;
                params = trial;
                normal = next;
                lambda = (lambda / 10.0).max(1e-12);
                if small || settled {
                    break;
                }
            }
            _ => {
                lambda *= 10.0;
                if lambda > 1e12 {
                    break;
                }
            }
        }
    }
    Some(Solution { params, normal })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_line_through_noisy_points_is_the_closed_form_least_squares_line() {
        // y = 2 + 3x with a known residual pattern: the normal equations' solution exactly.
        let x: [f64; 6] = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0];
        let e = [0.1, -0.2, 0.05, 0.0, 0.15, -0.1];
        let y: [f64; 6] = core::array::from_fn(|i| 2.0 + 3.0 * x[i] + e[i]);
        let s = least_squares(SVector::<f64, 2>::new(0.0, 0.0), |p, n| {
            for i in 0..6 {
                n.add(
                    p[0] + p[1] * x[i] - y[i],
                    &SVector::<f64, 2>::new(1.0, x[i]),
                );
            }
            true
        })
        .unwrap();
        let (mx, my) = (x.iter().sum::<f64>() / 6.0, y.iter().sum::<f64>() / 6.0);
        let sxy: f64 = (0..6).map(|i| (x[i] - mx) * (y[i] - my)).sum();
        let sxx: f64 = (0..6).map(|i| (x[i] - mx) * (x[i] - mx)).sum();
        let slope = sxy / sxx;
        assert!((s.params[1] - slope).abs() < 1e-12);
        assert!((s.params[0] - (my - slope * mx)).abs() < 1e-12);
        // The slope's standard error: s/√Sxx.
        let se = (s.normal.cost / 4.0 / sxx).sqrt();
        assert!((s.sigma(0.0)[1] / se - 1.0).abs() < 1e-9);
    }
}
