//! The backward pass against the batch least-squares solution it equals for a linear Gaussian
//! model: a constant-velocity state observed in position, run as a closed-loop filter whose
//! records feed `rts_backward`.
use imu_core::fusion::smoother::{Covariance, EpochRecord, ErrorVector, rts_backward};
use nalgebra::{DMatrix, DVector, Matrix2, Vector2};

#[test]
fn rts_equals_batch_least_squares_on_a_linear_model() {
    let (dt, q, r): (f64, f64, f64) = (0.5, 0.04, 0.25);
    let phi = Matrix2::new(1.0, dt, 0.0, 1.0);
    // Continuous white acceleration of PSD q.
    let qd = Matrix2::new(
        q * dt.powi(3) / 3.0,
        q * dt * dt / 2.0,
        q * dt * dt / 2.0,
        q * dt,
    );
    let p0 = Matrix2::new(4.0, 0.0, 0.0, 1.0);
    let x0 = Vector2::new(0.0, 1.0);
    let z: Vec<f64> = (0..12)
        .map(|k| 0.9 * k as f64 * dt + 0.3 * ((k * 7 % 5) as f64 - 2.0))
        .collect();
    // Forward filter, closed loop: the nominal is the estimate; the records as the ESKF keeps them.
    let mut records: Vec<EpochRecord<2>> = Vec::new();
    let mut nominal = Vec::new();
    let (mut x, mut p) = (x0, p0);
    for (k, zk) in z.iter().enumerate() {
        let (prior_x, prior_p, transition) = if k == 0 {
            (x, p, Matrix2::identity())
        } else {
            (phi * x, phi * p * phi.transpose() + qd, phi)
        };
        let h = nalgebra::RowVector2::new(1.0, 0.0);
        let s = (h * prior_p * h.transpose())[(0, 0)] + r;
        let gain = prior_p * h.transpose() / s;
        let dx = gain * (zk - (h * prior_x)[(0, 0)]);
        let post_p = (Matrix2::identity() - gain * h) * prior_p;
        x = prior_x + dx;
        p = post_p;
        records.push(EpochRecord {
            t_s: k as f64 * dt,
            phi: transition,
            prior: prior_p,
            posterior: post_p,
            correction: dx,
            reset: false,
        });
        nominal.push(x);
    }
    let mut smoothed = vec![ErrorVector::<2>::zeros(); z.len()];
    let mut cov = vec![Covariance::<2>::zeros(); z.len()];
    rts_backward(records.as_slice(), |j, s, p| {
        smoothed[j] = *s;
        cov[j] = *p;
    });
    // Batch: minimise |x_0 − x̄_0|²_{P0⁻¹} + Σ|x_{k+1} − Φx_k|²_{Q⁻¹} + Σ|z_k − x_k,pos|²/r.
    let n = z.len();
    let mut info = DMatrix::<f64>::zeros(2 * n, 2 * n);
    let mut rhs = DVector::<f64>::zeros(2 * n);
    let p0i = p0.try_inverse().unwrap();
    let qi = qd.try_inverse().unwrap();
    let add = |info: &mut DMatrix<f64>, i: usize, j: usize, m: &Matrix2<f64>| {
        for a in 0..2 {
            for b in 0..2 {
                info[(2 * i + a, 2 * j + b)] += m[(a, b)];
            }
        }
    };
    add(&mut info, 0, 0, &p0i);
    let b0 = p0i * x0;
    rhs[0] += b0[0];
    rhs[1] += b0[1];
    for k in 0..n - 1 {
        add(&mut info, k, k, &(phi.transpose() * qi * phi));
        add(&mut info, k + 1, k + 1, &qi);
        add(&mut info, k, k + 1, &(-phi.transpose() * qi));
        add(&mut info, k + 1, k, &(-qi * phi));
    }
    for (k, zk) in z.iter().enumerate() {
        info[(2 * k, 2 * k)] += 1.0 / r;
        rhs[2 * k] += zk / r;
    }
    let batch = info.clone().cholesky().unwrap().solve(&rhs);
    let batch_cov = info.try_inverse().unwrap();
    for k in 0..n {
        let s = nominal[k] + smoothed[k];
        for a in 0..2 {
            assert!(
                (s[a] - batch[2 * k + a]).abs() < 1e-9,
                "epoch {k}: {s} vs batch"
            );
            let (got, want) = (cov[k][(a, a)], batch_cov[(2 * k + a, 2 * k + a)]);
            assert!(
                (got / want - 1.0).abs() < 1e-9,
                "epoch {k}: variance {got} vs {want}"
            );
        }
    }
}

#[test]
fn a_reset_is_not_crossed() {
    let rec = |reset: bool, dx: f64| EpochRecord::<1> {
        t_s: 0.0,
        phi: Covariance::<1>::identity(),
        prior: Covariance::<1>::identity(),
        posterior: Covariance::<1>::identity() * 0.5,
        correction: ErrorVector::<1>::new(dx),
        reset,
    };
    let records = [rec(false, 0.0), rec(true, 3.0), rec(false, 1.0)];
    let mut s = [ErrorVector::<1>::zeros(); 3];
    let mut visited = Vec::new();
    rts_backward(records.as_slice(), |j, dx, _| {
        s[j] = *dx;
        visited.push(j);
    });
    assert_eq!(visited, [2, 1, 0]);
    assert_eq!(s[0][0], 0.0);
    assert!(s[1][0] > 0.0);
}
