//! Finite-difference derivatives: a kept stencil's weights give the numbers computing them again
//! gives.
use imu_core::kinematics::finite_diff::{Stencils, derivatives_at};

#[test]
fn kept_weights_give_the_computed_numbers_bit_for_bit() {
    // Regular times (windows recur, so kept weights are used), times with jitter (every window
    // new), and regular times late in a long run, whose offsets round differently from window to
    // window.
    let series: [Vec<f64>; 3] = [
        (0..3000).map(|k| f64::from(k) / 100.0).collect(),
        (0..3000)
            .map(|k| f64::from(k) * 0.01 + 1e-4 * (f64::from(k) * 1.7).sin())
            .collect(),
        (0..3000).map(|k| 1e5 + f64::from(k) / 2000.0).collect(),
    ];
    for t in &series {
        let x = |j: usize| [t[j].sin() * 1e3, (0.3 * t[j]).cos()];
        for order in [2, 4, 6, 8] {
            let mut stencils = Stencils::new();
            for i in 0..t.len() {
                let kept = stencils.derivatives_at(t, i, order, x);
                let computed = derivatives_at(t, i, order, x);
                let bits = |(a, b): ([f64; 2], [f64; 2])| [a, b].map(|v| v.map(f64::to_bits));
                assert_eq!(bits(kept), bits(computed), "order {order}, sample {i}");
            }
        }
    }
}
